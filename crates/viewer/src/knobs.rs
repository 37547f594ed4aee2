//! The settings the overlay's sliders and a script's `set` change: each
//! method's sliders as its entry in `strata_render::methods::METHODS`
//! declares them, plus the frame's shadows; which methods read each, and
//! when a kept method still matches them.

use anyhow::Context;
use strata_render::MethodSettings;
use strata_render::methods::{METHODS, Slider, entry};

/// A setting a script (and the overlay) can change.
#[derive(Clone, Copy)]
pub enum Knob {
    /// One of a method's sliders.
    Method(&'static Slider),
    /// The shared shadow map (a frame setting, read by no method).
    Shadows,
}

/// Slider names are unique across `METHODS`: a knob is its name.
impl PartialEq for Knob {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for Knob {}

impl std::fmt::Debug for Knob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Knob({})", self.name())
    }
}

const SHADOWS: &str = "shadows";

impl Knob {
    /// Every knob, each once, in the order of `METHODS` (shadows last).
    pub fn all() -> Vec<Knob> {
        let mut out: Vec<Knob> = Vec::new();
        for slider in METHODS.iter().flat_map(|m| m.knobs.sliders) {
            if !out.iter().any(|k| k.name() == slider.name) {
                out.push(Knob::Method(slider));
            }
        }
        out.push(Knob::Shadows);
        out
    }

    /// The knob a script's `set NAME` names.
    pub fn parse(name: &str) -> anyhow::Result<Knob> {
        let all = Knob::all();
        all.iter()
            .find(|k| k.name() == name)
            .copied()
            .with_context(|| {
                let names: Vec<&str> = all.iter().map(|k| k.name()).collect();
                format!("unknown setting `{name}`; known: {}", names.join(", "))
            })
    }

    /// The name `set` takes (`ray-steps`).
    pub fn name(self) -> &'static str {
        match self {
            Knob::Method(slider) => slider.name,
            Knob::Shadows => SHADOWS,
        }
    }

    /// Whether method `name` reads this knob (none reads the shadows: a
    /// frame setting).
    pub fn read_by(self, name: &str) -> bool {
        match self {
            Knob::Method(slider) => entry(name).is_ok_and(|m| m.reads(slider)),
            Knob::Shadows => false,
        }
    }

    /// Write `value` into the knob's field of `settings` (counts must be
    /// whole and positive; each method checks its own range when built).
    pub fn set(self, settings: &mut MethodSettings, value: f32) -> anyhow::Result<()> {
        match self {
            Knob::Method(slider) => slider.set(settings, value),
            Knob::Shadows => {
                if !value.is_finite() {
                    anyhow::bail!("{value} is not a number");
                }
                settings.shadows = value != 0.0;
                Ok(())
            }
        }
    }
}

/// The settings of `s` that method `name` reads (the rest at defaults), so
/// two settings are "the same" for a method when these are equal.
pub fn relevant(name: &str, s: &MethodSettings) -> MethodSettings {
    match entry(name) {
        Ok(m) => m.relevant(s),
        Err(_) => MethodSettings::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knob(name: &str) -> Knob {
        Knob::parse(name).unwrap()
    }

    #[test]
    fn a_method_is_current_whatever_the_knobs_it_does_not_read() {
        let base = MethodSettings::default();
        let mut other = base.clone();
        knob("mesh-quality").set(&mut other, 0.75).unwrap();
        knob("shadows").set(&mut other, 0.0).unwrap();
        assert_eq!(relevant("ray", &base), relevant("ray", &other));
        assert_ne!(relevant("mesh", &base), relevant("mesh", &other));
        knob("ray-steps").set(&mut other, 64.0).unwrap();
        assert_ne!(
            relevant("ray-compute", &base),
            relevant("ray-compute", &other)
        );
        assert_eq!(relevant("sliced", &base), relevant("sliced", &other));
        assert!(knob("ray-steps").read_by("ray-compute"));
        assert!(!knob("ray-steps").read_by("mesh"));
        assert!(!Knob::Shadows.read_by("ray"));
    }

    #[test]
    fn counts_must_be_whole_and_positive() {
        let mut s = MethodSettings::default();
        for bad in [0.0, -3.0, 2.5, f32::NAN, f32::INFINITY] {
            assert!(knob("slices").set(&mut s, bad).is_err(), "{bad}");
        }
        knob("slices").set(&mut s, 256.0).unwrap();
        assert_eq!(s.slices, 256);
        assert!(Knob::parse("warp").is_err());
        assert_eq!(knob("density").name(), "density");
        // Every knob of the old list is still there, by name.
        for name in [
            "ray-steps",
            "voxel-steps",
            "slices",
            "density",
            "mesh-quality",
            "mesh-outline",
            "mesh-lod-pixels",
            "shadows",
        ] {
            assert_eq!(knob(name).name(), name);
        }
    }
}
