//! The CPU side of `scattered`'s grid: the footprint polygon, the
//! [`ScatterParams`] layout that `scatter_grid` builds for the scatter pass,
//! the density checks, and [`count_points`], a CPU twin of the scatter that
//! counts its work. See the `scattered` module for the method itself.

use super::super::forward::Z_MAX;
use super::super::forward::footprint_bounds;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use strata_camera::Camera;
use strata_level::Level;

/// Side of the tiles of the level's column-top maximum, texels.
const TILE: u32 = 16;
/// The highest column top of each `TILE`² tile of a level, to bound how close
/// the terrain of a footprint can come to the eye.
#[derive(Clone, Debug)]
pub struct TopMax {
    pub(super) size: [u32; 2],
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
/// Most footprint polygon vertices the uniform holds (a frustum cut by a slab
/// has at most 12).
const MAX_HULL: usize = 16;

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
    /// Grid samples this frame dispatches (rows x columns).
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

/// Points whose convex hull is the part of the frustum (near to far) with
/// altitude in `0..=top`: no terrain in view lies outside it when no column
/// top in view is above `top`.
pub fn slab_points(camera: &Camera, top: f32) -> Vec<Vec3> {
    strata_camera::frustum::slab_points(camera, camera.far, top)
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
    let mut hull = strata_camera::frustum::convex_hull(pts);
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
#[cfg(test)]
mod tests {
    use super::*;

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
