//! `scattered` (§3.5): point samples of the terrain scattered into a screen
//! buffer by a compute pass, the nearest kept by a 32-bit `atomicMin` of
//! `(24-bit depth << 8) | info` (info: surface kind << 3 | terrain type); a
//! full-screen pass then rebuilds each pixel's point from its depth and shades
//! it (`shaders/scattered.wgsl`, `shaders/scattered_resolve.wgsl`).
//!
//! # The grid and `scatter_density` (X, Y, Z)
//! Every density is in screen terms: X, Y and Z ask for `X * PER_PIXEL[0]`
//! samples per pixel across, `Y * PER_PIXEL[1]` along the (warped) distance
//! axis and `Z * PER_PIXEL[2]` per pixel of a column's projected height. The
//! paper's default (4, 4, 4) is 1.25, 1 and 1.25 ([`PER_PIXEL`]): a point splats
//! one pixel, so fewer leave holes (2 per 4 pixels: 50 % see-through at the
//! horizon) and more buy little. Work per frame grows with the image, not
//! with the world's texels.
//!
//! The footprint is the part of the frustum (near to far) with altitude in
//! 0..=256, seen from above in camera-aligned coordinates: `a` along the
//! horizontal heading `flat`, `c` along `right`, both from the eye. Its
//! outline is a convex polygon. A column at `(a, c)` is at least
//! `sqrt(a² + c² + h²)` from the eye, `h` the eye's clearance above the
//! highest column top in the footprint's bounding box (from a per-tile maximum
//! of the level, [`TopMax`]; at least the near distance), so one pixel there
//! is at most that distance / focal wide, taken at the image corners (whose
//! pixels are the smallest in angle). So the grid is
//! - rows uniform in `asinh(a / h)`, spacing `sqrt(a² + h²) / (focal * Y')`:
//!   logarithmic (like perspective) far away, fine only where the terrain can
//!   come close to the eye;
//! - columns uniform in `asinh(c / d)` within a row, `d = sqrt(a² + h²)`,
//!   spacing `sqrt(c² + d²) / (focal * X')`; `cols` is what the neediest row
//!   wants, and a row that wants fewer keeps every `2^k`-th (the rest return
//!   at once);
//! - a walk down each solid interval from its top, `[0, low]` and for a dual
//!   column `[mid, high]`, over the part that projects into the view (clipped
//!   analytically), each step `1 / Z'` pixels of the interval's projected
//!   height at that point, so a far column takes a few points and a column
//!   seen end-on one. The floor walk stops half a unit below the four
//!   neighbouring samples' floors (at the grid spacing: only the samples next
//!   to a texel's edge walk its sides),
//!   where boxes would hide it, and the slab's walk skips the part every
//!   neighbour's slab (or floor) hides; without this most points of a horizon
//!   view were buried inside the terrain.
//!
//! A sample whose whole column (0..=256) is off screen returns before reading
//! the texture. A grid over [`MAX_GRID`] samples is scaled down (both axes
//! alike) with a warning; each density is capped at [`MAX_DENSITY`]. Results
//! depend only on the camera and the terrain, never on earlier frames, so an
//! edit shows in the next frame (edits refresh the tile maximum).
//! [`count_points`] is a CPU twin of the scatter that counts its work.

use super::forward::{Z_MAX, footprint_bounds};
use super::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{COLOR_FORMAT, DEPTH_FORMAT, Shared, sky_clear, uniform_layout_entry};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use strata_camera::Camera;
use strata_level::Level;

/// Most grid samples per frame (16 M).
pub const MAX_GRID: u64 = 1 << 24;
/// Most of each density (X, Y, Z).
pub const MAX_DENSITY: f32 = 64.0;
/// Samples per pixel that a density of 1 asks for, across, along and
/// vertically: (4, 4, 4) is 1.25 across (one exactly left holes in about 1 %
/// of a horizon view), 1 along and 1.25 vertically (one left rows of holes in
/// near walls, which only the samples next to a texel's edge walk).
pub const PER_PIXEL: [f32; 3] = [0.3125, 0.25, 0.3125];
/// Radius (texels, a square) around the eye whose highest column top sets
/// the clearance `h`.
pub const NEAR_RADIUS: f32 = 96.0;
/// Side of the tiles of the level's column-top maximum, texels.
const TILE: u32 = 16;
/// Most footprint polygon vertices the uniform holds (a frustum cut by a slab
/// has at most 12).
const MAX_HULL: usize = 16;
/// Invocations per scatter workgroup (`WORKGROUP` in scattered.wgsl).
const WORKGROUP: u32 = 64;

/// Twin of `ScatterParams` in scattered.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ScatterParams {
    /// `flat` xy, `right` xy.
    pub axes: [f32; 4],
    /// Eye xy, the warp scale and clearance `h`, vertical samples per pixel.
    pub origin: [f32; 4],
    /// asinh(a / h) of the nearest and farthest row bound; columns a row needs
    /// per unit of its warped width (`across_warp`); unused.
    pub warp: [f32; 4],
    /// Rows, columns, polygon vertices, vertical samples per interval at most.
    pub grid: [u32; 4],
    /// The footprint polygon (a, c), two vertices per entry.
    pub hull: [[f32; 4]; MAX_HULL / 2],
}

impl ScatterParams {
    pub fn samples(&self) -> u64 {
        u64::from(self.grid[0]) * u64::from(self.grid[1])
    }

    fn vertex(&self, i: usize) -> [f32; 2] {
        let v = self.hull[i / 2];
        if i.is_multiple_of(2) {
            [v[0], v[1]]
        } else {
            [v[2], v[3]]
        }
    }

    /// The across range of the footprint polygon at distance `a`, `None`
    /// outside it (the CPU twin of `row_range`).
    pub fn row_range(&self, a: f32) -> Option<(f32, f32)> {
        let n = self.grid[2] as usize;
        let mut r: Option<(f32, f32)> = None;
        for i in 0..n {
            let (p, q) = (self.vertex(i), self.vertex((i + 1) % n));
            if a < p[0].min(q[0]) || a > p[0].max(q[0]) {
                continue;
            }
            let c = if q[0] != p[0] {
                p[1] + (q[1] - p[1]) * (a - p[0]) / (q[0] - p[0])
            } else {
                p[1]
            };
            r = Some(r.map_or((c, c), |(lo, hi)| (lo.min(c), hi.max(c))));
        }
        r
    }
}

/// Convex hull, counter-clockwise, without collinear points (monotone chain).
fn convex_hull(mut pts: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    pts.sort_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let turn = |o: [f32; 2], a: [f32; 2], b: [f32; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f32; 2]> = Vec::with_capacity(2 * pts.len());
    for pass in [false, true] {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f32; 2]>> = if pass {
            Box::new(pts.iter().rev())
        } else {
            Box::new(pts.iter())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The highest column top of each `TILE`² tile of a level, to bound how close
/// the terrain of a footprint can come to the eye.
#[derive(Clone, Debug)]
pub struct TopMax {
    size: [u32; 2],
    tiles: [u32; 2],
    tile: [u32; 2],
    top: Vec<u8>,
}

impl TopMax {
    pub fn new(level: &Level) -> Self {
        let size = [level.width(), level.height()];
        let tile = [TILE.min(size[0]), TILE.min(size[1])];
        let tiles = [size[0].div_ceil(tile[0]), size[1].div_ceil(tile[1])];
        let mut m = TopMax {
            size,
            tiles,
            tile,
            top: vec![0u8; (tiles[0] * tiles[1]) as usize],
        };
        for ty in 0..tiles[1] {
            for tx in 0..tiles[0] {
                m.refresh(level, tx, ty);
            }
        }
        m
    }

    /// Recompute tile (tx, ty) from the level.
    fn refresh(&mut self, level: &Level, tx: u32, ty: u32) {
        let mut t = 0u8;
        for y in ty * self.tile[1]..((ty + 1) * self.tile[1]).min(self.size[1]) {
            for x in tx * self.tile[0]..((tx + 1) * self.tile[0]).min(self.size[0]) {
                t = t.max(level.column(i64::from(x), i64::from(y)).top());
            }
        }
        self.top[(ty * self.tiles[0] + tx) as usize] = t;
    }

    /// Recompute the tiles `rect` touches (a pair's partner included).
    pub fn update(&mut self, level: &Level, rect: &strata_level::DirtyRect) {
        if rect.width == 0 || rect.height == 0 {
            return;
        }
        let x0 = rect.x.saturating_sub(1).min(self.size[0] - 1) / self.tile[0];
        let x1 = (rect.x + rect.width).min(self.size[0] - 1) / self.tile[0];
        let y0 = rect.y.min(self.size[1] - 1) / self.tile[1];
        let y1 = (rect.y + rect.height - 1).min(self.size[1] - 1) / self.tile[1];
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                self.refresh(level, tx, ty);
            }
        }
    }

    /// The highest column top in `camera`'s footprint and within
    /// [`NEAR_RADIUS`] of its eye.
    pub fn bounds(&self, camera: &Camera) -> (f32, f32) {
        let Some((lo, hi)) = footprint_bounds(camera, camera.far) else {
            return (0.0, 0.0);
        };
        let (e, r) = (camera.position, NEAR_RADIUS);
        (
            self.max_in(lo, hi),
            self.max_in([e.x - r, e.y - r], [e.x + r, e.y + r]),
        )
    }

    /// The highest column top with texel (x, y) in `lo..=hi` (wrapping).
    pub fn max_in(&self, lo: [f32; 2], hi: [f32; 2]) -> f32 {
        let range = |k: usize| {
            let t = i64::from(self.tile[k]);
            let (a, b) = (
                (lo[k].floor() as i64).div_euclid(t),
                (hi[k].floor() as i64).div_euclid(t),
            );
            let n = i64::from(self.tiles[k]);
            let w = i64::from(self.size[k]);
            if b - a + 1 >= n {
                (0..n).collect::<Vec<_>>()
            } else {
                (a..=b).map(|i| (i * t).rem_euclid(w) / t).collect()
            }
        };
        let (xs, ys) = (range(0), range(1));
        let mut m = 0u8;
        for &ty in &ys {
            for &tx in &xs {
                m = m.max(self.top[(ty * i64::from(self.tiles[0]) + tx) as usize]);
            }
        }
        f32::from(m)
    }
}

/// Points whose convex hull is the part of the frustum (near to far) with
/// altitude in `0..=top` (as `forward::frustum_slab_points`, which cuts at
/// `Z_MAX`): no terrain in view lies outside it when no column top in view is
/// above `top`.
pub fn slab_points(camera: &Camera, top: f32) -> Vec<Vec3> {
    let (w, h) = (camera.width as f32, camera.height as f32);
    let image = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)];
    let corners = |d: f32| {
        image.map(|(px, py)| {
            camera.position + camera.image_direction(px, py) * (d / camera.focal_px)
        })
    };
    let (near, far) = (corners(camera.near), corners(camera.far));
    let mut points: Vec<Vec3> = near
        .iter()
        .chain(&far)
        .copied()
        .filter(|p| (0.0..=top).contains(&p.z))
        .collect();
    for i in 0..4 {
        let j = (i + 1) % 4;
        for (a, b) in [(near[i], near[j]), (far[i], far[j]), (near[i], far[i])] {
            for z in [0.0, top] {
                if (a.z - z) * (b.z - z) < 0.0 {
                    points.push(a.lerp(b, (z - a.z) / (b.z - a.z)));
                }
            }
        }
    }
    points
}

/// The grid for `camera` at `density` (X, Y, Z, each already within
/// [`MAX_DENSITY`]) when no column top in the footprint is above `max_top`
/// and none within [`NEAR_RADIUS`] of the eye above `near_top`, at
/// most `max_samples` samples; the second value is a warning when the grid
/// had to be scaled down.
pub fn scatter_grid(
    camera: &Camera,
    density: [f32; 3],
    max_top: f32,
    near_top: f32,
    max_samples: u64,
) -> (ScatterParams, Option<String>) {
    let b = camera.basis();
    let e = camera.position;
    let [xp, yp, zp] = [0, 1, 2].map(|i| density[i] * PER_PIXEL[i]);
    // Clearance: a column top lies at least this far below the eye.
    // Clearance over the columns within NEAR_RADIUS; a column beyond is at
    // least NEAR_RADIUS >= 3 h away across the ground, so sqrt(r² + h²)
    // overstates its distance by at most sqrt(1 + 1/9): `per_px` makes up
    // for that.
    // The clearance above the whole footprint needs no cap: the larger wins.
    let h = (e.z - near_top.min(max_top))
        .min(NEAR_RADIUS / 3.0)
        .max(e.z - max_top)
        .max(camera.near);
    let (w, ht) = (camera.width as f32, camera.height as f32);
    let f = camera.focal_px;
    // Pixels per unit of length per unit of distance, at the image's corners
    // (the smallest pixels in angle are the ones that need the samples): at
    // `r` pixels from the centre a radian spans `(f² + r²) / f` pixels
    // radially. (Taking `f² / sqrt(f² + r²)` instead starved large images:
    // 5.7x too few samples per axis at 1280x800, 31 % see-through.)
    let r2 = 0.25 * (w * w + ht * ht);
    let per_px = (f * f + r2) / f * (10.0f32 / 9.0).sqrt();
    let mut params = ScatterParams {
        axes: [b.flat.x, b.flat.y, b.right.x, b.right.y],
        origin: [e.x, e.y, h, zp],
        ..Default::default()
    };
    let pts = slab_points(camera, (max_top + 1.0).min(Z_MAX))
        .into_iter()
        .map(|p| {
            let r = p - e;
            [r.dot(b.flat), r.dot(b.right)]
        })
        .collect();
    let mut hull = convex_hull(pts);
    if hull.len() < 3 {
        return (params, None);
    }
    if hull.len() > MAX_HULL {
        // Cannot happen for a frustum (12 at most); the bounding box is safe.
        let (mut lo, mut hi) = (hull[0], hull[0]);
        for p in &hull {
            lo = [lo[0].min(p[0]), lo[1].min(p[1])];
            hi = [hi[0].max(p[0]), hi[1].max(p[1])];
        }
        hull = vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    }
    for (i, p) in hull.iter().enumerate() {
        let slot = &mut params.hull[i / 2];
        slot[2 * (i % 2)..2 * (i % 2) + 2].copy_from_slice(p);
    }
    params.grid[2] = hull.len() as u32;
    let a0 = hull.iter().map(|p| p[0]).fold(f32::INFINITY, f32::min);
    let a1 = hull.iter().map(|p| p[0]).fold(f32::NEG_INFINITY, f32::max);
    let (s0, s1) = ((a0 / h).asinh(), (a1 / h).asinh());
    let col_scale = xp * per_px;
    // Columns the neediest row wants: the hull's vertices and 64 rows
    // between (uniform in the warp, like the rows).
    let need = |a: f32| {
        params
            .row_range(a)
            .map_or(0.0, |(lo, hi)| col_scale * across_warp(lo, hi, a, h))
    };
    let widest = hull
        .iter()
        .map(|p| need(p[0]))
        .chain((0..=64).map(|i| need(h * (s0 + (s1 - s0) * i as f32 / 64.0).sinh())))
        .fold(0.0f32, f32::max);
    let mut rows = (f64::from(yp * per_px) * f64::from(s1 - s0))
        .ceil()
        .max(1.0);
    let mut cols = f64::from(widest).ceil().max(1.0);
    let mut warning = None;
    if rows * cols > max_samples as f64 {
        let k = (max_samples as f64 / (rows * cols)).sqrt();
        let (r, c) = ((rows * k).floor().max(1.0), (cols * k).floor().max(1.0));
        warning = Some(format!(
            "scattered: the grid of {rows:.0} x {cols:.0} samples exceeds {max_samples}; \
             using {r:.0} x {c:.0} (density scaled by {k:.3})"
        ));
        (rows, cols) = (r, c.min((max_samples as f64 / r).floor()));
    }
    params.grid[0] = rows as u32;
    params.grid[1] = cols as u32;
    // A clipped interval projects inside the image: at most about w + h
    // pixels long.
    params.grid[3] = (zp * (w + ht)).ceil() as u32 + 2;
    params.warp = [s0, s1, col_scale, 0.0];
    (params, warning)
}

/// The warped width of a row at distance `a` spanning `lo..=hi` across:
/// columns are uniform in `asinh(c / d)`, `d = sqrt(a² + h²)` the row's least
/// distance, as a column at `c` is at least `sqrt(c² + d²)` from the eye.
fn across_warp(lo: f32, hi: f32, a: f32, h: f32) -> f32 {
    let d = (a * a + h * h).sqrt();
    (hi / d).asinh() - (lo / d).asinh()
}

/// The altitudes of `lo..=hi` whose points `base + z * dz` (clip space) lie
/// inside the view (the CPU twin of `clip_altitudes`).
fn clip_altitudes(base: glam::Vec4, dz: glam::Vec4, lo: f32, hi: f32) -> Option<(f32, f32)> {
    let alpha = [
        base.w + base.x,
        base.w - base.x,
        base.w + base.y,
        base.w - base.y,
        base.z,
        base.w - base.z,
    ];
    let beta = [
        dz.w + dz.x,
        dz.w - dz.x,
        dz.w + dz.y,
        dz.w - dz.y,
        dz.z,
        dz.w - dz.z,
    ];
    let (mut lo, mut hi) = (lo, hi);
    for (a, b) in alpha.into_iter().zip(beta) {
        if b.abs() < 1e-12 {
            if a < 0.0 {
                return None;
            }
        } else if b > 0.0 {
            lo = lo.max(-a / b);
        } else {
            hi = hi.min(-a / b);
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// What one frame's scatter does, counted on the CPU (a twin of
/// `cs_scatter`): (samples that walk a column, points scattered).
pub fn count_points(level: &Level, camera: &Camera, density: [f32; 3]) -> (u64, u64) {
    let tops = TopMax::new(level);
    let (max_top, near_top) = tops.bounds(camera);
    let (p, _) = scatter_grid(camera, density, max_top, near_top, MAX_GRID);
    let vp = camera.view_proj();
    let (rows, cols) = (p.grid[0], p.grid[1]);
    let h = p.origin[2];
    let (w, ht) = (camera.width as f32, camera.height as f32);
    let (mut samples, mut points) = (0u64, 0u64);
    for row in 0..rows {
        let s = p.warp[0] + (p.warp[1] - p.warp[0]) * (row as f32 + 0.5) / rows as f32;
        let a = h * s.sinh();
        let Some((lo, hi)) = p.row_range(a) else {
            continue;
        };
        let d = (a * a + h * h).sqrt();
        let u = ((lo / d).asinh(), (hi / d).asinh());
        let ratio = cols as f32 / (p.warp[2] * (u.1 - u.0)).max(1e-6);
        let k = if ratio >= 2.0 {
            1u32 << (ratio.log2().floor() as u32).min(30)
        } else {
            1
        };
        let da = d * (p.warp[1] - p.warp[0]) / rows as f32;
        for col in (0..cols).step_by(k as usize) {
            let across = d * (u.0 + (u.1 - u.0) * (col as f32 + 0.5) / cols as f32).sinh();
            let x = p.origin[0] + p.axes[0] * a + p.axes[2] * across;
            let y = p.origin[1] + p.axes[1] * a + p.axes[3] * across;
            let base = vp.col(0) * x + vp.col(1) * y + vp.col(3);
            let dz = vp.col(2);
            let Some((r0, r1)) = clip_altitudes(base, dz, 0.0, 256.0) else {
                continue;
            };
            samples += 1;
            let c = level.column_at(x, y);
            let dc = (across * across + d * d).sqrt() * (u.1 - u.0) * k as f32 / cols as f32;
            let mut cover = f32::from(c.low);
            let mut hid = (-1e9f32, 1e9f32);
            for (fa, fc) in [(da, 0.0), (-da, 0.0), (0.0, dc), (0.0, -dc)] {
                let nx = x + p.axes[0] * fa + p.axes[2] * fc;
                let ny = y + p.axes[1] * fa + p.axes[3] * fc;
                let n = level.column_at(nx, ny);
                cover = cover.min(f32::from(n.low));
                let hn = if n.dual {
                    (f32::from(n.mid), f32::from(n.high))
                } else {
                    (-1e9, f32::from(n.low))
                };
                hid = (hid.0.max(hn.0), hid.1.min(hn.1));
            }
            let bottom = cover - 0.5;
            let top = r1.min(f32::from(c.low));
            let mut intervals = vec![(bottom.max(r0).min(top), top)];
            if c.dual {
                let (lo, hi) = (r0.max(f32::from(c.mid)), r1.min(f32::from(c.high)));
                let (core_top, core_bottom) = (hid.1 - 0.5, hid.0 + 0.5);
                if core_bottom < core_top {
                    intervals.push((core_top.max(lo).min(hi), hi));
                    intervals.push((lo, core_bottom.min(hi).max(lo)));
                } else {
                    intervals.push((lo, hi));
                }
            }
            for (z0, z1) in intervals {
                if z0 > z1 {
                    continue;
                }
                let mut z = z1;
                for _ in 0..p.grid[3] {
                    points += 1;
                    if z <= z0 {
                        break;
                    }
                    let q = base + dz * z;
                    let dd = (dz.truncate().truncate() * q.w - q.truncate().truncate() * dz.w)
                        / (q.w * q.w);
                    let rate = (dd * glam::Vec2::new(w, ht) * 0.5).length();
                    z = (z - 1.0 / (p.origin[3] * rate.max(1e-4))).max(z0);
                }
            }
        }
    }
    (samples, points)
}

/// The density, checked: each positive and finite, each capped at
/// [`MAX_DENSITY`].
pub fn checked_density(density: [f32; 3]) -> anyhow::Result<[f32; 3]> {
    if density.iter().any(|d| !d.is_finite() || *d <= 0.0) {
        anyhow::bail!("scatter density must be positive and finite in X, Y and Z, got {density:?}");
    }
    let mut d = density;
    for v in &mut d {
        if *v > MAX_DENSITY {
            eprintln!(
                "warning: scattered: a density of {v} is over {MAX_DENSITY}; using {MAX_DENSITY}"
            );
            *v = MAX_DENSITY;
        }
    }
    Ok(d)
}

pub struct Scattered {
    density: [f32; 3],
    tops: TopMax,
    params: wgpu::Buffer,
    screen_bytes: u64,
    clear: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    scatter_group: wgpu::BindGroup,
    resolve: wgpu::RenderPipeline,
    resolve_group: wgpu::BindGroup,
    /// Most samples one frame may have: [`MAX_GRID`] and the dispatch limits.
    max_samples: u64,
    max_groups: u32,
    /// Workgroups of this frame's scatter (x, y); (0, 0) when nothing is in view.
    groups: (u32, u32),
    warned: bool,
}

fn storage_entry(
    binding: u32,
    read_only: bool,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let density = checked_density(settings.scatter_density)?;
    let device = &shared.device;
    let limits = device.limits();
    let screen_bytes = u64::from(shared.width) * u64::from(shared.height) * 4;
    let max_binding = limits.max_storage_buffer_binding_size;
    if screen_bytes > max_binding {
        anyhow::bail!(
            "scattered: a {}x{} screen buffer needs {screen_bytes} bytes, over this adapter's \
             storage binding limit of {max_binding}",
            shared.width,
            shared.height
        );
    }
    let params = shared.uniform_buffer("scattered", bytemuck::bytes_of(&ScatterParams::default()));
    let screen = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("scattered screen"),
        size: screen_bytes,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let scatter_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scattered"),
        entries: &[
            uniform_layout_entry(0),
            storage_entry(1, false, wgpu::ShaderStages::COMPUTE),
        ],
    });
    let scatter_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("scattered"),
        layout: &scatter_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: screen.as_entire_binding(),
            },
        ],
    });
    let module = shared.shader("scattered.wgsl")?;
    let layout = shared.pipeline_layout("scattered", &[&scatter_layout]);
    let compute = |entry: &str| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let (clear, scatter) = (compute("cs_clear"), compute("cs_scatter"));

    let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scattered resolve"),
        entries: &[storage_entry(0, true, wgpu::ShaderStages::FRAGMENT)],
    });
    let resolve_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("scattered resolve"),
        layout: &resolve_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: screen.as_entire_binding(),
        }],
    });
    let resolve_module = shared.shader("scattered_resolve.wgsl")?;
    let resolve = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("scattered resolve"),
        layout: Some(&shared.pipeline_layout("scattered resolve", &[&resolve_layout])),
        vertex: wgpu::VertexState {
            module: &resolve_module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &resolve_module,
            entry_point: Some("fs_resolve"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let max_groups = limits.max_compute_workgroups_per_dimension;
    let dispatchable = u64::from(max_groups) * u64::from(max_groups) * u64::from(WORKGROUP);
    Ok(Box::new(Scattered {
        density,
        tops: TopMax::new(level),
        params,
        screen_bytes,
        clear,
        scatter,
        scatter_group,
        resolve,
        resolve_group,
        max_samples: MAX_GRID.min(dispatchable),
        max_groups,
        groups: (0, 0),
        warned: false,
    }))
}

impl Method for Scattered {
    fn name(&self) -> &'static str {
        "scattered"
    }

    fn apply_edit(
        &mut self,
        _shared: &Shared,
        level: &Level,
        rects: &[strata_level::DirtyRect],
    ) -> anyhow::Result<()> {
        if level.width() != self.tops.size[0] || level.height() != self.tops.size[1] {
            self.tops = TopMax::new(level);
        }
        for r in rects {
            self.tops.update(level, r);
        }
        Ok(())
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        let (max_top, near_top) = self.tops.bounds(camera);
        let (params, warning) =
            scatter_grid(camera, self.density, max_top, near_top, self.max_samples);
        if let Some(w) = warning
            && !self.warned
        {
            eprintln!("warning: {w}");
            self.warned = true;
        }
        let groups = params.samples().div_ceil(u64::from(WORKGROUP));
        // groups <= max_groups^2 by `max_samples`, so y fits too.
        let x = groups.min(u64::from(self.max_groups));
        self.groups = if groups == 0 {
            (0, 0)
        } else {
            (x as u32, groups.div_ceil(x) as u32)
        };
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("scattered clear"),
                timestamp_writes: frame.timer.compute("scattered clear"),
            });
            pass.set_pipeline(&self.clear);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.scatter_group, &[]);
            pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
        }
        if self.groups.0 > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("scattered scatter"),
                timestamp_writes: frame.timer.compute("scattered scatter"),
            });
            pass.set_pipeline(&self.scatter);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.scatter_group, &[]);
            pass.dispatch_workgroups(self.groups.0, self.groups.1, 1);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scattered resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &shared.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(sky_clear()),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &shared.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: frame.timer.render("scattered resolve"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.resolve_group, &[]);
        pass.draw(0..3, 0..1);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The screen buffer (4 bytes per pixel) and the grid uniform.
        RetainedBytes {
            gpu: self.screen_bytes + std::mem::size_of::<ScatterParams>() as u64,
            cpu: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_points_match_the_forward_footprint_at_z_max() {
        use super::super::forward::frustum_slab_points;
        for pitch in [0.0, -45.0, -90.0] {
            let cam = Camera::new(Vec3::new(30.0, 50.0, 120.0), 20.0, pitch, 160, 100).unwrap();
            assert_eq!(slab_points(&cam, Z_MAX), frustum_slab_points(&cam, cam.far));
        }
    }

    #[test]
    fn a_low_terrain_shrinks_the_footprint_and_widens_the_rows() {
        // Looking steeply down from 150: terrain no higher than 50 is at least
        // 100 away, so rows near the eye are not needed.
        let cam = Camera::new(Vec3::new(0.0, 0.0, 150.0), 0.0, -60.0, 320, 200).unwrap();
        let (all, _) = scatter_grid(&cam, [4.0; 3], Z_MAX, Z_MAX, MAX_GRID);
        let (low, _) = scatter_grid(&cam, [4.0; 3], 50.0, 50.0, MAX_GRID);
        assert!(low.origin[2] == 100.0 && all.origin[2] == 1.0, "{low:?}");
        // Terrain up to 140 only within NEAR_RADIUS: the capped local clearance.
        let (near, _) = scatter_grid(&cam, [4.0; 3], Z_MAX, 140.0, MAX_GRID);
        assert_eq!(near.origin[2], 10.0);
        let (near, _) = scatter_grid(&cam, [4.0; 3], Z_MAX, 50.0, MAX_GRID);
        assert_eq!(near.origin[2], 32.0);
        assert!(
            low.samples() * 2 < all.samples(),
            "{} vs {}",
            low.samples(),
            all.samples()
        );
    }

    #[test]
    fn the_tile_maximum_follows_edits() {
        let mut level = Level::flat(64, 64, 10, 1).unwrap();
        let mut tops = TopMax::new(&level);
        assert_eq!(tops.max_in([-100.0, -100.0], [100.0, 100.0]), 10.0);
        level.planes_mut().0[0] = 200;
        let rect = strata_level::DirtyRect {
            x: 0,
            y: 0,
            width: 1,
            height: 1,
        };
        tops.update(&level, &rect);
        assert_eq!(tops.max_in([0.0, 0.0], [3.0, 3.0]), 200.0);
        // Wrapping: texel (0, 0) is also (64, 64).
        assert_eq!(tops.max_in([60.0, 60.0], [65.0, 65.0]), 200.0);
        assert_eq!(tops.max_in([20.0, 20.0], [40.0, 40.0]), 10.0);
    }

    #[test]
    fn hull_drops_inner_and_collinear_points() {
        let pts = vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [1.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 1.0],
        ];
        let h = convex_hull(pts);
        assert_eq!(h.len(), 4, "{h:?}");
    }

    #[test]
    fn grid_covers_the_view_at_every_pitch() {
        for (pitch, yaw) in [(0.0, 0.0), (-30.0, 45.0), (-60.0, 200.0), (-90.0, 10.0)] {
            let cam = Camera::new(Vec3::new(300.0, 500.0, 120.0), yaw, pitch, 160, 100).unwrap();
            // Terrain up to Z_MAX above this low eye is the worst case: the
            // grid may hit the clamp, but must still cover the view.
            let (p, _) = scatter_grid(&cam, [4.0, 4.0, 4.0], Z_MAX, Z_MAX, MAX_GRID);
            assert!(p.samples() > 0 && p.samples() <= MAX_GRID);
            let b = cam.basis();
            // Points of pixel rays inside the altitude range are inside the polygon.
            for (i, j) in [(0, 0), (159, 0), (80, 50), (0, 99), (159, 99)] {
                let d = cam.pixel_ray(i, j);
                for s in 1..=60 {
                    let q = cam.position + d * (cam.far_distance(i, j) * s as f32 / 60.0);
                    if !(0.0..=Z_MAX).contains(&q.z) {
                        continue;
                    }
                    let r = q - cam.position;
                    let (a, c) = (r.dot(b.flat), r.dot(b.right));
                    let (lo, hi) = p.row_range(a).expect("row inside the footprint");
                    assert!(
                        c >= lo - 1e-2 && c <= hi + 1e-2,
                        "{pitch}: {c} not in {lo}..{hi}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_huge_grid_is_clamped_and_bad_density_refused() {
        let mut cam = Camera::new(Vec3::new(0.0, 0.0, 100.0), 45.0, 0.0, 1280, 800).unwrap();
        cam.far = 100_000.0;
        let (p, w) = scatter_grid(&cam, [64.0, 64.0, 4.0], Z_MAX, Z_MAX, MAX_GRID);
        assert!(w.is_some() && p.samples() <= MAX_GRID && p.samples() > MAX_GRID / 2);
        for d in [[0.0, 4.0, 4.0], [4.0, -1.0, 4.0], [4.0, 4.0, f32::NAN]] {
            assert!(checked_density(d).is_err());
        }
        assert_eq!(checked_density([1.0, 1.0, 1e9]).unwrap()[2], MAX_DENSITY);
        assert_eq!(checked_density([1e9, 1.0, 1.0]).unwrap()[0], MAX_DENSITY);
        let above = Camera::new(Vec3::new(0.0, 0.0, 5000.0), 0.0, 30.0, 160, 100).unwrap();
        assert_eq!(
            scatter_grid(&above, [4.0; 3], Z_MAX, Z_MAX, MAX_GRID)
                .0
                .samples(),
            0
        );
    }
}
