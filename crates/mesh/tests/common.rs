//! Helpers shared by the integration tests.
#![allow(dead_code)]

use strata_level::model::META_DOUBLE_LEVEL;
use strata_level::{DirtyRect, Level};
use strata_mesh::emit::{KIND_CEILING, KIND_FLOOR, KIND_TOP};
use strata_mesh::{ChunkMesh, decode};

/// Floor triangles of one LOD as local grid points (128-chunks).
pub fn floor_triangles(mesh: &ChunkMesh, lod: usize) -> Vec<[[i32; 2]; 3]> {
    mesh.lod_triangles(lod)
        .filter_map(|t| {
            let vs = t.map(|i| decode(i, 129, 129 * 129));
            vs.iter()
                .all(|v| v.2 == KIND_FLOOR)
                .then(|| vs.map(|v| [v.0 as i32, v.1 as i32]))
        })
        .collect()
}

/// A triangle as local grid points.
pub type GridTriangle = [[i32; 2]; 3];

/// Slab top and cave ceiling triangles of one LOD as local grid points
/// (128-chunks), as drawn (the ceiling's winding reversed).
pub fn slab_triangles(mesh: &ChunkMesh, lod: usize) -> (Vec<GridTriangle>, Vec<GridTriangle>) {
    let (mut tops, mut ceilings) = (Vec::new(), Vec::new());
    for t in mesh.lod_triangles(lod) {
        let vs = t.map(|i| decode(i, 129, 129 * 129));
        let pts = vs.map(|v| [v.0 as i32, v.1 as i32]);
        if vs.iter().all(|v| v.2 == KIND_TOP) {
            tops.push(pts);
        } else if vs.iter().all(|v| v.2 == KIND_CEILING) {
            ceilings.push(pts);
        }
    }
    (tops, ceilings)
}

/// A crater like the paper's: altitude lowered by `depth (1 - d²/r²)`, the
/// upper layer removed inside. Returns the dirty rectangles (split at the
/// map edge).
pub fn dig(level: &mut Level, cx: i64, cy: i64, r: i64, depth: f64) -> Vec<DirtyRect> {
    let (w, h) = (i64::from(level.width()), i64::from(level.height()));
    let (heights, metas) = level.planes_mut();
    for y in cy - r..=cy + r {
        for x in ((cx - r) & !1..=cx + r).step_by(2) {
            let d2 = ((x - cx).pow(2) + (y - cy).pow(2)) as f64;
            if d2 > (r * r) as f64 {
                continue;
            }
            let (wx, wy) = (x.rem_euclid(w), y.rem_euclid(h));
            let even = (wy * w + wx) as usize;
            let cut = (depth * (1.0 - d2 / (r * r) as f64)) as i64;
            let low = (i64::from(heights[even]) - cut).max(0) as u8;
            heights[even] = low;
            heights[even + 1] = low;
            metas[even] &= !META_DOUBLE_LEVEL;
            metas[even + 1] &= !META_DOUBLE_LEVEL;
        }
    }
    // Dirty rectangles, split where the crater crosses the map edge.
    let mut rects = Vec::new();
    let split = |lo: i64, hi: i64, n: i64| -> Vec<(u32, u32)> {
        let (lo, hi) = (lo - 1, hi + 1);
        let a = lo.rem_euclid(n);
        let len = hi - lo + 1;
        if a + len <= n {
            vec![(a as u32, len as u32)]
        } else {
            vec![(a as u32, (n - a) as u32), (0, (a + len - n) as u32)]
        }
    };
    for (x, width) in split(cx - r, cx + r, w) {
        for &(y, height) in &split(cy - r, cy + r, h) {
            rects.push(DirtyRect {
                x,
                y,
                width,
                height,
            });
        }
    }
    rects
}

/// Boundary edges of a LOD's floor on one side of the chunk, as sorted
/// (from, to) positions along that side.
pub fn side_edges(
    chunk: &strata_mesh::ChunkMesh,
    lod: usize,
    axis: usize,
    at: i32,
) -> Vec<(i32, i32)> {
    side_edges_of(&floor_triangles(chunk, lod), axis, at)
}

/// Edges of `triangles` on one side of the chunk (`axis` 0: x = `at`), as
/// sorted (from, to) positions along that side.
pub fn side_edges_of(triangles: &[[[i32; 2]; 3]], axis: usize, at: i32) -> Vec<(i32, i32)> {
    let mut out = Vec::new();
    for &t in triangles {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            if p[axis] == at && q[axis] == at {
                let (u, v) = (p[1 - axis], q[1 - axis]);
                out.push((u.min(v), u.max(v)));
            }
        }
    }
    out.sort_unstable();
    out
}

/// For every chunk of `mesh` and every pair of LODs: the chunk's x and y
/// seams (at 128) equal its right and lower neighbours' (at 0, wrapping),
/// then `more(chunk, [right, below], lod_a, lod_b, y_seam)` checks more.
pub fn check_seams(
    mesh: &strata_mesh::LevelMesh,
    layout: &strata_mesh::ChunkLayout,
    mut more: impl FnMut(usize, [usize; 2], usize, usize, &[(i32, i32)]),
) {
    for i in 0..layout.count() {
        let (cx, cy) = layout.coords(i);
        let right = layout.index((cx + 1) % layout.chunks_x, cy);
        let below = layout.index(cx, (cy + 1) % layout.chunks_y);
        for la in 0..strata_mesh::LODS {
            for lb in 0..strata_mesh::LODS {
                let a = side_edges(&mesh.chunks[i], la, 0, 128);
                let b = side_edges(&mesh.chunks[right], lb, 0, 0);
                assert_eq!(a, b, "x seam chunk {i} lods {la}/{lb}");
                let a = side_edges(&mesh.chunks[i], la, 1, 128);
                let b = side_edges(&mesh.chunks[below], lb, 1, 0);
                assert_eq!(a, b, "y seam chunk {i} lods {la}/{lb}");
                more(i, [right, below], la, lb, &a);
            }
        }
    }
}
