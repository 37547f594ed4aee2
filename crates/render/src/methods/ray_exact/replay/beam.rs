//! The beam pre-pass on paper (`ray_exact_beam.wgsl`): the twin of
//! `cs_exact_beam` (a camera tile's start) and of the shadow blocks'
//! 64-slice search, step for step, counting iterations and pyramid reads.

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
        lo.z > h
    }

    /// `exact_shadow_block_start` of `ray_exact_beam.wgsl`: the beam of the
    /// shadow block whose first texel is (i, j), searched by its 64
    /// invocations at once: invocation k tests the k-th of 64 equal
    /// intervals of [0, span] (the four corner texels' rays are parallel;
    /// each of the block's rays is a convex combination of theirs), and the
    /// block's rays start at the first that is not clear. One iteration each.
    pub fn shadow_beam(&mut self, g: &Globals, i: u32, j: u32) -> BeamCount {
        let d = Vec3::from_slice(&g.light_dir[..3]);
        let far = (MARK_BLOCK - 1) as u32;
        let p = [(i, j), (i + far, j), (i, j + far), (i + far, j + far)]
            .map(|(a, b)| self.shadow_start(g, a, b).0);
        let base = exact_base(p[0].truncate());
        let o = p.map(|q| (q.truncate() - base.as_vec2()).extend(q.z));
        let span = self.shadow_start(g, i, j).1;
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
        self.beam(o, base, d, g.forward[3] / focal, g.right[3] / focal)
    }
}
