//! Where `ray` and `voxel` begin each camera ray's march (issue 36 item 2):
//! `ray-exact`'s beam pre-pass, called as it is (`cs_exact_beam` in
//! `ray_exact_beam.wgsl`: one invocation per 8x8-pixel tile searches the
//! least `t` at which any ray of the tile may meet a solid point, and its
//! argument shows it never passes a hit), over a max-height pyramid of the
//! whole map that the method keeps ([`GpuMaxMip`], updated by its edits).
//! The fragment pass reads the tile's start (`march_beam.wgsl`) and marches
//! from the last of its own samples before it (`ray_core.wgsl::march_from`,
//! `voxel_core.wgsl::voxel_march_from`): the same samples, fewer of them.
//!
//! The pass is compute and the starts a storage buffer the fragment reads:
//! an adapter without compute or fragment storage (WebGL2) marches without
//! it ([`MarchBeam::available`]), as `ray:N/nobeam` and `voxel:…/nobeam` do.

use super::contract::Frame;
use super::ray_exact::pyramid::GpuMaxMip;
use super::ray_exact::{ExactOptions, exact_params};
use crate::frame::{Shared, uniform_layout_entry};
use strata_level::{DirtyRect, Level};

/// Side of a tile in pixels (`MARCH_BEAM_TILE`, ray-exact's `BEAM_TILE`).
const TILE: u32 = super::ray_exact::replay::BEAM_TILE;

/// The binding of the starts in the fragment's group 1 (`march_starts`).
pub(crate) const STARTS_BINDING: u32 = 2;

/// The beam pass's binding of the starts (`exact_beams`).
const BEAM_BINDING: u32 = 12;

fn storage_entry(
    binding: u32,
    stages: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: stages,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The pyramid, the beam pass and the tiles' starts it writes.
pub(crate) struct MarchBeam {
    pyramid: GpuMaxMip,
    params: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    /// One f32 per tile of the targets.
    starts: wgpu::Buffer,
    /// The pass's label (`ray beam`, `voxel beam`).
    label: &'static str,
}

/// The starts' buffer for the shared targets' size.
fn starts_buffer(shared: &Shared) -> wgpu::Buffer {
    let tiles = u64::from(shared.width.div_ceil(TILE)) * u64::from(shared.height.div_ceil(TILE));
    shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("march beam starts"),
        size: tiles.max(1) * 4,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    })
}

impl MarchBeam {
    /// Whether this adapter runs the pass, lets the fragment read its
    /// starts and binds the pyramid of `level` (a map too large for it is
    /// drawn without the beam, as before, rather than refused).
    pub(crate) fn available(shared: &Shared, level: &Level) -> bool {
        let step = ExactOptions {
            compute: true,
            ..ExactOptions::DEFAULT
        }
        .pyramid_step();
        let bytes = u64::from(
            strata_maxmip::Layout::with_step(level.width(), level.height(), step)
                .bytes
                .max(4),
        );
        let limits = shared.device.limits();
        shared.caps.compute
            && shared.caps.fragment_storage
            && bytes
                <= limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size)
    }

    /// Build the pyramid (one submission, waited for) and the pass.
    pub(crate) fn new(shared: &Shared, level: &Level, label: &'static str) -> anyhow::Result<Self> {
        let options = ExactOptions {
            compute: true,
            ..ExactOptions::DEFAULT
        };
        let pyramid = GpuMaxMip::new(shared, level, options.pyramid_step(), false)?;
        let params = shared.uniform_buffer(
            "march beam params",
            bytemuck::bytes_of(&exact_params(&pyramid.layout)),
        );
        let stage = wgpu::ShaderStages::COMPUTE;
        let layout = shared
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &[
                    uniform_layout_entry(0),
                    storage_entry(1, stage, true),
                    storage_entry(BEAM_BINDING, stage, false),
                ],
            });
        let pipeline = super::common::compute_pipeline_with_constants(
            shared,
            label,
            "ray_exact.wgsl",
            &shared.pipeline_layout(label, &[&layout]),
            "cs_exact_beam",
            &[
                ("EXACT_LOG_RATIO", f64::from(options.log_ratio)),
                ("EXACT_BEAM", 1.0),
            ],
        )?;
        let starts = starts_buffer(shared);
        let group = Self::group(shared, &layout, &params, &pyramid, &starts);
        Ok(MarchBeam {
            pyramid,
            params,
            pipeline,
            layout,
            group,
            starts,
            label,
        })
    }

    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        pyramid: &GpuMaxMip,
        starts: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("march beam"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: pyramid.buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: BEAM_BINDING,
                    resource: starts.as_entire_binding(),
                },
            ],
        })
    }

    /// The fragment's layout entry for the starts.
    pub(crate) fn layout_entry() -> wgpu::BindGroupLayoutEntry {
        storage_entry(STARTS_BINDING, wgpu::ShaderStages::FRAGMENT, true)
    }

    /// A compute pass's layout entry for the starts (`sliced`'s deferred
    /// shading walks its gaps from them).
    pub(crate) fn compute_layout_entry() -> wgpu::BindGroupLayoutEntry {
        storage_entry(STARTS_BINDING, wgpu::ShaderStages::COMPUTE, true)
    }

    /// The fragment's group entry for the starts.
    pub(crate) fn binding(&self) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding: STARTS_BINDING,
            resource: self.starts.as_entire_binding(),
        }
    }

    /// Queue an edit's rectangles (the pyramid follows on the next frame).
    pub(crate) fn enqueue(&mut self, rects: &[DirtyRect]) {
        self.pyramid.enqueue(rects);
    }

    /// Write this frame's pyramid update parameters.
    pub(crate) fn prepare(&mut self, shared: &Shared) {
        self.pyramid.prepare(shared);
    }

    /// Starts for the targets' new size (rebind [`MarchBeam::binding`]).
    pub(crate) fn resize(&mut self, shared: &Shared) {
        self.starts = starts_buffer(shared);
        self.group = Self::group(
            shared,
            &self.layout,
            &self.params,
            &self.pyramid,
            &self.starts,
        );
    }

    /// The pyramid's update (after an edit) and the beam pass, before the march.
    pub(crate) fn record(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        self.record_pyramid_update(frame, encoder);
        self.record_beam(shared, frame, encoder);
    }

    /// The pyramid's update alone, if this frame has one (every frame an
    /// edit is queued, so the queue never grows; `prepare` schedules it).
    pub(crate) fn record_pyramid_update(
        &self,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        if self.pyramid.has_work() {
            self.pyramid
                .record(encoder, frame.timer.compute("march beam pyramid update"));
        }
    }

    /// The beam pass alone (the pyramid current).
    pub(crate) fn record_beam(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(self.label),
            timestamp_writes: frame.timer.compute(self.label),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        let tiles = (shared.width.div_ceil(TILE), shared.height.div_ceil(TILE));
        pass.dispatch_workgroups(tiles.0.div_ceil(8), tiles.1.div_ceil(8), 1);
    }

    /// GPU bytes: pyramid, its update slots, parameters and starts.
    pub(crate) fn gpu_bytes(&self) -> u64 {
        self.pyramid.gpu_bytes() + self.params.size() + self.starts.size()
    }
}

/// The highest column top of the map (every solid point is at or below it):
/// its highest height byte.
pub(crate) fn highest_top(level: &Level) -> u32 {
    level.heights().iter().copied().max().map_or(0, u32::from)
}

/// The highest height byte inside `rects` (an edit's new heights).
pub(crate) fn highest_top_in(level: &Level, rects: &[DirtyRect]) -> u32 {
    let width = level.width() as usize;
    let heights = level.heights();
    let mut top = 0u8;
    for r in rects {
        for y in r.y..r.y + r.height {
            let row = y as usize * width;
            let from = row + r.x as usize;
            let to = from + r.width as usize;
            if let Some(m) = heights[from..to].iter().copied().max() {
                top = top.max(m);
            }
        }
    }
    u32::from(top)
}

/// `strata render --no-march-beam` (`ray`, `voxel`): march as before.
pub(crate) const NO_BEAM_FLAG: super::knobs::Flag = super::knobs::Flag {
    long: "no-march-beam",
    value: None,
    help: "`ray`, `voxel`, `sliced`: no beam pre-pass (each ray marches, and each of `sliced`'s per-pixel walks starts, from its near end, as before; `ray:N/nobeam`).",
    default: |_| String::new(),
    apply: |_, s| {
        s.march_beam = false;
        Ok(())
    },
};

/// Split a trailing `/nobeam` off a method's setting: the rest, and whether
/// the beam stays on.
pub(crate) fn split_nobeam(text: &str) -> (&str, bool) {
    match text.strip_suffix("/nobeam") {
        Some(rest) => (rest, false),
        None if text == "nobeam" => ("", false),
        None => (text, true),
    }
}

/// What a method's settings record says after its knobs when the beam is off.
pub(crate) fn nobeam_tag(s: &super::contract::MethodSettings) -> &'static str {
    if s.march_beam { "" } else { " nobeam" }
}

#[cfg(test)]
mod tests {
    use super::super::contract::MethodSettings;
    use super::super::{ray, voxel};

    fn parsed(knobs: &super::super::Knobs, text: &str) -> anyhow::Result<MethodSettings> {
        let mut s = MethodSettings::default();
        (knobs.parse)(text, &mut s)?;
        Ok(s)
    }

    #[test]
    fn nobeam_is_a_setting_of_ray_and_voxel() {
        let s = parsed(&ray::KNOBS, "128/nobeam").unwrap();
        assert_eq!((s.ray_steps, s.march_beam), (128, false));
        assert_eq!((ray::KNOBS.describe)(&s), "steps=128 nobeam");
        let s = parsed(&ray::KNOBS, "64").unwrap();
        assert_eq!((s.ray_steps, s.march_beam), (64, true));
        assert_eq!((ray::KNOBS.describe)(&s), "steps=64");
        assert!(parsed(&ray::KNOBS, "128/beam").is_err());
        assert!(parsed(&ray::KNOBS, "nobeam").is_err());

        let s = parsed(&voxel::KNOBS, "4,8,2/100/nobeam").unwrap();
        assert_eq!(
            (s.voxel_size, s.voxel_steps, s.march_beam),
            ([4, 8, 2], 100, false)
        );
        assert_eq!((voxel::KNOBS.describe)(&s), "grid=(4,8,2) steps=100 nobeam");
        let s = parsed(&voxel::KNOBS, "/nobeam").unwrap();
        assert_eq!(
            s,
            MethodSettings {
                march_beam: false,
                ..MethodSettings::default()
            }
        );
        let s = parsed(&voxel::KNOBS, "2,4,1/50").unwrap();
        assert!(s.march_beam);
        // The beam is one of the settings two runs must share.
        let mut kept = MethodSettings::default();
        (voxel::KNOBS.keep)(&parsed(&voxel::KNOBS, "/nobeam").unwrap(), &mut kept);
        assert!(!kept.march_beam);
    }
}
