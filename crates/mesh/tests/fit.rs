//! Issue 7 tests: Delaunay, tolerance at every LOD, seams, determinism, refit.

mod common;

use common::{dig, floor_triangles};
use strata_level::Level;
use strata_mesh::candidate::barycentric;
use strata_mesh::predicates::orient2d;
use strata_mesh::samples::{ChunkLayout, ChunkSamples};
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{ChunkFitter, LODS, LevelMesh, tolerance_for_quality};

fn level() -> Level {
    synthetic_level(256, 256, 3)
}

#[test]
fn quality_maps_to_tolerance() {
    assert_eq!(tolerance_for_quality(0.5), Some(4.0));
    assert_eq!(tolerance_for_quality(0.0), Some(16.0));
    assert_eq!(tolerance_for_quality(1.0), Some(1.0));
    assert_eq!(tolerance_for_quality(1.5), None);
    assert_eq!(tolerance_for_quality(f64::NAN), None);
}

#[test]
fn synthetic_level_has_slabs() {
    let l = level();
    let frac = l.dual_texel_count() as f64 / (256.0 * 256.0);
    assert!((0.05..0.25).contains(&frac), "dual fraction {frac}");
}

#[test]
fn fitted_chunks_are_delaunay_and_consistent() {
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mut f = ChunkFitter::default();
    for tol in [1.0, 4.0] {
        for i in 0..layout.count() {
            let (cx, cy) = layout.coords(i);
            let mesh = f.fit(&l, &layout, cx, cy, tol);
            let tr = f.triangulation();
            assert!(tr.is_consistent(), "chunk {i}");
            assert_eq!(tr.delaunay_violations(), 0, "chunk {i} tol {tol}");
            assert!(
                tr.tris.len() > 100,
                "the fit did something: {}",
                tr.tris.len()
            );
            assert_eq!(mesh.stats.lods[0].planar as usize, tr.tris.len());
        }
    }
}

#[test]
fn every_sample_is_within_tolerance_at_every_lod() {
    let l = level();
    let layout = ChunkLayout::of(&l);
    let tol = 4.0;
    let mesh = LevelMesh::fit(&l, tol);
    let mut samples = ChunkSamples::default();
    let mut worst = [0.0f64; LODS];
    for (i, chunk) in mesh.chunks.iter().enumerate() {
        let (cx, cy) = layout.coords(i);
        samples.load(&l, &layout, cx, cy);
        for (lod, worst) in worst.iter_mut().enumerate() {
            let limit = tol * f64::from(1u32 << lod);
            let mut area = 0i64;
            for [a, b, c] in floor_triangles(chunk, lod) {
                let den = orient2d(a, b, c);
                assert!(den > 0, "counter-clockwise, non-degenerate floor triangle");
                area += den;
                let zs = [a, b, c].map(|p| samples.at(p[0], p[1]).z);
                for y in a[1].min(b[1]).min(c[1])..=a[1].max(b[1]).max(c[1]) {
                    for x in a[0].min(b[0]).min(c[0])..=a[0].max(b[0]).max(c[0]) {
                        let w = barycentric(a, b, c, [x, y]);
                        if w.iter().any(|&w| w < 0) {
                            continue;
                        }
                        let s = samples.at(x, y).z;
                        for f in 0..3 {
                            let interp = (0..3)
                                .map(|k| f64::from(w[k]) * f64::from(zs[k][f]))
                                .sum::<f64>()
                                / den as f64;
                            let e = (interp - f64::from(s[f])).abs();
                            *worst = worst.max(e);
                            assert!(
                                e <= limit + 1e-9,
                                "chunk {i} lod {lod} ({x},{y}) field {f}: {e} > {limit}"
                            );
                        }
                    }
                }
            }
            assert_eq!(area, 2 * 128 * 128, "LOD {lod} floor tiles chunk {i}");
        }
    }
    // The fit uses its budget: the worst error is close to each LOD's limit.
    for (lod, w) in worst.iter().enumerate() {
        assert!(
            *w > tol * f64::from(1u32 << lod) * 0.5,
            "lod {lod} worst {w}"
        );
    }
    let s = mesh.stats();
    assert!(s.lods[0].planar > s.lods[1].planar && s.lods[1].planar > s.lods[2].planar);
}

#[test]
fn seams_match_between_neighbours_at_every_lod_pair() {
    let l = synthetic_level(512, 256, 11);
    let layout = ChunkLayout::of(&l);
    let mesh = LevelMesh::fit(&l, 4.0);
    let mut checked = 0;
    common::check_seams(&mesh, &layout, |_, _, _, _, seam| {
        // The seam is a contiguous polyline from 0 to 128.
        let mut at = 0;
        for (u, v) in seam {
            assert_eq!(*u, at);
            at = *v;
        }
        assert_eq!(at, 128);
        checked += 1;
    });
    assert_eq!(checked, layout.count() * LODS * LODS);
}

#[test]
fn fit_is_deterministic_at_any_thread_count() {
    let l = level();
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| LevelMesh::fit(&l, 4.0));
    let two = pool(2).install(|| LevelMesh::fit(&l, 4.0));
    let again = pool(2).install(|| LevelMesh::fit(&l, 4.0));
    assert_eq!(one, two);
    assert_eq!(two, again);
    assert!(one.stats().lods[0].planar > 1000);
}

#[test]
fn fit_in_steps_equals_the_parallel_fit() {
    let l = level();
    let whole = LevelMesh::fit(&l, 4.0);
    let mut steps = LevelMesh::fit_in_steps(&l, 4.0);
    assert_eq!(
        LevelMesh::fit_in_steps(&l, 4.0).finish(),
        None,
        "an unfinished fit"
    );
    let mut calls = 0;
    // Two chunks per call: the fit must resume where it stopped.
    while !steps.step(&l, {
        let mut left = 2;
        move || {
            left -= 1;
            left > 0
        }
    }) {
        calls += 1;
        assert!(steps.progress() < 1.0);
    }
    assert!(calls >= whole.chunks.len() / 2 - 1, "{calls} calls");
    assert_eq!(steps.progress(), 1.0);
    assert_eq!(steps.finish(), Some(whole));
}

#[test]
fn refit_after_edit_equals_fresh_fit() {
    // One crater inside the map, one across the corner (wraps both ways).
    for (cx, cy) in [(130, 120), (3, 250)] {
        let mut l = level();
        let mut mesh = LevelMesh::fit(&l, 4.0);
        let before = mesh.clone();
        let dirty = dig(&mut l, cx, cy, 48, 90.0);
        let changed = mesh.refit(&l, &dirty);
        let fresh = LevelMesh::fit(&l, 4.0);
        assert_eq!(mesh, fresh, "crater at ({cx},{cy})");
        assert!(!changed.is_empty());
        // Exactly the chunks that differ from the unedited fit are reported.
        let differ: Vec<usize> = (0..fresh.chunks.len())
            .filter(|&i| fresh.chunks[i] != before.chunks[i])
            .collect();
        assert_eq!(changed, differ);
        // The same answer once the CPU copies are released after upload.
        let mut released = before.clone();
        released.release_indices();
        assert_eq!(released.refit(&l, &dirty), differ);
        assert_eq!(released.stats(), fresh.stats());
        for &i in &differ {
            assert_eq!(released.chunks[i], fresh.chunks[i]);
        }
    }
}

#[test]
fn dirty_chunks_include_shared_borders_and_wrap() {
    use strata_level::DirtyRect;
    use strata_mesh::dirty_chunks;
    let layout = ChunkLayout {
        size_x: 128,
        size_y: 128,
        chunks_x: 4,
        chunks_y: 2,
    };
    // A texel on x = 128 belongs to chunks 0 and 1; its pair partner 129 too.
    let r = DirtyRect {
        x: 129,
        y: 5,
        width: 1,
        height: 1,
    };
    assert_eq!(dirty_chunks(&layout, 512, 256, &[r]), vec![0, 1]);
    // Row 0 is shared with the last chunk row (wrap), row 5 is not.
    let r = DirtyRect {
        x: 300,
        y: 0,
        width: 2,
        height: 1,
    };
    assert_eq!(dirty_chunks(&layout, 512, 256, &[r]), vec![2, 6]);
    let r = DirtyRect {
        x: 0,
        y: 200,
        width: 1,
        height: 1,
    };
    assert_eq!(dirty_chunks(&layout, 512, 256, &[r]), vec![4, 7]);
}

#[test]
fn flat_level_fits_to_two_triangles_per_chunk() {
    let l = Level::flat(256, 256, 77, 2).unwrap();
    let mesh = LevelMesh::fit(&l, 1.0);
    for c in &mesh.chunks {
        for lod in 0..LODS {
            assert_eq!(c.lod_triangles(lod).count(), 2);
        }
        // Shared by all three LODs: stored once.
        assert_eq!(c.indices.len(), 6);
    }
    assert_eq!(mesh.stats().causes, [0; 4]);
}

#[test]
fn small_and_odd_shaped_levels_fit_without_panics() {
    use strata_mesh::samples::ChunkLayout;
    for (w, h) in [(2, 1), (2, 2), (4, 4), (64, 256), (256, 32)] {
        let l = synthetic_level(w, h, 9);
        let layout = ChunkLayout::of(&l);
        let mesh = LevelMesh::fit(&l, 2.0);
        assert_eq!(mesh.chunks.len(), layout.count());
        // Floor triangles tile each chunk at every LOD.
        let stride = layout.size_x + 1;
        let positions = stride * (layout.size_y + 1);
        for c in &mesh.chunks {
            for lod in 0..LODS {
                let area: i64 = c
                    .lod_triangles(lod)
                    .map(|t| t.map(|i| strata_mesh::decode(i, stride, positions)))
                    .filter(|v| v.iter().all(|v| v.2 == 0))
                    .map(|v| {
                        let [a, b, c] = v.map(|v| [v.0 as i32, v.1 as i32]);
                        orient2d(a, b, c)
                    })
                    .sum();
                assert_eq!(
                    area,
                    i64::from(layout.size_x * layout.size_y * 2),
                    "{w}x{h} lod {lod}"
                );
            }
        }
    }
    // Nonsense tolerances are clamped, not trusted.
    let l = synthetic_level(128, 128, 2);
    assert_eq!(LevelMesh::fit(&l, f64::NAN), LevelMesh::fit(&l, 1.0));
    assert_eq!(LevelMesh::fit(&l, -3.0), LevelMesh::fit(&l, 1.0));
}
