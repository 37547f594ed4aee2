//! Emission and accounting tests: the slab is a closed, consistently wound
//! surface at every LOD; causes are attributed as defined.

mod common;

use std::collections::HashMap;

use strata_level::Level;
use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
use strata_mesh::emit::{KIND_CEILING, KIND_FLOOR, KIND_TOP};
use strata_mesh::samples::{ChunkLayout, ChunkSamples};
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{Cause, LODS, LevelMesh, decode, encode};

type P3 = [i32; 3];

fn position(samples: &ChunkSamples, index: u16) -> (P3, u16) {
    let (x, y, kind) = decode(index, 129, 129 * 129);
    let s = samples.at(x as i32, y as i32);
    let z = match kind {
        KIND_FLOOR => s.z[0],
        KIND_TOP => s.z[2],
        _ => s.z[1],
    };
    ([x as i32, y as i32, i32::from(z)], kind)
}

#[test]
fn index_encoding_round_trips_and_fits_u16() {
    for kind in [KIND_FLOOR, KIND_TOP, KIND_CEILING] {
        for (x, y) in [(0, 0), (128, 0), (0, 128), (128, 128), (17, 93)] {
            let i = encode(x, y, 129, 129 * 129, kind);
            assert_eq!(decode(i, 129, 129 * 129), (x, y, kind));
        }
    }
    assert_eq!(
        encode(128, 128, 129, 129 * 129, KIND_CEILING),
        3 * 129 * 129 - 1
    );
}

#[test]
fn slab_surface_is_closed_and_consistently_wound_at_every_lod() {
    let l = synthetic_level(256, 256, 5);
    let layout = ChunkLayout::of(&l);
    let mesh = LevelMesh::fit(&l, 4.0);
    let mut samples = ChunkSamples::default();
    let mut slab_tris = 0;
    for (i, chunk) in mesh.chunks.iter().enumerate() {
        let (cx, cy) = layout.coords(i);
        samples.load(&l, &layout, cx, cy);
        for lod in 0..LODS {
            // Directed edges of every slab triangle (top, ceiling, wall): a
            // closed oriented surface has each edge once in each direction.
            let mut edges: HashMap<(P3, P3), i32> = HashMap::new();
            let (mut tops, mut ceilings, mut duals) = (0, 0, 0);
            for t in chunk.lod_triangles(lod) {
                let v = t.map(|i| position(&samples, i));
                let kinds = v.map(|v| v.1);
                if kinds == [KIND_FLOOR; 3] {
                    let all_dual = v.iter().all(|v| samples.at(v.0[0], v.0[1]).dual());
                    duals += usize::from(all_dual);
                    continue;
                }
                assert!(
                    !kinds.contains(&KIND_FLOOR),
                    "floor vertices only in floor triangles"
                );
                tops += usize::from(kinds == [KIND_TOP; 3]);
                ceilings += usize::from(kinds == [KIND_CEILING; 3]);
                slab_tris += 1;
                for k in 0..3 {
                    let (p, q) = (v[k].0, v[(k + 1) % 3].0);
                    if p == q {
                        continue;
                    }
                    *edges.entry((p, q)).or_default() += 1;
                    *edges.entry((q, p)).or_default() -= 1;
                }
            }
            assert_eq!(
                tops, duals,
                "a top over every all-dual floor triangle (chunk {i} lod {lod})"
            );
            assert_eq!(ceilings, duals, "a ceiling under every top");
            let open: Vec<_> = edges.iter().filter(|(_, n)| **n != 0).collect();
            assert!(
                open.is_empty(),
                "chunk {i} lod {lod}: {} unmatched edges, e.g. {:?}",
                open.len(),
                open.first()
            );
        }
    }
    assert!(
        slab_tris > 1000,
        "the synthetic level has slabs: {slab_tris}"
    );
}

/// A flat level with one slab rectangle whose top is `top(x, y)`.
fn slab_level(top: impl Fn(u32, u32) -> u8) -> Level {
    let (w, h) = (256u32, 256u32);
    let mut heights = vec![50u8; (w * h) as usize];
    let mut metas = vec![1u8 << META_TERRAIN_SHIFT; (w * h) as usize];
    for y in 40..90 {
        for x in (100..160).step_by(2) {
            let i = (y * w + x) as usize;
            heights[i + 1] = top(x, y);
            metas[i] = META_DOUBLE_LEVEL | (2 << META_TERRAIN_SHIFT) | 0b01;
            metas[i + 1] = META_DOUBLE_LEVEL | (3 << META_TERRAIN_SHIFT) | 0b10;
        }
    }
    Level::from_planes(w, h, heights, metas, Default::default()).unwrap()
}

#[test]
fn insertions_are_attributed_to_their_cause() {
    // Flat floor, flat slab top: only the region outline costs vertices, and
    // the slab crosses the chunk edge at x = 128 (border vertices).
    let flat = LevelMesh::fit(&slab_level(|_, _| 120), 4.0).stats();
    let c = flat.causes;
    assert_eq!(c[Cause::Floor as usize], 0, "{c:?}");
    assert_eq!(c[Cause::SlabInterior as usize], 0, "{c:?}");
    assert!(c[Cause::Boundary as usize] > 20, "{c:?}");
    assert!(c[Cause::Border as usize] >= 4, "{c:?}");
    // A rough slab top adds slab-interior insertions and nothing on the floor.
    let rough =
        LevelMesh::fit(&slab_level(|x, y| 120 + ((x * 7 + y * 13) % 29) as u8), 4.0).stats();
    let r = rough.causes;
    assert_eq!(r[Cause::Floor as usize], 0, "{r:?}");
    assert!(r[Cause::SlabInterior as usize] > 100, "{r:?}");
    assert!(rough.lods[0].planar > flat.lods[0].planar);
    // Every insertion has a cause: vertices = 4 corners per chunk + insertions.
    assert_eq!(
        rough.planar_vertices,
        4 * rough.chunks as u64 + r.iter().sum::<u64>()
    );
}
