//! The beam pre-pass on paper (`ray_exact_beam.wgsl`): the twin of
//! `cs_exact_beam` (a camera tile's start) and of the shadow blocks'
//! 64-slice search, step for step, counting iterations and pyramid reads.

use super::BeamSearch;
use super::{LOG_RATIO, MARK_BLOCK, MAX_ALTITUDE, Replay, camera_ray, exact_base};
use crate::frame::Globals;
use glam::{IVec2, Vec3};

/// Side of a beam's square pixel tile (`BEAM_TILE` in `ray_exact_beam.wgsl`:
/// the march's 8x8 workgroup).
pub const BEAM_TILE: u32 = 8;
/// Intervals a shadow block's beam tests at once, one per invocation.
pub const SHADOW_BEAM_LANES: u32 = 64;
/// Most iterations of one beam (`BEAM_CAP`): the beam pass is a chain of
/// dependent fetches per tile, and its slowest warp sets its time. On the
/// H100 (the protocol's views, one binary, the cap swept): cap 64 gave a
/// 0.0305 ms pass and a 0.1106 ms march, 24 gives 0.0163 and 0.1150, the
/// least frame (0.1896 ms against 0.1972 without the beam; 16: 0.1919,
/// 32: 0.1911; `bench/issue36-beam/`).
pub const BEAM_CAP: u32 = 24;
/// A beam's first interval moves its rays this far (`BEAM_FIRST_STEP`).
const BEAM_FIRST_STEP: f32 = 4.0;
/// The beam box's margin for f32 rounding, absolute and relative to its
/// coordinates (`BEAM_MARGIN`, `BEAM_MARGIN_RELATIVE`).
const BEAM_MARGIN: f32 = 0.0625;
const BEAM_MARGIN_RELATIVE: f32 = 1.0e-5;

/// Intervals a wide search tests at once, one per invocation of the tile's
/// (block's) workgroup (`WIDE_LANES`).
pub const WIDE_LANES: u32 = 64;
/// Most rounds of a wide search (`WIDE_ROUNDS`): the first tests 64 slices
/// of the beam's depth range, each later one 64 sub-slices of the first
/// slice that may hold ground and has not been found clear.
pub const WIDE_ROUNDS: u32 = 8;

/// What one beam did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BeamCount {
    /// Where its rays start.
    pub t: f32,
    /// Search iterations.
    pub iterations: u32,
    /// Pyramid words read.
    pub pyramid_reads: u32,
}

impl Replay<'_> {
    /// `exact_beam` of `ray_exact_beam.wgsl`: the least t at which a ray
    /// o + t d, d in the convex hull of `d`, may meet a solid point, searched
    /// over [t0, t1] (t1 when none may), and what the search did. Each
    /// iteration bounds the hull's points over [t, t2] by the box of the
    /// corner rays' points at t and t2 (a point o + s d with s in [t, t2]
    /// and d = sum l_i d_i is sum l_i (o + s d_i), and o + s d_i lies between
    /// o + t d_i and o + t2 d_i), widened by a margin for f32 rounding, and
    /// compares its lowest altitude with the highest column top of the 2x2
    /// pyramid tiles, one level, that hold its xy extent: above it, nothing in
    /// [t, t2] is solid (every solid point of a column is at or below its top).
    pub fn beam(&mut self, o: Vec3, base: IVec2, d: [Vec3; 4], t0: f32, t1: f32) -> BeamCount {
        self.beam_of([o; 4], base, d, t0, t1)
    }

    /// [`Replay::beam`] of four corner rays o_i + t d_i (rays o + t d with
    /// (o, d) a convex combination of the corners').
    pub fn beam_of(
        &mut self,
        o: [Vec3; 4],
        base: IVec2,
        d: [Vec3; 4],
        t0: f32,
        t1: f32,
    ) -> BeamCount {
        let reach = d
            .iter()
            .map(|v| v.abs().max_element())
            .fold(0.0f32, f32::max);
        let boxed = |t: f32| {
            let p = [0, 1, 2, 3].map(|i| o[i] + d[i] * t);
            (
                p[0].min(p[1]).min(p[2].min(p[3])),
                p[0].max(p[1]).max(p[2].max(p[3])),
            )
        };
        let mut r = BeamCount {
            t: t0,
            ..BeamCount::default()
        };
        if reach == 0.0 {
            return r;
        }
        let mut t = t0;
        let mut dt = BEAM_FIRST_STEP / reach;
        let mut a = boxed(t);
        while t < t1 && r.iterations < BEAM_CAP {
            r.iterations += 1;
            let t2 = (t + dt).min(t1);
            let b = boxed(t2);
            let clear = self.box_clear(base, (a.0.min(b.0), a.1.max(b.1)), &mut r.pyramid_reads);
            if clear {
                t = t2;
                a = b;
                dt *= 2.0;
            } else if dt * reach <= (a.1.x - a.0.x).max(a.1.y - a.0.y) + 1.0 {
                break;
            } else {
                dt *= 0.5;
            }
        }
        r.t = t;
        r
    }

    /// `beam_clear` of `ray_exact_beam.wgsl`: whether nothing in the box
    /// (lo, hi), relative to `base` and widened by the margin, is solid:
    /// its lowest altitude above 255 or above the highest top of the 2x2
    /// tiles, of the finest kept level whose tile is at least its extent,
    /// that hold it. Counts the pyramid words read into `reads`.
    fn box_clear(&mut self, base: IVec2, (lo, hi): (Vec3, Vec3), reads: &mut u32) -> bool {
        let m = BEAM_MARGIN + BEAM_MARGIN_RELATIVE * lo.abs().max(hi.abs()).max_element();
        let (lo, hi) = (lo - Vec3::splat(m), hi + Vec3::splat(m));
        if lo.z > MAX_ALTITUDE {
            return true;
        }
        let ext = (hi.x - lo.x).max(hi.y - lo.y);
        if self.traversal.beam_texels && ext <= 1.0 {
            return self.texels_clear(base, lo, hi, reads);
        }
        let mut shift = LOG_RATIO;
        while shift < self.top && ((1u32 << shift) as f32) < ext {
            shift += LOG_RATIO;
        }
        let size = (1u32 << shift) as f32;
        if size < ext {
            return false;
        }
        let inv = 1.0 / size;
        let tiles = base >> shift as i32;
        let c0 = (lo.truncate() * inv).floor().as_ivec2() + tiles;
        let c1 = (hi.truncate() * inv).floor().as_ivec2() + tiles;
        *reads += 4;
        let h = self
            .maxmip(shift, c0.x, c0.y)
            .max(self.maxmip(shift, c1.x, c0.y))
            .max(
                self.maxmip(shift, c0.x, c1.y)
                    .max(self.maxmip(shift, c1.x, c1.y)),
            );
        if lo.z > h {
            return true;
        }
        if !self.traversal.cave_skip {
            return false;
        }
        // Between every one of the four tiles' floors and slabs (the GPU
        // reads the four words at once).
        *reads += 4;
        [(c0.x, c0.y), (c1.x, c0.y), (c0.x, c1.y), (c1.x, c1.y)]
            .into_iter()
            .all(|(x, y)| self.cave_clear(shift, x, y, lo.z, hi.z))
    }

    /// `texels_clear` of `ray_exact_beam.wgsl`: a box at most a texel wide
    /// against the (at most 2x2) texels that hold it: above every one's top,
    /// or between every one's floor and slab. Counts the texels read into
    /// `reads` (the GPU reads them in order and stops at the first that is
    /// not clear).
    fn texels_clear(&mut self, base: IVec2, lo: Vec3, hi: Vec3, reads: &mut u32) -> bool {
        let c0 = lo.truncate().floor().as_ivec2() + base;
        let c1 = hi.truncate().floor().as_ivec2() + base;
        for (x, y) in [(c0.x, c0.y), (c1.x, c0.y), (c0.x, c1.y), (c1.x, c1.y)] {
            *reads += 1;
            let c = self.column(x, y);
            let above = lo.z > f32::from(c.top());
            let bottom = if c.dual {
                c.mid
            } else {
                strata_maxmip::NO_SLAB
            };
            let between = self.traversal.cave_skip
                && lo.z > f32::from(c.low) + super::CAVE_MARGIN
                && hi.z < f32::from(bottom) - super::CAVE_MARGIN;
            if !above && !between {
                return false;
            }
        }
        true
    }

    /// `wide_search` of `ray_exact_beam.wgsl`: the least t in [ta, tb] at
    /// which a ray o + t d with o in the box (o_lo, o_hi) and d in the box
    /// (d_lo, d_hi) may be solid (tb when none may), searched by
    /// [`WIDE_LANES`] invocations at once in at most `rounds` rounds (1 to
    /// [`WIDE_ROUNDS`]). Such a ray's point at t >= 0 lies
    /// in the box (o_lo + t d_lo, o_hi + t d_hi), whose corners are affine in
    /// t, so over [a, b] (0 <= a <= b) in the union of the boxes at a and b.
    /// Round 1: invocation k tests slice k of 64 equal slices of [ta, tb];
    /// each later round, sub-slice j of 64 of the first slice that is not
    /// clear and not yet refined. The start is the first sub-slice that is
    /// not clear, else the next slice not clear (every interval before it was
    /// found clear: the slices' bounds are shared by neighbours, and the last
    /// is exactly the slice's end). `iterations`: the rounds.
    pub fn wide_beam(
        &mut self,
        base: IVec2,
        (o_lo, o_hi): (Vec3, Vec3),
        (d_lo, d_hi): (Vec3, Vec3),
        (ta, tb): (f32, f32),
        rounds: u32,
    ) -> BeamCount {
        let lanes = WIDE_LANES;
        let rounds = rounds.clamp(1, WIDE_ROUNDS);
        let mut r = BeamCount {
            t: tb,
            ..BeamCount::default()
        };
        // One round: the first of the 64 intervals of [lo, hi] that is
        // not clear, as a mask; one lane's pyramid reads added.
        let round = |replay: &mut Self, lo: f32, hi: f32, reads: &mut u32| {
            let (mut mask, mut most) = (0u64, 0);
            for k in 0..lanes {
                let (a, b) = (wide_bound(lo, hi, k), wide_bound(lo, hi, k + 1));
                let (lo_a, hi_a) = (o_lo + d_lo * a, o_hi + d_hi * a);
                let (lo_b, hi_b) = (o_lo + d_lo * b, o_hi + d_hi * b);
                let mut n = 0;
                if !replay.box_clear(base, (lo_a.min(lo_b), hi_a.max(hi_b)), &mut n) {
                    mask |= 1 << k;
                }
                most = most.max(n);
            }
            *reads += most;
            mask
        };
        // Round 1: which of the 64 slices may hold ground.
        let mut mask = round(self, ta, tb, &mut r.pyramid_reads);
        r.iterations = 1;
        // Later rounds: refine the first slice not yet found clear.
        while mask != 0 {
            let c = mask.trailing_zeros();
            let (lo, hi) = (wide_bound(ta, tb, c), wide_bound(ta, tb, c + 1));
            if r.iterations >= rounds {
                r.t = lo;
                return r;
            }
            r.iterations += 1;
            let sub = round(self, lo, hi, &mut r.pyramid_reads);
            if sub != 0 {
                r.t = wide_bound(lo, hi, sub.trailing_zeros());
                return r;
            }
            mask &= !(1u64 << c);
        }
        r
    }

    /// The wide search of the [`BEAM_TILE`]-pixel square tile (tx, ty)
    /// (`exact_wide_tile_start`): its corner rays' directions boxed, the
    /// depth range cut to where a ray of the tile may be at or below 255 and
    /// to where every one is below 0 (`wide_range`).
    pub fn tile_beam_wide(&mut self, g: &Globals, tx: u32, ty: u32) -> BeamCount {
        let (o, base, d, t0, t1) = tile_corners(g, tx, ty);
        let d_lo = d[0].min(d[1]).min(d[2].min(d[3]));
        let d_hi = d[0].max(d[1]).max(d[2].max(d[3]));
        let (ta, tb) = wide_range(o.z, o.z, d_lo.z, d_hi.z, t0, t1);
        self.wide_beam(base, (o, o), (d_lo, d_hi), (ta, tb), WIDE_ROUNDS)
    }

    /// The wide search of the shadow block whose first texel is (i, j)
    /// (`exact_shadow_block_start` with the wide search): the corner texels'
    /// rays' starts boxed, one direction, over [0, span].
    pub fn shadow_beam_wide(&mut self, g: &Globals, i: u32, j: u32) -> BeamCount {
        let (o, base, d, span) = self.shadow_corners(g, i, j);
        let o_lo = o[0].min(o[1]).min(o[2].min(o[3]));
        let o_hi = o[0].max(o[1]).max(o[2].max(o[3]));
        let rounds = self.traversal.shadow_rounds;
        self.wide_beam(base, (o_lo, o_hi), (d, d), (0.0, span), rounds)
    }

    /// The tile's beam by the traversal's search.
    pub fn tile_start(&mut self, g: &Globals, tx: u32, ty: u32) -> BeamCount {
        match self.traversal.search {
            BeamSearch::Serial => self.tile_beam(g, tx, ty),
            BeamSearch::Wide | BeamSearch::WidePass => self.tile_beam_wide(g, tx, ty),
        }
    }

    /// The shadow block's beam by the traversal's search.
    pub fn shadow_block_start(&mut self, g: &Globals, i: u32, j: u32) -> BeamCount {
        self.without_caves(|replay| match replay.traversal.search {
            BeamSearch::Serial => replay.shadow_beam(g, i, j),
            BeamSearch::Wide | BeamSearch::WidePass => replay.shadow_beam_wide(g, i, j),
        })
    }

    /// The shadow block's four corner texels' rays: starts relative to the
    /// base, the base, the light's direction and the first's span.
    fn shadow_corners(&self, g: &Globals, i: u32, j: u32) -> ([Vec3; 4], IVec2, Vec3, f32) {
        let d = Vec3::from_slice(&g.light_dir[..3]);
        let far = (MARK_BLOCK - 1) as u32;
        let p = [(i, j), (i + far, j), (i, j + far), (i + far, j + far)]
            .map(|(a, b)| self.shadow_start(g, a, b).0);
        let base = exact_base(p[0].truncate());
        let o = p.map(|q| (q.truncate() - base.as_vec2()).extend(q.z));
        (o, base, d, self.shadow_start(g, i, j).1)
    }

    /// `exact_shadow_block_start` of `ray_exact_beam.wgsl`: the beam of the
    /// shadow block whose first texel is (i, j), searched by its 64
    /// invocations at once: invocation k tests the k-th of 64 equal
    /// intervals of [0, span] (the four corner texels' rays are parallel;
    /// each of the block's rays is a convex combination of theirs), and the
    /// block's rays start at the first that is not clear. One iteration each.
    pub fn shadow_beam(&mut self, g: &Globals, i: u32, j: u32) -> BeamCount {
        let (o, base, d, span) = self.shadow_corners(g, i, j);
        let boxed = |t: f32| {
            let p = o.map(|q| q + d * t);
            (
                p[0].min(p[1]).min(p[2].min(p[3])),
                p[0].max(p[1]).max(p[2].max(p[3])),
            )
        };
        let lanes = SHADOW_BEAM_LANES;
        let mut r = BeamCount {
            t: span,
            iterations: 1,
            pyramid_reads: 0,
        };
        for k in 0..lanes {
            let ta = span * (k as f32 / lanes as f32);
            let tb = span * ((k + 1) as f32 / lanes as f32);
            let (a, b) = (boxed(ta), boxed(tb));
            let mut reads = 0;
            if !self.box_clear(base, (a.0.min(b.0), a.1.max(b.1)), &mut reads) {
                r.t = r.t.min(ta);
            }
            r.pyramid_reads = r.pyramid_reads.max(reads);
        }
        r
    }

    /// `cs_exact_beam` of `ray_exact_beam.wgsl`: the beam of the
    /// [`BEAM_TILE`]-pixel square tile (tx, ty), through its corner pixels'
    /// centres (every pixel's ray is a convex combination of theirs:
    /// `camera_ray` is affine in the pixel).
    pub fn tile_beam(&mut self, g: &Globals, tx: u32, ty: u32) -> BeamCount {
        let (o, base, d, t0, t1) = tile_corners(g, tx, ty);
        self.beam(o, base, d, t0, t1)
    }
}

/// The [`BEAM_TILE`]-pixel square tile (tx, ty)'s rays: the eye relative to
/// the base, the base, the corner pixels' rays and the near and far `t`.
fn tile_corners(g: &Globals, tx: u32, ty: u32) -> (Vec3, IVec2, [Vec3; 4], f32, f32) {
    let (w, h) = (g.screen[0] as u32, g.screen[1] as u32);
    let (x0, y0) = (tx * BEAM_TILE, ty * BEAM_TILE);
    let xa = x0 as f32 + 0.5;
    let ya = y0 as f32 + 0.5;
    let xb = (x0 + BEAM_TILE).min(w) as f32 - 0.5;
    let yb = (y0 + BEAM_TILE).min(h) as f32 - 0.5;
    let d = [
        camera_ray(g, xa, ya),
        camera_ray(g, xb, ya),
        camera_ray(g, xa, yb),
        camera_ray(g, xb, yb),
    ];
    let eye = Vec3::from_slice(&g.eye[..3]);
    let focal = g.eye[3];
    let base = exact_base(eye.truncate());
    let o = (eye.truncate() - base.as_vec2()).extend(eye.z);
    (o, base, d, g.forward[3] / focal, g.right[3] / focal)
}

/// `wide_bound` of `ray_exact_beam.wgsl`: bound k of 64 equal slices of
/// [lo, hi] (bound 64 is hi itself, so neighbouring slices and rounds share
/// their bounds exactly).
fn wide_bound(lo: f32, hi: f32, k: u32) -> f32 {
    if k >= WIDE_LANES {
        hi
    } else {
        lo + (hi - lo) * (k as f32 / WIDE_LANES as f32)
    }
}

/// `wide_range` of `ray_exact_beam.wgsl`: [t0, t1] cut to where rays
/// o + t d (o.z in [oz_lo, oz_hi], d.z in [dz_lo, dz_hi]) may hold a solid
/// point: nothing is solid above 255, so not before the earliest t at which
/// one may come down to 255 (less a relative margin: the search tests from
/// there, and a start earlier than needed is still safe); and every point at
/// or below 0 is solid, so every ray has met the ground once all are below
/// -1 (the search need not look further). Empty (x >= y) when no ray comes
/// down to 255 before t1.
pub(super) fn wide_range(
    oz_lo: f32,
    oz_hi: f32,
    dz_lo: f32,
    dz_hi: f32,
    t0: f32,
    t1: f32,
) -> (f32, f32) {
    let mut a = t0;
    let mut b = t1;
    if oz_lo > MAX_ALTITUDE {
        if dz_lo >= 0.0 {
            return (t1, t1);
        }
        a = a.max((MAX_ALTITUDE - oz_lo) / dz_lo * (1.0 - WIDE_RANGE_MARGIN));
    }
    if dz_hi < 0.0 {
        b = b.min((-1.0 - oz_hi) / dz_hi * (1.0 + WIDE_RANGE_MARGIN));
    }
    (a, b.max(a))
}

/// `WIDE_RANGE_MARGIN`: [`wide_range`]'s relative margin for f32 rounding.
const WIDE_RANGE_MARGIN: f32 = 1.0e-4;
