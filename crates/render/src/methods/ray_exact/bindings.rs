//! The bindings and pipelines `ray-exact`'s passes share: the march, the
//! deferred frame's passes and the exact shadow map all read the pyramid and
//! the march's parameters the same way.

use super::pyramid::GpuMaxMip;
use crate::frame::Shared;
use crate::methods::common::DepthCopy;
use crate::options::{BeamSearch, ExactOptions};
use crate::paged::PagedTerrain;

pub(super) fn buffer_entry(
    binding: u32,
    stages: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: stages,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The pyramid the march reads: the whole map's, or paged terrain's coarse
/// level and page pyramids (with its page table, feedback and parameters).
pub enum Levels {
    /// The whole map's pyramid, built and updated on the GPU.
    Whole(Box<GpuMaxMip>),
    /// Pages of a world of any size (`crate::paged`).
    Paged(Box<PagedTerrain>),
}

impl Levels {
    /// The texel plane's first byte in the buffer, if it holds one.
    pub fn texel_plane(&self) -> Option<u32> {
        match self {
            Levels::Whole(p) => p.texel_plane(),
            Levels::Paged(_) => None,
        }
    }

    /// The buffer `maxmip` binds.
    fn buffer(&self) -> &wgpu::Buffer {
        match self {
            Levels::Whole(p) => &p.buffer,
            Levels::Paged(p) => &p.levels,
        }
    }

    /// Whether the march reads pages (shaders composed `paged:`).
    pub fn is_paged(&self) -> bool {
        matches!(self, Levels::Paged(_))
    }

    /// The shader name to compose for `name` over these levels.
    pub fn shader(&self, name: &str) -> String {
        if self.is_paged() {
            format!("{}{name}", crate::shaders::PAGED)
        } else {
            name.to_string()
        }
    }
}

/// Layout entries 0..=2 of group 1: parameters, pyramid, statistics; and
/// for paged levels 9..=11: page table, feedback, paging parameters.
pub(super) fn core_entries(
    stages: wgpu::ShaderStages,
    paged: bool,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let mut entries = vec![
        buffer_entry(0, stages, wgpu::BufferBindingType::Uniform),
        buffer_entry(
            1,
            stages,
            wgpu::BufferBindingType::Storage { read_only: true },
        ),
        buffer_entry(
            2,
            stages,
            wgpu::BufferBindingType::Storage { read_only: false },
        ),
    ];
    if paged {
        entries.extend([
            buffer_entry(
                9,
                stages,
                wgpu::BufferBindingType::Storage { read_only: true },
            ),
            buffer_entry(
                10,
                stages,
                wgpu::BufferBindingType::Storage { read_only: false },
            ),
            buffer_entry(
                11,
                stages,
                wgpu::BufferBindingType::Storage { read_only: true },
            ),
        ]);
    }
    entries
}

pub(super) fn core_bindings<'a>(
    params: &'a wgpu::Buffer,
    levels: &'a Levels,
    stats: &'a wgpu::Buffer,
) -> Vec<wgpu::BindGroupEntry<'a>> {
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: levels.buffer().as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: stats.as_entire_binding(),
        },
    ];
    if let Levels::Paged(p) = levels {
        for (binding, buffer) in [(9, &p.table), (10, &p.feedback), (11, &p.params)] {
            entries.push(wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            });
        }
    }
    entries
}

pub(super) fn march_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    levels: &Levels,
    stats: &wgpu::Buffer,
    depth: Option<&DepthCopy>,
    beam: Option<&wgpu::Buffer>,
) -> wgpu::BindGroup {
    let mut entries = core_bindings(params, levels, stats);
    if let Some(depth) = depth {
        entries.extend(depth.bindings(shared, 3));
    }
    entries.extend(beam.map(beam_binding));
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray-exact"),
        layout,
        entries: &entries,
    })
}

/// A compute pipeline of the exact core with its traversal constants.
pub(super) fn exact_pipeline(
    shared: &Shared,
    label: &str,
    levels: &Levels,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    entry: &str,
    options: ExactOptions,
) -> anyhow::Result<wgpu::ComputePipeline> {
    // Paged terrain starts at its coarse level, the whole map lower down.
    let start = if levels.is_paged() {
        strata_maxmip::MAX_LEVEL
    } else {
        super::START_LEVEL
    };
    let mut constants = vec![
        ("EXACT_CLIMB", f64::from(options.climb)),
        ("EXACT_LOG_RATIO", f64::from(options.log_ratio)),
        ("EXACT_START_LEVEL", f64::from(start)),
        (
            "EXACT_FUSED_DESCENT",
            f64::from(u8::from(options.fused_descent)),
        ),
        // Pages keep no cave pyramid (`paged_levels.wgsl` skips nothing).
        // Shadow rays come down from above the map, never under a slab: on
        // the H100 the test only cost their pass (0.0346 -> 0.0360 ms,
        // `bench/issue36-cave-skip/`).
        (
            "EXACT_CAVE_SKIP",
            f64::from(u8::from(
                options.cave_skip && !levels.is_paged() && shader != "ray_exact_shadow.wgsl",
            )),
        ),
        // The texel walk needs the plane, which only a whole map's pyramid
        // may hold (`GpuMaxMip::texel_plane`).
        (
            "EXACT_TEXEL_BLOCKS",
            f64::from(if levels.texel_plane().is_some() {
                options.texel_walk.constant()
            } else {
                0
            }),
        ),
        (
            "EXACT_ITERATION_STATS",
            f64::from(u8::from(
                options.iteration_stats || shared.options.exact_stats,
            )),
        ),
    ];
    if reads_beam(levels, shader) {
        constants.push(("EXACT_BEAM", f64::from(u8::from(options.beam))));
        let search = match options.beam_search {
            BeamSearch::Serial => 0u8,
            BeamSearch::Wide => 1,
            BeamSearch::WidePass => 2,
        };
        constants.push(("EXACT_BEAM_SEARCH", f64::from(search)));
        let rounds = options.shadow_rounds.clamp(1, super::replay::WIDE_ROUNDS);
        constants.push(("EXACT_SHADOW_ROUNDS", f64::from(rounds)));
        constants.push(("EXACT_BEAM_LEVEL", f64::from(super::BEAM_LEVEL)));
        constants.push((
            "EXACT_BEAM_TEXELS",
            f64::from(u8::from(options.beam_texels)),
        ));
    }
    if matches!(shader, "ray_exact.wgsl" | "ray_exact_deferred.wgsl") {
        // The pipelines that shade (`shading.wgsl`).
        constants.push((
            "SHADE_FETCH_CHAIN",
            f64::from(u8::from(options.shade_fetch_chain)),
        ));
    }
    super::super::common::compute_pipeline_with_constants(
        shared,
        label,
        &levels.shader(shader),
        layout,
        entry,
        &constants,
    )
}

/// The binding of the beam pre-pass's tile starts in group 1
/// (`exact_beams` in `ray_exact_beam.wgsl`).
pub(super) const BEAM_BINDING: u32 = 12;

/// Whether `shader` over `levels` reads the beam's starts (and takes the
/// `EXACT_BEAM` constants): the compute frames over the whole map.
pub(super) fn reads_beam(levels: &Levels, shader: &str) -> bool {
    !levels.is_paged()
        && matches!(
            shader,
            "ray_exact.wgsl" | "ray_exact_deferred.wgsl" | "ray_exact_shadow.wgsl"
        )
}

/// The layout entry of the beam's starts.
pub(super) fn beam_layout_entry() -> wgpu::BindGroupLayoutEntry {
    buffer_entry(
        BEAM_BINDING,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BufferBindingType::Storage { read_only: false },
    )
}

/// The group entry of the beam's starts.
pub(super) fn beam_binding(buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding: BEAM_BINDING,
        resource: buffer.as_entire_binding(),
    }
}
