//! Issue 17: the outline fit (a floor triangulation fitted on `low` alone,
//! and a slab triangulation constrained to the single/double outline whose
//! slab triangles draw top, ceiling and walls). The same guarantees as the
//! plain fit (consistent, Delaunay except at the outline's constraint
//! edges, within tolerance at every LOD, crack-free seams, refit == fresh
//! fit, the fit in steps == the parallel fit) plus its own: no slab is
//! drawn over a single sample, and none is missing over a dual one, by more
//! than the LOD's tolerance.

mod common;

use common::{dig, floor_triangles, slab_triangles};
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
            let floor = f.floor_triangulation();
            assert!(floor.is_consistent(), "floor, chunk {i}");
            assert!(!floor.outline, "the floor has no constraints");
            assert_eq!(floor.delaunay_violations(), 0, "floor, chunk {i}");
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

/// Interpolate field `f` of the vertex samples `vs` at barycentric
/// numerators `w` of a triangle of twice-area `den`.
fn interp(vs: &[strata_mesh::samples::Sample; 3], w: [i32; 3], den: i64, f: usize) -> f64 {
    (0..3)
        .map(|k| f64::from(w[k]) * f64::from(vs[k].z[f]))
        .sum::<f64>()
        / den as f64
}

/// Every sample of triangle `(a, b, c)` with its barycentric numerators.
fn samples_in(a: [i32; 2], b: [i32; 2], c: [i32; 2]) -> impl Iterator<Item = ([i32; 2], [i32; 3])> {
    let (x0, x1) = (a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]));
    let (y0, y1) = (a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]));
    (y0..=y1)
        .flat_map(move |y| (x0..=x1).map(move |x| [x, y]))
        .map(move |p| (p, barycentric(a, b, c, p)))
        .filter(|(_, w)| w.iter().all(|&w| w >= 0))
}

/// Checks LOD `lod` of the drawn mesh against the samples: the floor
/// tiles the chunk within `limit` of `low`; the slab top and ceiling come
/// in pairs, within `limit` of `high` and `mid` over the dual samples they
/// cover; returns the samples drawn wrong beyond `limit` at the outline (a
/// single sample under a slab triangle, a dual one no slab triangle draws,
/// except the vertices of the slab triangulation and dual samples on its
/// edges between dual vertices, where `finest` gives that triangulation).
fn straddles(
    l: &Level,
    mesh: &LevelMesh,
    lod: usize,
    limit: f64,
    finest: Option<&[Vec<[[i32; 2]; 3]>]>,
) -> usize {
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
            for (p, w) in samples_in(a, b, c) {
                let err = (interp(&vs, w, den, 0) - f64::from(samples.at(p[0], p[1]).z[0])).abs();
                assert!(err <= limit, "chunk {i} lod {lod} floor at {p:?}");
            }
        }
        assert_eq!(area, 2 * 128 * 128, "LOD {lod} floor tiles chunk {i}");
        let (tops, ceilings) = slab_triangles(chunk, lod);
        let mut mirrored: Vec<_> = ceilings.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let mut sorted = tops.clone();
        for v in [&mut mirrored, &mut sorted] {
            for t in v.iter_mut() {
                let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                t.rotate_left(k);
            }
            v.sort_unstable();
        }
        assert_eq!(
            sorted, mirrored,
            "chunk {i} lod {lod}: top and ceiling differ"
        );
        let mut covered = vec![false; samples.samples.len()];
        for &[a, b, c] in &tops {
            let den = orient2d(a, b, c);
            assert!(den > 0, "chunk {i} lod {lod}: slab top winding");
            let vs = [a, b, c].map(|p| *samples.at(p[0], p[1]));
            assert!(vs.iter().all(|s| s.dual()), "a slab vertex without a slab");
            for (p, w) in samples_in(a, b, c) {
                let s = samples.at(p[0], p[1]);
                covered[p[1] as usize * 129 + p[0] as usize] = true;
                let err = (1..3)
                    .map(|f| (interp(&vs, w, den, f) - f64::from(s.z[f])).abs())
                    .fold(0.0, f64::max);
                if s.dual() {
                    assert!(err <= limit, "chunk {i} lod {lod} slab at {p:?}: {err}");
                } else if err > limit {
                    wrong += 1;
                }
            }
        }
        let Some(finest) = finest else { continue };
        // Dual samples no slab triangle draws: allowed on the slab
        // triangulation's vertices and its edges between dual vertices.
        let mut excused = vec![false; samples.samples.len()];
        for &[a, b, c] in &finest[i] {
            let vs = [a, b, c].map(|p| samples.at(p[0], p[1]).dual());
            for (p, w) in samples_in(a, b, c) {
                let vertex = w.iter().filter(|&&w| w == 0).count() >= 2;
                let on_dual_edge = (0..3).any(|k| w[k] == 0 && vs[(k + 1) % 3] && vs[(k + 2) % 3]);
                if vertex || on_dual_edge {
                    excused[p[1] as usize * 129 + p[0] as usize] = true;
                }
            }
        }
        for y in 1..128 {
            for x in 1..128 {
                let s = samples.at(x, y);
                let k = y as usize * 129 + x as usize;
                let missing = f64::from(s.z[2]) - f64::from(s.z[0]);
                if s.dual() && !covered[k] && !excused[k] && missing > limit {
                    wrong += 1;
                }
            }
        }
    }
    wrong
}

#[test]
fn no_slab_straddles_the_outline_beyond_tolerance() {
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mesh = fit(&l, 4.0);
    let mut f = ChunkFitter::default();
    let finest: Vec<Vec<[[i32; 2]; 3]>> = (0..layout.count())
        .map(|i| {
            let (cx, cy) = layout.coords(i);
            f.fit_with(&l, &layout, cx, cy, 4.0, OUTLINE);
            let tr = f.triangulation();
            tr.tris.iter().map(|t| t.v.map(|v| tr.pt(v))).collect()
        })
        .collect();
    for lod in 0..LODS {
        let limit = 4.0 * f64::from(1u32 << lod) + 1e-9;
        let finest = (lod == 0).then_some(finest.as_slice());
        assert_eq!(straddles(&l, &mesh, lod, limit, finest), 0, "LOD {lod}");
    }
}

#[test]
fn outline_fit_costs_about_what_the_plain_fit_costs_on_clean_slabs() {
    // This level's slabs are clean rectangles over a rough floor, so the
    // plain fit's floor vertices serve its slab too, and two separate
    // triangulations draw a few percent more. Where the outline is ragged
    // (the generated world) the outline fit draws far fewer triangles
    // (bench/issue17/).
    let l = level();
    let (plain, outline) = (LevelMesh::fit(&l, 4.0).stats(), fit(&l, 4.0).stats());
    let (p, o) = (plain.lods[0], outline.lods[0]);
    println!("finest drawn: plain {}, outline {}", p.emitted, o.emitted);
    println!(
        "finest footprints (floor + slab tops): plain {}, outline {}",
        p.planar,
        o.planar + o.slab / 2
    );
    // The floor alone is no dearer than the plain fit's whole planar mesh.
    assert!(o.planar <= p.planar, "plain {p:?} outline {o:?}");
    let (pe, oe) = (p.emitted as f64, o.emitted as f64);
    assert!(oe < 1.1 * pe && oe > 0.7 * pe, "plain {p:?} outline {o:?}");
}

#[test]
fn outline_seams_match_between_neighbours_at_every_lod_pair() {
    let l = synthetic_level(512, 256, 11);
    let layout = ChunkLayout::of(&l);
    let mesh = fit(&l, 4.0);
    common::check_seams(&mesh, &layout, |i, [right, below], la, lb, _| {
        // The slab's seam edges on both sides join the same border
        // vertices: where they overlap, they are the same edge.
        for (axis, other) in [(0, right), (1, below)] {
            let a =
                common::side_edges_of(&common::slab_triangles(&mesh.chunks[i], la).0, axis, 128);
            let b =
                common::side_edges_of(&common::slab_triangles(&mesh.chunks[other], lb).0, axis, 0);
            for &(u0, u1) in &a {
                for &(v0, v1) in &b {
                    let overlap = u1.min(v1) - u0.max(v0);
                    assert!(
                        overlap <= 0 || (u0, u1) == (v0, v1),
                        "slab seam chunk {i} axis {axis} lods {la}/{lb}: {:?} {:?}",
                        (u0, u1),
                        (v0, v1)
                    );
                }
            }
        }
    });
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

#[test]
fn slab_scan_equals_the_per_sample_rule() {
    use strata_mesh::candidate::{scan_slab, slab_error};
    // Triangles of every shape over a chunk with both classes: the row
    // spans and their fast paths give the per-sample answer exactly.
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mut s = ChunkSamples::default();
    let mut checked = [0; 2];
    for chunk in 0..layout.count() {
        let (cx, cy) = layout.coords(chunk);
        s.load(&l, &layout, cx, cy);
        let mut h = 0x9e37_79b9u32 ^ chunk as u32;
        let mut next = |m: i32| {
            h ^= h << 13;
            h ^= h >> 17;
            h ^= h << 5;
            (h % m as u32) as i32
        };
        let duals: Vec<[i32; 2]> = (0..129 * 129)
            .filter(|&i| s.samples[i as usize].dual())
            .map(|i| [i % 129, i / 129])
            .collect();
        for k in 0..400 {
            let mut pick = || {
                if k % 2 == 0 && !duals.is_empty() {
                    duals[next(duals.len() as i32) as usize]
                } else {
                    [next(129), next(129)]
                }
            };
            let (a, b, c) = (pick(), pick(), pick());
            let (a, b, c) = match orient2d(a, b, c) {
                o if o > 0 => (a, b, c),
                o if o < 0 => (a, c, b),
                _ => continue,
            };
            let pts = [a, b, c];
            let vs = pts.map(|p| *s.at(p[0], p[1]));
            let duals = vs.map(|v| v.dual());
            let zs = vs.map(|v| v.z);
            let den = orient2d(a, b, c) as i32;
            let slab = duals.iter().all(|&d| d);
            let covered = [0, 1, 2].map(|k| duals[(k + 1) % 3] && duals[(k + 2) % 3]);
            let mut best = (0i32, 0u32);
            for y in 1..128 {
                for x in 1..128 {
                    let w = barycentric(a, b, c, [x, y]);
                    if w.iter().any(|&w| w < 0) {
                        continue;
                    }
                    let i = y as usize * 129 + x as usize;
                    let e = slab_error(w, den, zs, &s.samples[i], slab, covered);
                    if e > best.0 {
                        best = (e, i as u32);
                    }
                }
            }
            let (num, _, at) = scan_slab(pts, zs, slab, covered, &s);
            assert_eq!(num, i64::from(best.0), "chunk {chunk} {pts:?}");
            if num > 0 {
                assert_eq!(at, best.1, "chunk {chunk} {pts:?}");
            }
            checked[usize::from(slab)] += 1;
        }
    }
    assert!(checked[0] > 100 && checked[1] > 10, "{checked:?}");
}

/// Do the open triangle `t` and the open unit square `[i, i+1] x [j, j+1]`
/// meet? Separating axes (the square's two, the triangle's three edge
/// normals), exactly, in integers.
fn meets_square(t: [[i32; 2]; 3], i: i32, j: i32) -> bool {
    let square = [[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]];
    let mut axes = vec![[1i64, 0], [0, 1]];
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        axes.push([i64::from(b[1] - a[1]), i64::from(a[0] - b[0])]);
    }
    axes.iter().all(|ax| {
        let on = |q: &[i32; 2]| i64::from(q[0]) * ax[0] + i64::from(q[1]) * ax[1];
        let (t0, t1) = (t.iter().map(on).min(), t.iter().map(on).max());
        let (s0, s1) = (square.iter().map(on).min(), square.iter().map(on).max());
        t1 > s0 && s1 > t0
    })
}

/// Slab triangles of LOD `lod` that pass over a unit square of the grid
/// with no dual sample at any corner and none of its corners under the
/// triangle: the slab drawn there is at least half a texel from every slab
/// column, and no sample sees it. (A square with a corner under the
/// triangle is the vertical error's, which [`straddles`] checks.) The
/// greedy error, measured at samples, cannot see such a thin triangle,
/// and its walls stand across the whole gap.
fn slabs_off_the_dual_region(l: &Level, mesh: &LevelMesh, lod: usize) -> usize {
    let layout = ChunkLayout::of(l);
    let mut samples = ChunkSamples::default();
    let mut off = 0;
    for (i, chunk) in mesh.chunks.iter().enumerate() {
        let (cx, cy) = layout.coords(i);
        samples.load(l, &layout, cx, cy);
        let single_square = |x: i32, y: i32| samples.duals_in(x, y, x + 1, y + 1) == 0;
        for t in slab_triangles(chunk, lod).0 {
            let (x0, x1) = (t.iter().map(|p| p[0]).min(), t.iter().map(|p| p[0]).max());
            let (y0, y1) = (t.iter().map(|p| p[1]).min(), t.iter().map(|p| p[1]).max());
            let (Some(x0), Some(x1), Some(y0), Some(y1)) = (x0, x1, y0, y1) else {
                continue;
            };
            let crosses = (y0..y1)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .any(|(x, y)| {
                    let corners = [[x, y], [x + 1, y], [x + 1, y + 1], [x, y + 1]];
                    single_square(x, y)
                        && meets_square(t, x, y)
                        && !corners
                            .iter()
                            .any(|&p| barycentric(t[0], t[1], t[2], p).iter().all(|&w| w >= 0))
                });
            off += usize::from(crosses);
        }
    }
    off
}

#[test]
fn no_slab_is_drawn_over_a_gap_between_slab_columns() {
    // The generated world's canyon: two overhanging rims 30 texels apart.
    // Only slab triangles that lie within half a texel of the slab columns
    // (no unit square without a dual corner under them) may be drawn.
    let params = strata_level::generate::GenerateParams {
        seed: 1997,
        width: 512,
        height: 1024,
    };
    let l = strata_level::generate::generate_with(&params, &Default::default())
        .expect("generate")
        .level;
    let mesh = fit(&l, 4.0);
    for lod in 0..LODS {
        assert_eq!(slabs_off_the_dual_region(&l, &mesh, lod), 0, "LOD {lod}");
    }
    let l = level();
    let mesh = fit(&l, 4.0);
    for lod in 0..LODS {
        assert_eq!(
            slabs_off_the_dual_region(&l, &mesh, lod),
            0,
            "synthetic, LOD {lod}"
        );
    }
}

#[test]
fn gap_test_of_an_edge_equals_the_squares_it_meets() {
    use strata_mesh::samples::GapSquares;
    // Every segment between two dual samples of a few chunks, against the
    // separating-axis test of each square in its bounding box.
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mut s = ChunkSamples::default();
    let mut gaps = GapSquares::default();
    let mut seen = [0usize; 2];
    for chunk in [0, 3, 5] {
        let (cx, cy) = layout.coords(chunk);
        s.load(&l, &layout, cx, cy);
        gaps.load(&s);
        let duals: Vec<[i32; 2]> = (0..129 * 129)
            .filter(|&i| s.samples[i as usize].dual())
            .map(|i| [i % 129, i / 129])
            .step_by(37)
            .collect();
        for &a in &duals {
            for &b in &duals {
                let t = [a, b, b];
                let (x0, x1) = (a[0].min(b[0]), a[0].max(b[0]));
                let (y0, y1) = (a[1].min(b[1]), a[1].max(b[1]));
                // Separating axes of the open segment and the open square.
                let meets = |x: i32, y: i32| {
                    let square = [[x, y], [x + 1, y], [x + 1, y + 1], [x, y + 1]];
                    let axes = [
                        [1i64, 0],
                        [0, 1],
                        [i64::from(b[1] - a[1]), i64::from(a[0] - b[0])],
                    ];
                    axes.iter().all(|ax| {
                        let on = |q: &[i32; 2]| i64::from(q[0]) * ax[0] + i64::from(q[1]) * ax[1];
                        let (t0, t1) = (t.iter().map(on).min(), t.iter().map(on).max());
                        let (s0, s1) = (square.iter().map(on).min(), square.iter().map(on).max());
                        t1 > s0 && s1 > t0
                    })
                };
                let brute = !(y0..y1)
                    .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                    .any(|(x, y)| s.duals_in(x, y, x + 1, y + 1) == 0 && meets(x, y));
                assert_eq!(gaps.clear(a, b), brute, "{a:?} {b:?}");
                seen[usize::from(brute)] += 1;
            }
        }
    }
    assert!(seen[0] > 100 && seen[1] > 100, "{seen:?}");
}

#[test]
fn the_two_outline_parts_joined_are_the_outline_fit() {
    use strata_mesh::{OutlinePart, fit_chunks, join_outline_parts};
    let l = level();
    let layout = ChunkLayout::of(&l);
    let mut f = ChunkFitter::default();
    let ids: Vec<usize> = (0..layout.count()).collect();
    for threads in [1, 3] {
        let fitted = fit_chunks(&l, 4.0, OUTLINE, &ids, threads);
        for (&i, mesh) in ids.iter().zip(&fitted) {
            let (cx, cy) = layout.coords(i);
            let whole = f.fit_with(&l, &layout, cx, cy, 4.0, OUTLINE);
            assert_eq!(*mesh, whole, "chunk {i}, {threads} threads");
            // Either order.
            let slab = f.fit_outline_part(&l, &layout, (cx, cy), 4.0, OutlinePart::Slab);
            let floor = f.fit_outline_part(&l, &layout, (cx, cy), 4.0, OutlinePart::Floor);
            assert_eq!(join_outline_parts(slab, floor), whole, "chunk {i}");
        }
    }
}
