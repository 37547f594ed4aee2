//! ꟻLIP (NVIDIA's perceptual image difference, the `nv-flip` crate) between
//! a method's picture and the CPU colour reference. Native only: the
//! library is C++.

use image::RgbaImage;
use strata_reference::ColorImage;

/// Per-pixel ꟻLIP errors of one picture and what the results file keeps.
pub struct FlipMap {
    pub width: u32,
    pub height: u32,
    /// Row-major, each in [0, 1].
    pub errors: Vec<f32>,
}

impl FlipMap {
    /// ꟻLIP of `test` (RGBA8, alpha ignored) against `reference`, at the
    /// library's default 67 pixels per degree (a 0.7 m view of a 24" 4K
    /// screen). Errors name a size mismatch instead of panicking.
    pub fn compare(reference: &ColorImage, test: &RgbaImage) -> anyhow::Result<Self> {
        let (w, h) = (reference.width, reference.height);
        if test.dimensions() != (w, h) {
            anyhow::bail!(
                "ꟻLIP: picture is {}x{} but the colour reference is {w}x{h}",
                test.width(),
                test.height()
            );
        }
        let rgb: Vec<u8> = test
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect();
        let errors = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, &reference.rgb),
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec();
        Ok(FlipMap {
            width: w,
            height: h,
            errors,
        })
    }

    /// Mean ꟻLIP.
    pub fn mean(&self) -> f64 {
        self.errors.iter().map(|&e| f64::from(e)).sum::<f64>() / self.errors.len().max(1) as f64
    }

    /// Percent of pixels above 0.5.
    pub fn percent_over_half(&self) -> f64 {
        let n = self.errors.iter().filter(|&&e| e > 0.5).count();
        100.0 * n as f64 / self.errors.len().max(1) as f64
    }

    /// The error map in the magma colours ꟻLIP's own tool uses (black 0,
    /// yellow-white 1).
    pub fn picture(&self) -> RgbaImage {
        let map = nv_flip::FlipImageFloat::with_data(self.width, self.height, &self.errors);
        let rgb = map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
        RgbaImage::from_fn(self.width, self.height, |x, y| {
            let i = 3 * (y * self.width + x) as usize;
            image::Rgba([rgb[i], rgb[i + 1], rgb[i + 2], 255])
        })
    }
}

/// The colour reference as a picture.
pub fn reference_picture(c: &ColorImage) -> RgbaImage {
    RgbaImage::from_fn(c.width, c.height, |x, y| {
        let i = 3 * (y * c.width + x) as usize;
        image::Rgba([c.rgb[i], c.rgb[i + 1], c.rgb[i + 2], 255])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_pictures_score_zero_and_a_wrong_block_scores_high() {
        let (w, h) = (32u32, 24u32);
        let rgb: Vec<u8> = (0..w * h).flat_map(|i| [(i % 200) as u8, 90, 40]).collect();
        let reference = ColorImage {
            width: w,
            height: h,
            rgb,
        };
        let same = reference_picture(&reference);
        let f = FlipMap::compare(&reference, &same).unwrap();
        assert_eq!(f.mean(), 0.0);
        assert_eq!(f.percent_over_half(), 0.0);
        // A 8x8 block of the wrong colour: those pixels are clearly visible.
        let mut wrong = same.clone();
        for y in 0..8 {
            for x in 0..8 {
                wrong.put_pixel(x, y, image::Rgba([20, 250, 250, 255]));
            }
        }
        let f = FlipMap::compare(&reference, &wrong).unwrap();
        assert!(f.percent_over_half() > 4.0, "{}", f.percent_over_half());
        assert!(f.mean() > 0.03, "{}", f.mean());
        assert_eq!(f.picture().dimensions(), (w, h));
        // A wrong size is an error, not a panic.
        assert!(FlipMap::compare(&reference, &RgbaImage::new(3, 3)).is_err());
    }
}
