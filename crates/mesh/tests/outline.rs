//! Issue 17: the outline-constrained fit. The same guarantees as the plain
//! fit (consistent, Delaunay except at the outline's constraint edges,
//! within tolerance at every LOD, crack-free seams, refit == fresh fit,
//! the fit in steps == the parallel fit) plus its own: no triangle
//! straddles the single/double outline by more than the LOD's tolerance.

mod common;

use common::{dig, floor_triangles};
use strata_level::Level;
use strata_mesh::candidate::barycentric;
use strata_mesh::predicates::orient2d;
use strata_mesh::samples::{ChunkLayout, ChunkSamples};
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{ChunkFitter, FitOptions, LODS, LevelMesh};

const OUTLINE: FitOptions = FitOptions { outline: true };

fn level() -> Level {
    synthetic_level(256, 256, 3)
}

fn fit(l: &Level, tol: f64) -> LevelMesh {
    LevelMesh::fit_with_options(l, tol, OUTLINE, &|_, _| {})
}

#[test]
fn outline_fit_is_consistent_and_delaunay_off_the_outline() {
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mut f = ChunkFitter::default();
    let mut constrained = 0;
    for tol in [1.0, 4.0] {
        for i in 0..layout.count() {
            let (cx, cy) = layout.coords(i);
            f.fit_with(&l, &layout, cx, cy, tol, OUTLINE);
            let tr = f.triangulation();
            assert!(tr.is_consistent(), "chunk {i}");
            assert_eq!(tr.delaunay_violations(), 0, "chunk {i} tol {tol}");
            // The constraints matter: with them off, some edges would flip.
            let mut plain = tr.clone();
            plain.outline = false;
            constrained += plain.delaunay_violations();
        }
    }
    assert!(constrained > 0, "no outline edge was ever kept from a flip");
}

/// Samples of LOD `lod` that the drawn mesh gets wrong by more than
/// `limit` at the outline (a dual sample no slab triangle draws, or a slab
/// triangle over a single sample), after asserting that the floor (and the
/// slab where drawn) is within `limit` when `strict`.
fn straddles(l: &Level, mesh: &LevelMesh, lod: usize, limit: f64, strict: bool) -> usize {
    let layout = ChunkLayout::of(l);
    let mut samples = ChunkSamples::default();
    let mut wrong = 0;
    for (i, chunk) in mesh.chunks.iter().enumerate() {
        let (cx, cy) = layout.coords(i);
        samples.load(l, &layout, cx, cy);
        let mut area = 0i64;
        for [a, b, c] in floor_triangles(chunk, lod) {
            let den = orient2d(a, b, c);
            assert!(den > 0);
            area += den;
            let vs = [a, b, c].map(|p| *samples.at(p[0], p[1]));
            let slab = vs.iter().all(|s| s.dual());
            let zs = vs.map(|s| s.z);
            for y in a[1].min(b[1]).min(c[1])..=a[1].max(b[1]).max(c[1]) {
                for x in a[0].min(b[0]).min(c[0])..=a[0].max(b[0]).max(c[0]) {
                    let w = barycentric(a, b, c, [x, y]);
                    if w.iter().any(|&w| w < 0) || w.iter().filter(|&&w| w == 0).count() >= 2 {
                        continue; // outside, or a vertex (exact)
                    }
                    let s = samples.at(x, y);
                    let err = |f: usize| {
                        let interp = (0..3)
                            .map(|k| f64::from(w[k]) * f64::from(zs[k][f]))
                            .sum::<f64>()
                            / den as f64;
                        (interp - f64::from(s.z[f])).abs()
                    };
                    if strict {
                        // The floor everywhere; the slab's fields where drawn.
                        for f in 0..if slab { 3 } else { 1 } {
                            assert!(err(f) <= limit, "chunk {i} lod {lod} ({x},{y}) field {f}");
                        }
                    }
                    // A dual sample on an edge between dual vertices is
                    // drawn by the slab triangle across.
                    let on_dual_edge = (0..3)
                        .any(|k| w[k] == 0 && vs[(k + 1) % 3].dual() && vs[(k + 2) % 3].dual());
                    let missing = f64::from(s.z[2]) - f64::from(s.z[0]);
                    if (!slab && s.dual() && !on_dual_edge && missing > limit)
                        || (slab && !s.dual() && (0..3).any(|f| err(f) > limit))
                    {
                        wrong += 1;
                    }
                }
            }
        }
        assert_eq!(area, 2 * 128 * 128, "LOD {lod} floor tiles chunk {i}");
    }
    wrong
}

#[test]
fn no_triangle_straddles_the_outline_beyond_tolerance() {
    let l = level();
    let mesh = fit(&l, 4.0);
    for lod in 0..LODS {
        let limit = 4.0 * f64::from(1u32 << lod) + 1e-9;
        assert_eq!(straddles(&l, &mesh, lod, limit, true), 0, "LOD {lod}");
    }
}

#[test]
fn outline_fit_costs_about_what_the_plain_fit_costs() {
    // On this level the plain fit happens not to straddle either (its slab
    // regions are clean rectangles with thick slabs); the outline fit gives
    // the same accuracy for about the same triangles. On the generated
    // world it saves a few percent (bench/survey/).
    let l = level();
    let (plain, outline) = (LevelMesh::fit(&l, 4.0).stats(), fit(&l, 4.0).stats());
    let (p, o) = (plain.lods[0].planar as f64, outline.lods[0].planar as f64);
    println!("finest triangles: plain {p}, outline {o}");
    assert!(o < 1.1 * p && o > 0.7 * p, "plain {p} outline {o}");
}

#[test]
fn outline_seams_match_between_neighbours_at_every_lod_pair() {
    let l = synthetic_level(512, 256, 11);
    let layout = ChunkLayout::of(&l);
    let mesh = fit(&l, 4.0);
    for i in 0..layout.count() {
        let (cx, cy) = layout.coords(i);
        let right = layout.index((cx + 1) % layout.chunks_x, cy);
        let below = layout.index(cx, (cy + 1) % layout.chunks_y);
        for la in 0..LODS {
            for lb in 0..LODS {
                let a = common::side_edges(&mesh.chunks[i], la, 0, 128);
                let b = common::side_edges(&mesh.chunks[right], lb, 0, 0);
                assert_eq!(a, b, "x seam chunk {i} lods {la}/{lb}");
                let a = common::side_edges(&mesh.chunks[i], la, 1, 128);
                let b = common::side_edges(&mesh.chunks[below], lb, 1, 0);
                assert_eq!(a, b, "y seam chunk {i} lods {la}/{lb}");
            }
        }
    }
}

#[test]
fn outline_refit_after_edit_equals_fresh_fit_and_steps_equal_parallel() {
    for (cx, cy) in [(130, 120), (3, 250)] {
        let mut l = level();
        let mut mesh = fit(&l, 4.0);
        let before = mesh.clone();
        let dirty = dig(&mut l, cx, cy, 48, 90.0);
        let changed = mesh.refit(&l, &dirty);
        let fresh = fit(&l, 4.0);
        assert_eq!(mesh, fresh, "crater at ({cx},{cy})");
        assert_eq!(mesh.options, OUTLINE);
        let differ: Vec<usize> = (0..fresh.chunks.len())
            .filter(|&i| fresh.chunks[i] != before.chunks[i])
            .collect();
        assert!(!differ.is_empty());
        assert_eq!(changed, differ);
    }
    let l = level();
    let mut steps = LevelMesh::fit_in_steps_with(&l, 4.0, OUTLINE);
    while !steps.step(&l, || true) {}
    assert_eq!(steps.finish(), Some(fit(&l, 4.0)));
}
