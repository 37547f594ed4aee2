//! Scoring a rendered distance image against the reference (DESIGN §3).
//! Every figure is in percent of ALL pixels, so they add up across a frame.

use crate::Reference;
use serde::{Deserialize, Serialize};
use strata_camera::Camera;

/// Relative tolerance of the coherence test: a pixel is incoherent when its
/// distance differs from the median of its 3x3 by more than this times
/// `max(d, 1)`.
pub const COHERENCE_TOLERANCE: f32 = 0.04;

/// How a rendered distance image differs from the reference; see the module
/// docs for the units (percent of all pixels, world units).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Reference solid, renderer empty (% of all pixels).
    pub see_through: f64,
    /// Reference empty, renderer solid (% of all pixels).
    pub covers_sky: f64,
    /// Median of |d - reference| over pixels solid in both, world units
    /// (0 when there are none; see `both_solid`).
    pub depth_p50: f32,
    /// 95th percentile of the same.
    pub depth_p95: f32,
    /// Reference-solid pixels where the renderer is incoherent and the
    /// reference is not (% of all pixels).
    pub coherence: f64,
    /// Pixels solid in both, the population of `depth_p50` / `depth_p95` (%).
    pub both_solid: f64,
}

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MetricsError {
    /// The rendered image's pixel count differs from the reference's.
    #[error(
        "rendered image has {got} pixels, the reference {expected} ({width}x{height}): different sizes"
    )]
    Size {
        /// Pixels in the rendered image.
        got: usize,
        /// Pixels in the reference.
        expected: usize,
        /// Reference width, pixels.
        width: u32,
        /// Reference height, pixels.
        height: u32,
    },
}

/// Compare a rendered distance image (`f32::INFINITY` or any non-finite value
/// = nothing drawn) with the reference.
///
/// # Panics
/// When the lengths differ: a caller's bug. Use [`try_compare`] on untrusted input.
pub fn compare(reference: &Reference, rendered_distance: &[f32]) -> Metrics {
    match try_compare(reference, rendered_distance) {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    }
}

/// [`compare`], with a size mismatch as an error.
pub fn try_compare(
    reference: &Reference,
    rendered_distance: &[f32],
) -> Result<Metrics, MetricsError> {
    let n = reference.pixel_count();
    if rendered_distance.len() != n || reference.distance.len() != n {
        return Err(MetricsError::Size {
            got: rendered_distance.len(),
            expected: n,
            width: reference.width,
            height: reference.height,
        });
    }
    let (w, h) = (reference.width as usize, reference.height as usize);
    let mut see_through = 0usize;
    let mut covers_sky = 0usize;
    let mut errors = Vec::with_capacity(n);
    for (&r, &d) in reference.distance.iter().zip(rendered_distance) {
        match (r.is_finite(), d.is_finite()) {
            (true, false) => see_through += 1,
            (false, true) => covers_sky += 1,
            (true, true) => errors.push((d - r).abs()),
            (false, false) => {}
        }
    }
    let ref_incoherent = incoherent_mask(&reference.distance, w, h);
    let ren_incoherent = incoherent_mask(rendered_distance, w, h);
    let coherence = (0..n)
        .filter(|&k| reference.distance[k].is_finite() && ren_incoherent[k] && !ref_incoherent[k])
        .count();
    errors.sort_unstable_by(f32::total_cmp);
    let pct = |c: usize| 100.0 * c as f64 / n.max(1) as f64;
    Ok(Metrics {
        see_through: pct(see_through),
        covers_sky: pct(covers_sky),
        depth_p50: percentile(&errors, 50.0),
        depth_p95: percentile(&errors, 95.0),
        coherence: pct(coherence),
        both_solid: pct(errors.len()),
    })
}

/// Nearest-rank percentile of sorted values (the smallest value with at least
/// `p`% of the values at or below it); 0 for none.
pub fn percentile(sorted: &[f32], p: f64) -> f32 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (p / 100.0 * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// Per pixel: is its distance incoherent with its 3x3 neighbourhood? Empty
/// (non-finite) pixels are never incoherent and are excluded from their
/// neighbours' medians; the median includes the pixel itself, and of an even
/// count is the mean of the middle two, so a pixel with no solid neighbour
/// is its own median and coherent.
pub fn incoherent_mask(distance: &[f32], width: usize, height: usize) -> Vec<bool> {
    use rayon::prelude::*;
    let mut out = vec![false; distance.len()];
    if width == 0 || height == 0 || distance.len() < width * height {
        return out;
    }
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let mut window = [0f32; 9];
        for (x, flag) in row.iter_mut().enumerate() {
            let d = distance[x + y * width];
            if !d.is_finite() {
                continue;
            }
            let mut count = 0;
            for ny in y.saturating_sub(1)..=(y + 1).min(height - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(width - 1) {
                    let v = distance[nx + ny * width];
                    if v.is_finite() {
                        window[count] = v;
                        count += 1;
                    }
                }
            }
            let vals = &mut window[..count];
            vals.sort_unstable_by(f32::total_cmp);
            let median = if count % 2 == 1 {
                vals[count / 2]
            } else {
                0.5 * (vals[count / 2 - 1] + vals[count / 2])
            };
            *flag = (d - median).abs() > COHERENCE_TOLERANCE * d.max(1.0);
        }
    });
    out
}

/// Distances along each pixel's ray from a depth buffer (0 at near .. 1 at
/// far, row-major, the camera's size). `depth >= 1` (cleared, nothing drawn)
/// and non-finite values become `f32::INFINITY`. Pixels beyond the camera's
/// `width * height` are ignored.
pub fn distance_from_depth(camera: &Camera, depth: &[f32]) -> Vec<f32> {
    let w = camera.width.max(1) as usize;
    depth
        .iter()
        .enumerate()
        .take(w * camera.height as usize)
        .map(|(k, &z)| {
            if !z.is_finite() || z >= 1.0 {
                f32::INFINITY
            } else {
                camera.depth_to_distance((k % w) as u32, (k / w) as u32, z)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HitClass;
    use glam::Vec3;

    fn reference(w: u32, h: u32, distance: Vec<f32>) -> Reference {
        let class = distance
            .iter()
            .map(|d| {
                if d.is_finite() {
                    HitClass::Floor
                } else {
                    HitClass::Sky
                }
            })
            .collect();
        Reference {
            width: w,
            height: h,
            terrain: vec![0; distance.len()],
            distance,
            class,
        }
    }

    const INF: f32 = f32::INFINITY;

    #[test]
    fn identical_images_score_zero() {
        let d: Vec<f32> = (0..64)
            .map(|k| {
                if k % 7 == 0 {
                    INF
                } else {
                    10.0 + k as f32 * 0.01
                }
            })
            .collect();
        let r = reference(8, 8, d.clone());
        let m = compare(&r, &d);
        assert_eq!((m.see_through, m.covers_sky, m.coherence), (0.0, 0.0, 0.0));
        assert_eq!((m.depth_p50, m.depth_p95), (0.0, 0.0));
        assert!(
            (m.both_solid - 100.0 * 54.0 / 64.0).abs() < 1e-9,
            "{}",
            m.both_solid
        );
    }

    #[test]
    fn see_through_and_covers_sky_count_all_pixels() {
        // 4x5 = 20 pixels; top row is reference sky.
        let mut r = vec![50.0f32; 20];
        r[..4].fill(INF);
        let mut d = r.clone();
        d[0] = 50.0; // covers sky
        d[1] = 50.0; // covers sky
        d[10] = INF; // see-through
        let m = compare(&reference(4, 5, r), &d);
        assert_eq!(m.covers_sky, 10.0);
        assert_eq!(m.see_through, 5.0);
        assert_eq!(m.both_solid, 75.0);
    }

    #[test]
    fn depth_percentiles_are_nearest_rank() {
        // 20 solid pixels with errors 1..=20: p50 = 10, p95 = 19.
        let r = vec![100.0f32; 20];
        let d: Vec<f32> = (1..=20).map(|e| 100.0 + e as f32).collect();
        let m = compare(&reference(5, 4, r), &d);
        assert_eq!(m.depth_p50, 10.0);
        assert_eq!(m.depth_p95, 19.0);
    }

    #[test]
    fn one_spike_is_one_incoherent_pixel() {
        // 4x4 plane at distance 10, renderer has a spike of 20 at (1, 1).
        let r = vec![10.0f32; 16];
        let mut d = r.clone();
        d[5] = 20.0;
        let m = compare(&reference(4, 4, r), &d);
        // The spike differs from its median (10) by 10 > 0.4; its neighbours'
        // medians stay 10.
        assert_eq!(m.coherence, 100.0 / 16.0);
        assert_eq!(incoherent_mask(&d, 4, 4).iter().filter(|&&b| b).count(), 1);
    }

    #[test]
    fn coherence_is_in_excess_of_the_reference_and_over_reference_solid() {
        let mut r = vec![10.0f32; 16];
        r[5] = 20.0; // the reference has the same spike: not counted
        r[15] = INF;
        let mut d = r.clone();
        d[10] = 30.0; // a new spike: counted
        d[15] = 60.0; // covers sky next to a 30: incoherent but not reference-solid
        let m = compare(&reference(4, 4, r), &d);
        assert!(incoherent_mask(&d, 4, 4)[15]);
        assert_eq!(m.coherence, 100.0 / 16.0);
        assert_eq!(m.covers_sky, 100.0 / 16.0);
    }

    #[test]
    fn empty_neighbours_are_excluded() {
        // A lone solid pixel in sky is coherent; a pair 10 / 10.3 is
        // coherent (|10 - 10.15| = 0.15 <= 0.4); a pair 10 / 12 is not
        // (|10 - 11| = 1 > 0.4, |12 - 11| = 1 > 0.48).
        let mut d = vec![INF; 25];
        d[0] = 10.0;
        assert!(!incoherent_mask(&d, 5, 5)[0]);
        d[1] = 10.3;
        assert_eq!(incoherent_mask(&d, 5, 5).iter().filter(|&&b| b).count(), 0);
        d[1] = 12.0;
        let mask = incoherent_mask(&d, 5, 5);
        assert!(mask[0] && mask[1]);
        // Tolerance scales with max(d, 1): near pixels use 1.
        let mut near = vec![INF; 4];
        near[0] = 0.1;
        near[1] = 0.15; // |0.1 - 0.125| = 0.025 <= 0.04
        assert!(!incoherent_mask(&near, 2, 2)[0]);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let r = reference(4, 4, vec![1.0; 16]);
        assert!(matches!(
            try_compare(&r, &[1.0; 15]),
            Err(MetricsError::Size { got: 15, .. })
        ));
    }

    #[test]
    fn depth_buffer_round_trips_to_distance() {
        let cam = Camera::new(Vec3::new(0.0, 0.0, 100.0), 30.0, -20.0, 40, 30).unwrap();
        let mut depth = Vec::new();
        let mut expected = Vec::new();
        for j in 0..30 {
            for i in 0..40 {
                let dist = 5.0 + (i + j) as f32;
                let p = cam.position + cam.pixel_ray(i, j) * dist;
                depth.push(cam.project(p).unwrap().z);
                expected.push(dist);
            }
        }
        depth[3] = 1.0;
        expected[3] = INF;
        depth[4] = f32::NAN;
        expected[4] = INF;
        let got = distance_from_depth(&cam, &depth);
        for (g, e) in got.iter().zip(&expected) {
            assert!(g == e || (g - e).abs() < 1e-3 * e, "{g} vs {e}");
        }
    }
}
