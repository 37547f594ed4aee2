//! The method settings the overlay's sliders and a script's `set` change,
//! which methods read each, and when a kept method still matches them.

use anyhow::{Context, bail};
use strata_render::MethodSettings;

/// The settings a script (and the overlay) can change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Knob {
    RaySteps,
    VoxelSteps,
    Slices,
    Density,
    MeshQuality,
    /// The outline-constrained mesh fit (0 off, else on).
    MeshOutline,
    /// The mesh's LOD tolerance in pixels.
    MeshLodPixels,
    Shadows,
}

impl Knob {
    pub const ALL: [(&'static str, Knob); 8] = [
        ("ray-steps", Knob::RaySteps),
        ("voxel-steps", Knob::VoxelSteps),
        ("slices", Knob::Slices),
        ("density", Knob::Density),
        ("mesh-quality", Knob::MeshQuality),
        ("mesh-outline", Knob::MeshOutline),
        ("mesh-lod-pixels", Knob::MeshLodPixels),
        ("shadows", Knob::Shadows),
    ];

    pub fn parse(name: &str) -> anyhow::Result<Knob> {
        Knob::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, k)| *k)
            .with_context(|| {
                let names: Vec<_> = Knob::ALL.iter().map(|(n, _)| *n).collect();
                format!("unknown setting `{name}`; known: {}", names.join(", "))
            })
    }
    /// The methods that read this knob (none: a frame setting).
    pub fn methods(self) -> &'static [&'static str] {
        match self {
            Knob::RaySteps => &["ray", "ray-compute"],
            Knob::VoxelSteps => &["voxel", "voxel-compute"],
            Knob::Slices => &["sliced"],
            Knob::Density => &["scattered"],
            Knob::MeshQuality | Knob::MeshOutline | Knob::MeshLodPixels => &["mesh"],
            Knob::Shadows => &[],
        }
    }

    /// Write `value` into the knob's field of `settings` (counts must be
    /// whole and positive; each method checks its own range when built).
    pub fn set(self, settings: &mut MethodSettings, value: f32) -> anyhow::Result<()> {
        let count = |v: f32| -> anyhow::Result<u32> {
            if v >= 1.0 && v.fract() == 0.0 && v <= 1e6 {
                Ok(v as u32)
            } else {
                bail!("{value} is not a positive whole number")
            }
        };
        if !value.is_finite() {
            bail!("{value} is not a number");
        }
        match self {
            Knob::RaySteps => settings.ray_steps = count(value)?,
            Knob::VoxelSteps => settings.voxel_steps = count(value)?,
            Knob::Slices => settings.slices = count(value)?,
            Knob::Density => settings.scatter_density = [value; 3],
            Knob::MeshQuality => settings.mesh_quality = value,
            Knob::MeshOutline => settings.mesh_outline = value != 0.0,
            Knob::MeshLodPixels => settings.mesh_lod_pixels = value,
            Knob::Shadows => settings.shadows = value != 0.0,
        }
        Ok(())
    }
}

/// The settings of `s` that method `name` reads (the rest at defaults), so
/// two settings are "the same" for a method when these are equal.
pub fn relevant(name: &str, s: &MethodSettings) -> MethodSettings {
    let d = MethodSettings::default();
    let uses = |knob: Knob| knob.methods().contains(&name);
    MethodSettings {
        ray_steps: if uses(Knob::RaySteps) {
            s.ray_steps
        } else {
            d.ray_steps
        },
        voxel_steps: if uses(Knob::VoxelSteps) {
            s.voxel_steps
        } else {
            d.voxel_steps
        },
        voxel_size: if name.starts_with("voxel") {
            s.voxel_size
        } else {
            d.voxel_size
        },
        slices: if uses(Knob::Slices) {
            s.slices
        } else {
            d.slices
        },
        sliced_refine: name == "sliced" && s.sliced_refine,
        scatter_density: if uses(Knob::Density) {
            s.scatter_density
        } else {
            d.scatter_density
        },
        mesh_quality: if uses(Knob::MeshQuality) {
            s.mesh_quality
        } else {
            d.mesh_quality
        },
        mesh_outline: if uses(Knob::MeshOutline) {
            s.mesh_outline
        } else {
            d.mesh_outline
        },
        mesh_lod_pixels: if uses(Knob::MeshLodPixels) {
            s.mesh_lod_pixels
        } else {
            d.mesh_lod_pixels
        },
        mesh_gradient_normal: name == "mesh" && s.mesh_gradient_normal,
        shadows: d.shadows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_method_is_current_whatever_the_knobs_it_does_not_read() {
        let base = MethodSettings::default();
        let mut other = base.clone();
        Knob::MeshQuality.set(&mut other, 0.75).unwrap();
        Knob::Shadows.set(&mut other, 0.0).unwrap();
        assert_eq!(relevant("ray", &base), relevant("ray", &other));
        assert_ne!(relevant("mesh", &base), relevant("mesh", &other));
        Knob::RaySteps.set(&mut other, 64.0).unwrap();
        assert_ne!(
            relevant("ray-compute", &base),
            relevant("ray-compute", &other)
        );
        assert_eq!(relevant("sliced", &base), relevant("sliced", &other));
    }

    #[test]
    fn counts_must_be_whole_and_positive() {
        let mut s = MethodSettings::default();
        for bad in [0.0, -3.0, 2.5, f32::NAN, f32::INFINITY] {
            assert!(Knob::Slices.set(&mut s, bad).is_err(), "{bad}");
        }
        Knob::Slices.set(&mut s, 256.0).unwrap();
        assert_eq!(s.slices, 256);
        assert!(Knob::parse("warp").is_err());
        assert_eq!(Knob::parse("density").unwrap(), Knob::Density);
    }
}
