//! What the object-order methods `painted` and `sliced` share: the camera's
//! ground footprint (the axis-aligned xy bound of the view frustum, cut at the
//! far plane and clipped to the altitude range), and the order that walks its
//! samples away from the eye. `shaders/forward.wgsl` is the GPU twin of
//! [`FootprintParams`] and decodes an instance index into a sample.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use strata_camera::Camera;

/// Top of the altitude range the footprint is clipped to: heights are 0..=255,
/// and a surface at 255 must still be inside.
pub const Z_MAX: f32 = 256.0;

/// The most ground samples one frame may enumerate. Far beyond any real view
/// (600 units of far plane give under 1.5 M at 1280 px), and small enough that
/// `painted`'s 14 vertices and 36 indices per sample stay far from `u32`
/// overflow.
pub const MAX_SAMPLES: u64 = 1 << 22;

/// Twin of `Footprint` in `forward.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct FootprintParams {
    /// x, y of the bound's first sample (unwrapped world texels); z: 0 when
    /// rows run along x (the major axis is y), 1 when they run along y; w unused.
    pub origin: [i32; 4],
    /// Rows (along the major axis), samples per row, the eye's row, the eye's
    /// sample within a row (both clamped into the bound).
    pub size: [u32; 4],
    /// Samples drawn (rows x row length, clamped to [`MAX_SAMPLES`]), then
    /// three method-specific words (`sliced`: slice count, eye's slice rank,
    /// gap walk columns).
    pub count: [u32; 4],
}

impl FootprintParams {
    /// The bound's extent in x and y, texels (rows run along x when
    /// `origin[2]` is 0).
    pub fn extent(&self) -> [u32; 2] {
        if self.origin[2] == 0 {
            [self.size[1], self.size[0]]
        } else {
            [self.size[0], self.size[1]]
        }
    }
}

/// Bytes of the footprint uniform (what `painted` and `sliced` retain).
pub const PARAMS_BYTES: u64 = std::mem::size_of::<FootprintParams>() as u64;

/// The xy bound of the part of the frustum (near to `far`) with altitude in
/// `0..=Z_MAX`, or `None` when the frustum misses that range.
pub fn footprint_bounds(camera: &Camera, far: f32) -> Option<([f32; 2], [f32; 2])> {
    let points = frustum_slab_points(camera, far);
    let first = points.first()?;
    let (mut lo, mut hi) = ([first.x, first.y], [first.x, first.y]);
    for p in &points {
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    Some((lo, hi))
}

/// Points whose convex hull is the part of the frustum (near to `far`) with
/// altitude in `0..=Z_MAX` (empty when the frustum misses that range).
pub fn frustum_slab_points(camera: &Camera, far: f32) -> Vec<Vec3> {
    strata_camera::frustum::slab_points(camera, far, Z_MAX)
}

/// Samples in the bound of the frustum cut at `far`: the bound's corners.
fn bound_samples(camera: &Camera, far: f32) -> Option<(i64, i64, i64, i64)> {
    let (lo, hi) = footprint_bounds(camera, far)?;
    // One texel of margin: a bar's column starts at floor(x).
    // (Float to int casts saturate; so do the margins, for absurd cameras.)
    let x0 = (lo[0].floor() as i64).saturating_sub(1);
    let y0 = (lo[1].floor() as i64).saturating_sub(1);
    let x1 = (hi[0].ceil() as i64).saturating_add(1);
    let y1 = (hi[1].ceil() as i64).saturating_add(1);
    Some((x0, y0, x1.max(x0), y1.max(y0)))
}

/// The footprint's samples and their front-to-back order for this camera.
/// Where the bound would exceed [`MAX_SAMPLES`], the footprint is cut at a
/// nearer plane that fits, with a warning naming `warn_as` when given.
pub fn footprint(camera: &Camera, warn_as: Option<&str>) -> FootprintParams {
    let area = |b: (i64, i64, i64, i64)| (b.2 as f64 - b.0 as f64) * (b.3 as f64 - b.1 as f64);
    let mut far = camera.far;
    let Some(mut b) = bound_samples(camera, far) else {
        return FootprintParams::default();
    };
    let full = area(b);
    // The bound grows about with far^2: shrink far until it fits.
    let fits = |b| area(b) <= MAX_SAMPLES as f64;
    while !fits(b) && far > camera.near {
        far = (far * (MAX_SAMPLES as f64 / area(b)).sqrt() as f32 * 0.95).max(camera.near);
        match bound_samples(camera, far) {
            Some(nb) => b = nb,
            None => return FootprintParams::default(),
        }
    }
    if let Some(method) = warn_as
        && far < camera.far
    {
        eprintln!(
            "warning: {method}: the footprint holds {full} samples (over {MAX_SAMPLES}); \
             drawing the part nearer than {far:.0} of the far plane's {:.0}",
            camera.far
        );
    }
    let (x0, y0, x1, y1) = b;
    let flat = camera.basis().flat;
    // Rows across the axis the view mostly runs along, so row rank ~ distance.
    let rows_along_x = flat.y.abs() >= flat.x.abs();
    let (len_x, len_y) = ((x1 - x0).max(0) as u64, (y1 - y0).max(0) as u64);
    let (rows, row_len) = if rows_along_x {
        (len_y, len_x)
    } else {
        (len_x, len_y)
    };
    let eye_x = (camera.position.x.floor() as i64 - x0).clamp(0, len_x.max(1) as i64 - 1);
    let eye_y = (camera.position.y.floor() as i64 - y0).clamp(0, len_y.max(1) as i64 - 1);
    let (eye_row, eye_col) = if rows_along_x {
        (eye_y, eye_x)
    } else {
        (eye_x, eye_y)
    };
    let total = rows * row_len;
    // Row lengths and row counts are under 2^32 whenever `total` fits the clamp;
    // saturate so an absurd camera cannot wrap.
    let sat = |v: u64| v.min(u64::from(u32::MAX)) as u32;
    FootprintParams {
        origin: [x0 as i32, y0 as i32, i32::from(!rows_along_x), 0],
        size: [sat(rows), sat(row_len), eye_row as u32, eye_col as u32],
        count: [total.min(MAX_SAMPLES) as u32, 0, 0, 0],
    }
}

/// Rank `rank` of the order that starts at `centre` and alternates outwards
/// over `0..count` (the CPU twin of `outward` in `forward.wgsl`).
pub fn outward(rank: u32, centre: u32, count: u32) -> u32 {
    let below = centre;
    let above = count - 1 - centre;
    let m = below.min(above);
    if rank == 0 {
        centre
    } else if rank <= 2 * m {
        let k = rank.div_ceil(2);
        if rank % 2 == 1 {
            centre + k
        } else {
            centre - k
        }
    } else if above > below {
        centre + rank - m
    } else {
        centre - (rank - m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outward_visits_every_index_once_nearest_first() {
        for count in 1..12u32 {
            for centre in 0..count {
                let order: Vec<u32> = (0..count).map(|r| outward(r, centre, count)).collect();
                let mut seen = order.clone();
                seen.sort_unstable();
                assert_eq!(seen, (0..count).collect::<Vec<_>>(), "{count} {centre}");
                let dist: Vec<u32> = order.iter().map(|&i| i.abs_diff(centre)).collect();
                assert!(dist.windows(2).all(|w| w[0] <= w[1]), "{order:?}");
            }
        }
    }

    #[test]
    fn footprint_contains_what_the_camera_sees() {
        for (pitch, yaw) in [(0.0, 0.0), (-30.0, 45.0), (-60.0, 200.0), (-90.0, 10.0)] {
            let cam = Camera::new(Vec3::new(300.0, 500.0, 120.0), yaw, pitch, 160, 100).unwrap();
            let f = footprint(&cam, None);
            let (x0, y0) = (f.origin[0] as f32, f.origin[1] as f32);
            let [lx, ly] = f.extent();
            // Every pixel ray's points inside the altitude range lie inside.
            for (i, j) in [(0, 0), (159, 0), (80, 50), (0, 99), (159, 99)] {
                let d = cam.pixel_ray(i, j);
                for s in 0..=60 {
                    let p = cam.position + d * (cam.far_distance(i, j) * s as f32 / 60.0);
                    if (0.0..=Z_MAX).contains(&p.z) {
                        assert!(p.x >= x0 && p.x <= x0 + lx as f32, "{pitch} {p}");
                        assert!(p.y >= y0 && p.y <= y0 + ly as f32, "{pitch} {p}");
                    }
                }
            }
            assert!(f.count[0] > 0 && u64::from(f.count[0]) <= MAX_SAMPLES);
        }
    }

    #[test]
    fn a_frustum_above_the_terrain_has_no_footprint() {
        let cam = Camera::new(Vec3::new(0.0, 0.0, 5000.0), 0.0, 30.0, 160, 100).unwrap();
        assert_eq!(footprint(&cam, None).count[0], 0);
    }

    #[test]
    fn a_huge_footprint_is_clamped() {
        let mut cam = Camera::new(Vec3::new(0.0, 0.0, 100.0), 45.0, 0.0, 160, 100).unwrap();
        cam.far = 100_000.0;
        let f = footprint(&cam, None);
        let n = u64::from(f.count[0]);
        assert!(n <= MAX_SAMPLES && n > MAX_SAMPLES / 4, "{n}");
        // The nearest part is kept: the eye's row is in the bound.
        assert!(f.size[2] < f.size[0]);
        cam.far = f32::INFINITY;
        assert!(u64::from(footprint(&cam, None).count[0]) <= MAX_SAMPLES);
    }
}
