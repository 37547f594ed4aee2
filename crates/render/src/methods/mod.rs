//! The methods: one module each, behind one trait.
//!
//! # Adding a method
//! A method is four files: its module, its WGSL, the shader list and one
//! entry in [`METHODS`].
//! 1. Write `src/methods/<name>.rs` (or a folder `src/methods/<name>/` when
//!    it grows helpers) with a struct implementing [`Method`] and a
//!    `pub fn create(shared: &Shared, level: &Level, settings: &MethodSettings)
//!    -> anyhow::Result<Box<dyn Method>>` that validates its own settings field
//!    (clear error on 0 etc.) and builds its pipelines. Its knobs (a
//!    [`Knobs`]: the `name:SETTING` form, its default, the results' record,
//!    the viewer's sliders, `strata render`'s flags) and its [`Sweep`] for
//!    `strata tune` live there too; a new knob is a field of
//!    [`MethodSettings`] (`contract.rs`).
//! 2. Put its WGSL in `shaders/<name>.wgsl`, starting with
//!    `#include "frame.wgsl"`, `"surface.wgsl"`, `"shading.wgsl"` (and
//!    `"ray_core.wgsl"`, `"fullscreen.wgsl"` as needed); add the file to
//!    `shaders::SOURCES` and `shaders::ENTRY_SHADERS` (the naga test validates it).
//! 3. Add one entry to [`METHODS`] below: the only place a name maps to code,
//!    with the [`Capability`]s beyond WebGL2's baseline the method uses
//!    (compute, storage textures, storage buffers per stage), so an adapter
//!    without them refuses it before any GPU work, its knobs and its sweep.
//!    The CLI (`--methods`, `strata render`'s flags), the results, the
//!    viewer's panel and scripts, `strata tune` and the browser page's
//!    `?NAME=SETTING` read it from there.
//!
//! # The contract
//! - Group 0 of every pipeline is the shared frame ([`Shared::frame_layout`],
//!   bind [`Shared::frame_group`]); build layouts with [`Shared::pipeline_layout`].
//!   Your own bindings go in groups 1 and up.
//! - Draw into [`Shared::color_view`] ([`crate::COLOR_FORMAT`]) and
//!   [`Shared::depth_view`] ([`crate::DEPTH_FORMAT`], depth 0 near .. 1 far
//!   from `Camera::view_proj`, `Less` test). Your first pass that touches them
//!   must clear them: colour to [`crate::frame::sky_clear`], depth to 1.0.
//!   Every pixel ends with a colour and a depth (sky = 1.0).
//! - Shade every surface point with `shade(p, ray_dir)` from `shading.wgsl`
//!   (the mesh: `shade_with_normal`), so palette, light, cave ambient,
//!   shadow and fog are the same in every method.
//! - Every pass you begin takes its timestamp writes from
//!   `frame.timer.render("label")` / `.compute("label")`, so the frame's GPU
//!   time is the sum over passes.
//! - `apply_edit` runs after the shared terrain texture has been updated;
//!   methods that only read the texture need not override it.
//! - `retained_bytes` counts only what the method allocates beyond [`Shared`].
//! - `update_settings` takes what it can in place (the viewer's sliders);
//!   the default asks for a rebuild.
//! - A method that binds the shared targets, or sizes anything by them, in
//!   `create` must redo that in `resize` (the viewer follows its window).

mod build_bindings;
mod coalesce;
mod common;
pub mod contract;
#[doc(hidden)]
pub mod forward;
pub mod knobs;
mod march_beam;
#[doc(hidden)]
pub mod mesh;
#[doc(hidden)]
pub mod painted;
#[doc(hidden)]
pub mod ray;
#[doc(hidden)]
pub mod ray_compute;
#[doc(hidden)]
pub mod ray_exact;
#[doc(hidden)]
pub mod scattered;
#[doc(hidden)]
pub mod sliced;
#[doc(hidden)]
pub mod voxel;

/// The integration tests' helpers (adapter skip, metric loops, distance
/// comparisons), shared by the methods' unit tests; `strata_render::` paths
/// there resolve through the `extern crate self` alias in lib.rs.
#[cfg(test)]
#[path = "../../tests/common/mod.rs"]
pub(crate) mod test_common;

pub use contract::{
    BuildSteps, Constructor, Frame, FrameTargets, Method, MethodSettings, RetainedBytes,
    StepsConstructor,
};
pub use knobs::{Flag, Knobs, Slider, SliderKind, Sweep};

use crate::caps::{Capabilities, Capability, Refusal};
use crate::frame::Shared;
use strata_level::Level;

/// A method by name: how to build it, what it needs of the adapter, and its
/// knobs. Callers outside the renderer identify a method by its entry
/// (`&'static MethodEntry`), never by a label.
pub struct MethodEntry {
    /// The name `Renderer::new` and `--method` take.
    pub name: &'static str,
    /// Builds it whole.
    pub create: Constructor,
    /// A build in slices, for methods whose CPU preparation takes long
    /// (built whole in one step when `None`).
    pub in_steps: Option<StepsConstructor>,
    /// Capabilities beyond WebGL2's baseline (a fragment pass reading the
    /// terrain texture) that its pipelines use.
    pub needs: &'static [Capability],
    /// Its settings as the CLI, the results, the viewer and the page see them.
    pub knobs: &'static Knobs,
    /// Its sweep in `strata tune` (`None`: not tuned).
    pub tune: Option<&'static Sweep>,
}

impl MethodEntry {
    /// `Err` naming what `caps` lacks for this method.
    pub fn check(&self, caps: &Capabilities) -> Result<(), Refusal> {
        let missing = caps.missing(self.needs);
        if missing.is_empty() {
            Ok(())
        } else {
            Err(Refusal {
                method: self.name.to_string(),
                missing,
            })
        }
    }

    /// `settings` with `setting` (`name:SETTING`'s part after the colon)
    /// applied; an error says what was wrong with it.
    pub fn apply_setting(
        &self,
        setting: &str,
        settings: &mut MethodSettings,
    ) -> anyhow::Result<()> {
        if self.knobs.default.is_none() {
            anyhow::bail!("`{}` has no setting to change", self.name);
        }
        (self.knobs.parse)(setting, settings)
    }

    /// The settings this method read, for the results' record: its name and
    /// its knobs (`ray steps=128`, `mesh q=0.5 lod=1px`).
    pub fn describe(&self, settings: &MethodSettings) -> String {
        let knobs = (self.knobs.describe)(settings);
        if knobs.is_empty() {
            self.name.to_string()
        } else {
            format!("{} {knobs}", self.name)
        }
    }

    /// The settings of `s` this method reads (the rest at their defaults,
    /// shadows too), so two settings are the same for it when these are equal.
    pub fn relevant(&self, s: &MethodSettings) -> MethodSettings {
        let mut out = MethodSettings::default();
        (self.knobs.keep)(s, &mut out);
        out
    }

    /// Whether this method reads `slider`.
    pub fn reads(&self, slider: &Slider) -> bool {
        self.knobs.sliders.iter().any(|s| s.name == slider.name)
    }
}

/// Names are unique in [`METHODS`]: an entry is its name.
impl PartialEq for MethodEntry {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for MethodEntry {}

impl std::fmt::Debug for MethodEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MethodEntry({})", self.name)
    }
}

use Capability::{ComputeShaders, FragmentStorage, StorageTextures, VertexStorage};

/// Every method: the only place a name maps to code.
pub const METHODS: &[MethodEntry] = &[
    MethodEntry {
        name: "ray",
        create: ray::create,
        in_steps: None,
        needs: &[],
        knobs: &ray::KNOBS,
        tune: Some(&ray::SWEEP),
    },
    MethodEntry {
        name: "ray-compute",
        create: ray_compute::create,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
        knobs: &ray::KNOBS,
        tune: None,
    },
    MethodEntry {
        name: "ray-exact",
        // The pyramid is built and edited by compute passes; the march is a
        // compute dispatch writing storage images.
        create: ray_exact::create,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
        knobs: &Knobs::NONE,
        tune: Some(&ray_exact::SWEEP),
    },
    MethodEntry {
        name: "ray-exact-fragment",
        create: ray_exact::create_fragment,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
        knobs: &Knobs::NONE,
        tune: None,
    },
    MethodEntry {
        name: "voxel",
        // The occupancy pyramid is built and edited by compute passes.
        create: voxel::create,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
        knobs: &voxel::KNOBS,
        tune: Some(&voxel::SWEEP),
    },
    MethodEntry {
        name: "voxel-compute",
        create: voxel::create_compute,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
        knobs: &voxel::KNOBS,
        tune: None,
    },
    MethodEntry {
        name: "painted",
        create: painted::create,
        in_steps: None,
        needs: &[],
        knobs: &Knobs::NONE,
        tune: Some(&painted::SWEEP),
    },
    MethodEntry {
        name: "sliced",
        create: sliced::create,
        in_steps: None,
        needs: &[],
        knobs: &sliced::KNOBS,
        tune: Some(&sliced::SWEEP),
    },
    MethodEntry {
        name: "mesh",
        // Vertices fetch their chunk's placement from a storage buffer.
        create: mesh::create,
        in_steps: Some(mesh::build_in_steps),
        needs: &[VertexStorage],
        knobs: &mesh::KNOBS,
        tune: Some(&mesh::SWEEP),
    },
    MethodEntry {
        name: "scattered",
        // Compute scatters into an atomic screen buffer; a fragment pass resolves it.
        create: scattered::create,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
        knobs: &scattered::KNOBS,
        tune: Some(&scattered::SWEEP),
    },
];

/// How a caller names a method: its entry, or its name.
pub trait MethodId {
    /// The entry in [`METHODS`], or an error listing the known names.
    fn entry(&self) -> anyhow::Result<&'static MethodEntry>;
}

impl MethodId for str {
    fn entry(&self) -> anyhow::Result<&'static MethodEntry> {
        entry(self)
    }
}

impl MethodId for String {
    fn entry(&self) -> anyhow::Result<&'static MethodEntry> {
        entry(self)
    }
}

impl<T: MethodId + ?Sized> MethodId for &T {
    fn entry(&self) -> anyhow::Result<&'static MethodEntry> {
        (**self).entry()
    }
}

impl MethodId for MethodEntry {
    fn entry(&self) -> anyhow::Result<&'static MethodEntry> {
        entry(self.name)
    }
}

/// The names [`create`] accepts.
pub fn names() -> Vec<&'static str> {
    METHODS.iter().map(|m| m.name).collect()
}

/// The method called `name`, or an error listing the known ones.
pub fn entry(name: &str) -> anyhow::Result<&'static MethodEntry> {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .ok_or_else(|| anyhow::anyhow!("unknown method `{name}`; known: {}", names().join(", ")))
}

/// Whether `method` runs on an adapter with `caps`: `Err` with the
/// reason (an unknown name, or the capabilities it lacks).
pub fn check_support(method: &(impl MethodId + ?Sized), caps: &Capabilities) -> anyhow::Result<()> {
    method.entry()?.check(caps)?;
    Ok(())
}

/// The methods an adapter with `caps` can run.
pub fn supported(caps: &Capabilities) -> Vec<&'static str> {
    METHODS
        .iter()
        .filter(|m| m.check(caps).is_ok())
        .map(|m| m.name)
        .collect()
}

/// Build `method`; refused before any GPU work when the shared frame's
/// adapter lacks what it needs. A GPU error during the build (out of memory,
/// a refused allocation) is an error naming the method and the sizes
/// ([`crate::build_guard`]).
pub fn create(
    method: &(impl MethodId + ?Sized),
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let entry = method.entry()?;
    entry.check(&shared.caps)?;
    let target = crate::build_guard::BuildTarget {
        method: entry.name,
        width: shared.width,
        height: shared.height,
        level,
    };
    crate::build_guard::guarded(&shared.device, &shared.options, &target, || {
        (entry.create)(shared, level, settings)
    })
}

/// Start building `method` in slices ([`BuildSteps`]); refused at once,
/// like [`create`], when the adapter lacks what it needs.
pub fn create_in_steps(
    method: &(impl MethodId + ?Sized),
    caps: &Capabilities,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn BuildSteps>> {
    let entry = method.entry()?;
    entry.check(caps)?;
    match entry.in_steps {
        Some(start) => start(settings),
        None => Ok(Box::new(Whole {
            create: entry.create,
            settings: settings.clone(),
        })),
    }
}

/// A method without a sliced build: built whole in its first step.
struct Whole {
    create: Constructor,
    settings: MethodSettings,
}

impl BuildSteps for Whole {
    fn step(
        &mut self,
        shared: &Shared,
        level: &Level,
        _: f64,
    ) -> anyhow::Result<Option<Box<dyn Method>>> {
        (self.create)(shared, level, &self.settings).map(Some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_every_default_parses() {
        for (i, m) in METHODS.iter().enumerate() {
            assert!(!METHODS[..i].iter().any(|o| o.name == m.name), "{}", m.name);
            if let Some(default) = m.knobs.default {
                let mut s = MethodSettings::default();
                m.apply_setting(default, &mut s).unwrap();
                assert_eq!(s, MethodSettings::default(), "{}:{default}", m.name);
            } else {
                assert!(
                    m.apply_setting("1", &mut MethodSettings::default())
                        .is_err()
                );
            }
        }
    }

    #[test]
    fn webgl2_runs_the_fragment_methods_and_names_what_the_rest_lack() {
        let caps = Capabilities::webgl2();
        assert_eq!(supported(&caps), ["ray", "painted", "sliced"]);
        let error = check_support("ray-compute", &caps).unwrap_err().to_string();
        assert_eq!(
            error,
            "ray-compute: needs compute shaders and storage textures, which this adapter lacks"
        );
        let error = check_support("mesh", &caps).unwrap_err().to_string();
        assert_eq!(
            error,
            "mesh: needs storage buffers in vertex shaders, which this adapter lacks"
        );
        assert_eq!(
            caps.shadow_pass(),
            Some(crate::caps::ShadowPassKind::Fragment)
        );
    }

    #[test]
    fn a_full_adapter_runs_every_method() {
        let caps = Capabilities::full();
        assert_eq!(supported(&caps).len(), METHODS.len());
        assert_eq!(
            caps.shadow_pass(),
            Some(crate::caps::ShadowPassKind::Compute)
        );
        assert!(check_support("no-such-method", &caps).is_err());
    }
}
