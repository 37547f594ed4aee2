//! Which image rows of a frame hold rays that may cross the slices more
//! than [`GAP_MIN`] texels apart: rays within a few degrees of level, whose
//! gaps between slice crossings are walked (`sliced.wgsl::slice_hit`). Plain
//! `sliced`'s gap pass runs over those rows only (`gaps.rs`), and the refined
//! slicer's marks use the shader without the walk on frames that have none
//! (`fs_slice_mark_steep`): the walk's loop costs a shader occupancy on every
//! fragment, walked or not (H100: 9.19 ms a frame with the walk never taken,
//! against 8.09 without the loop). The camera has no roll, so a row's most
//! level rays are at its two ends; those are tested, with a margin, and
//! every walking row's neighbours count as walking too.

use std::ops::Range;
use strata_camera::Camera;

/// Twin of `sliced.wgsl`'s `GAP_MIN`: rays that cross the slices at most this
/// many texels apart never walk.
pub const GAP_MIN: f32 = 2.0;

/// A band of image rows and whether any of its rays may walk.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RowBand {
    pub rows: Range<u32>,
    pub walks: bool,
}

/// Whether the ray through image point (`px`, `py`) may walk at `spacing`
/// (world units between slices), with a relative margin for the GPU's
/// rounding: `spacing / |d.z| * |d.xy| > GAP_MIN` in the shader.
fn may_walk(camera: &Camera, px: f32, py: f32, spacing: f64) -> bool {
    let d = camera.image_direction(px, py).as_dvec3();
    let level = spacing * d.truncate().length();
    level > f64::from(GAP_MIN) * d.z.abs() * (1.0 - 1e-3)
}

/// The frame's rows, top to bottom, in bands that alternate between steep
/// (no ray walks) and walking. Empty for an empty image.
pub fn row_bands(camera: &Camera, slices: u32) -> Vec<RowBand> {
    let (w, h) = (camera.width, camera.height);
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let spacing = f64::from(super::Z_MAX) / f64::from(slices.max(1));
    let ends = [0.5, w as f32 - 0.5, w as f32 * 0.5];
    let walks: Vec<bool> = (0..h)
        .map(|y| {
            let py = y as f32 + 0.5;
            ends.iter().any(|&px| may_walk(camera, px, py, spacing))
        })
        .collect();
    // A walking row's neighbours walk too.
    let dilated: Vec<bool> = (0..h as usize)
        .map(|y| walks[y.saturating_sub(1)..=(y + 1).min(h as usize - 1)].contains(&true))
        .collect();
    let mut bands: Vec<RowBand> = Vec::new();
    for (y, &walks) in dilated.iter().enumerate() {
        let y = y as u32;
        match bands.last_mut() {
            Some(band) if band.walks == walks => band.rows.end = y + 1,
            _ => bands.push(RowBand {
                rows: y..y + 1,
                walks,
            }),
        }
    }
    bands
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn camera(pitch: f32, w: u32, h: u32) -> Camera {
        Camera::new(Vec3::new(100.0, 200.0, 80.0), 30.0, pitch, w, h).unwrap()
    }

    /// The bands cover every row once, in order, alternating.
    fn check_partition(bands: &[RowBand], h: u32) {
        let mut next = 0;
        for (i, band) in bands.iter().enumerate() {
            assert_eq!(band.rows.start, next, "{bands:?}");
            assert!(band.rows.end > band.rows.start, "{bands:?}");
            if i > 0 {
                assert_ne!(band.walks, bands[i - 1].walks, "{bands:?}");
            }
            next = band.rows.end;
        }
        assert_eq!(next, h, "{bands:?}");
    }

    #[test]
    fn every_pixel_that_may_walk_is_in_a_walking_band() {
        for pitch in [
            -90.0, -75.0, -60.0, -45.0, -30.0, -10.0, 0.0, 20.0, 60.0, 90.0,
        ] {
            for (w, h) in [(1280, 800), (320, 200), (64, 400), (7, 3)] {
                for slices in [32, 512, 2048] {
                    let cam = camera(pitch, w, h);
                    let bands = row_bands(&cam, slices);
                    check_partition(&bands, h);
                    let spacing = f64::from(super::super::Z_MAX) / f64::from(slices);
                    for y in 0..h {
                        let band = bands.iter().find(|b| b.rows.contains(&y)).unwrap();
                        if band.walks {
                            continue;
                        }
                        // Every pixel of a steep row, without the margin.
                        for x in 0..w {
                            let d = cam
                                .image_direction(x as f32 + 0.5, y as f32 + 0.5)
                                .as_dvec3();
                            let gap = spacing / d.z.abs() * d.truncate().length();
                            assert!(
                                gap <= f64::from(GAP_MIN),
                                "pitch {pitch} {w}x{h} N {slices}: pixel ({x}, {y}) gap {gap}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn level_views_walk_a_band_and_steep_views_none() {
        // 0°, 1280x800, 512 slices: the rows within about 14° of level.
        let bands = row_bands(&camera(0.0, 1280, 800), 512);
        assert_eq!(bands.len(), 3, "{bands:?}");
        assert!(!bands[0].walks && bands[1].walks && !bands[2].walks);
        let band = &bands[1].rows;
        assert!(band.start > 150 && band.end < 650, "{band:?}");
        assert!(band.contains(&400), "{band:?}");
        // Looking 60° down no ray comes within 14° of level.
        let bands = row_bands(&camera(-60.0, 1280, 800), 512);
        assert_eq!(
            bands,
            vec![RowBand {
                rows: 0..800,
                walks: false
            }]
        );
    }

    #[test]
    fn the_rust_twin_matches_the_shaders() {
        for (name, source) in [
            ("sliced.wgsl", include_str!("../../../shaders/sliced.wgsl")),
            (
                "sliced_gap_walk.wgsl",
                include_str!("../../../shaders/sliced_gap_walk.wgsl"),
            ),
        ] {
            assert!(
                source.contains(&format!("const GAP_MIN: f32 = {GAP_MIN:?};")),
                "{name}'s GAP_MIN differs from rows::GAP_MIN ({GAP_MIN:?})"
            );
        }
    }
}
