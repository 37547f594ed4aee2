//! Generator knobs (issue 17): controls that each move one statistic of the
//! world and leave the others alone, so a survey can vary one variable at a
//! time. Without knobs the world is the built-in one, byte for byte.

use super::noise::{Fbm, fast_round};
use super::{GenerateError, Slab, Texel};

/// Largest `--dual-fraction` (the paper's worlds span 0 … ~0.45).
pub const MAX_DUAL_FRACTION: f64 = 0.5;
/// Largest `--floor-roughness` factor.
pub const MAX_FLOOR_ROUGHNESS: f64 = 4.0;

/// `None` everywhere is the default world.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Knobs {
    /// Share of texels in dual pairs, `0 ..= 0.5`: every slab of the world
    /// (terrain and landmarks) is replaced by roofs over smooth blobs that
    /// cover this share of the pairs. The floor under them is untouched.
    pub dual_fraction: Option<f64>,
    /// Factor on the floor's small relief (bumps and specks), `0 ..= 4`;
    /// 1 is the default world's relief, 0 flat terraces.
    pub floor_roughness: Option<f64>,
}

impl Knobs {
    /// A clear error naming the knob and its range when a value is outside it.
    pub fn check(&self) -> Result<(), GenerateError> {
        let bad = |name: &'static str, value: f64, max: f64| GenerateError::Knob {
            name,
            value: value.to_string(),
            range: format!("0 ..= {max}"),
        };
        if let Some(f) = self.dual_fraction
            && !(0.0..=MAX_DUAL_FRACTION).contains(&f)
        {
            return Err(bad("dual fraction", f, MAX_DUAL_FRACTION));
        }
        if let Some(r) = self.floor_roughness
            && !(0.0..=MAX_FLOOR_ROUGHNESS).contains(&r)
        {
            return Err(bad("floor roughness", r, MAX_FLOOR_ROUGHNESS));
        }
        Ok(())
    }

    /// Whether no knob is turned (the default world).
    pub fn is_default(&self) -> bool {
        *self == Knobs::default()
    }

    /// A suffix for the world's name (empty without knobs).
    pub fn name_suffix(&self) -> String {
        let mut s = String::new();
        if let Some(f) = self.dual_fraction {
            s.push_str(&format!("-dual{f}"));
        }
        if let Some(r) = self.floor_roughness {
            s.push_str(&format!("-rough{r}"));
        }
        s
    }
}

/// Where the `dual_fraction` knob puts slabs: pairs where a smooth noise is
/// above its `1 - fraction` quantile (measured on a grid over the whole map,
/// so the share is hit to within a fraction of a percent).
pub struct SlabMask {
    noise: Fbm,
    relief: Fbm,
    threshold: f32,
}

impl SlabMask {
    /// The mask of a `width x height` map putting slabs on `fraction`
    /// (0 ..= [`MAX_DUAL_FRACTION`]) of its pairs.
    pub fn new(seed: u32, width: u32, height: u32, fraction: f64) -> Self {
        // Blobs about 64 texels across with wiggly outlines (three octaves).
        let noise = Fbm::new(seed ^ 0x51ab, 6, 3, width, height);
        let relief = Fbm::new(seed ^ 0x2e1f, 4, 2, width, height);
        let threshold = if fraction <= 0.0 {
            f32::INFINITY
        } else {
            // Every 8th texel each way up to 2^28 texels (the in-memory
            // worlds, whose bytes must not move), then sparser, so that a
            // world of any size samples at most 2^22 points.
            let texels = u64::from(width) * u64::from(height);
            let mut step = 8;
            while texels / (step * step) > 1 << 22 {
                step *= 2;
            }
            let step = step as usize;
            let mut vs: Vec<f32> = (0..height)
                .step_by(step)
                .flat_map(|y| (0..width).step_by(step).map(move |x| (x, y)))
                .map(|(x, y)| noise.at(x as f32, y as f32))
                .collect();
            vs.sort_unstable_by(f32::total_cmp);
            let k = ((1.0 - fraction) * vs.len() as f64) as usize;
            vs[k.min(vs.len() - 1)]
        };
        SlabMask {
            noise,
            relief,
            threshold,
        }
    }

    /// `t` with its slab replaced: a roof 16 above the floor, its top a
    /// gently rolling 12 to 20 above the ceiling, where the mask is on.
    /// Decided per pair (`x` rounded down to even) so both texels agree.
    #[inline]
    pub fn apply(&self, t: Texel, x: u32, y: u32) -> Texel {
        let (px, yf) = ((x & !1) as f32, y as f32);
        if self.noise.at(px, yf) <= self.threshold {
            return Texel { slab: None, ..t };
        }
        let ceiling = t.floor + 16;
        let high = ceiling + 12 + fast_round(self.relief.at(px, yf) * 8.0);
        Texel {
            slab: Some(Slab {
                ceiling,
                high,
                ty: (t.ty % 7) + 1,
            }),
            ..t
        }
    }
}
