//! `scattered` (§3.5): point samples of the terrain scattered into a screen
//! buffer by a compute pass, the nearest kept by a 32-bit `atomicMin` of
//! `(24-bit depth << 8) | info` (info: surface kind << 3 | terrain type); a
//! full-screen pass then rebuilds each pixel's point from its depth and shades
//! it (`shaders/scattered.wgsl`, `shaders/scattered_resolve.wgsl`).
//!
//! # The grid and `scatter_density` (X, Y, Z)
//! Every density is in screen terms: X, Y and Z ask for `X * PER_PIXEL[0]`
//! samples per pixel across, `Y * PER_PIXEL[1]` along the (warped) distance
//! axis and `Z * PER_PIXEL[2]` per pixel of a column's projected height. The
//! paper's default (4, 4, 4) is 1.25, 1 and 1.25 ([`PER_PIXEL`]): a point splats
//! one pixel, so fewer leave holes (2 per 4 pixels: 50 % see-through at the
//! horizon) and more buy little. Work per frame grows with the image, not
//! with the world's texels.
//!
//! The footprint is the part of the frustum (near to far) with altitude in
//! 0..=256, seen from above in camera-aligned coordinates: `a` along the
//! horizontal heading `flat`, `c` along `right`, both from the eye. Its
//! outline is a convex polygon. A column at `(a, c)` is at least
//! `sqrt(a² + c² + h²)` from the eye, `h` the eye's clearance above the
//! highest column top in the footprint's bounding box (from a per-tile maximum
//! of the level, [`TopMax`]; at least the near distance), so one pixel there
//! is at most that distance / focal wide, taken at the image corners (whose
//! pixels are the smallest in angle). So the grid is
//! - rows uniform in `asinh(a / h)`, spacing `sqrt(a² + h²) / (focal * Y')`:
//!   logarithmic (like perspective) far away, fine only where the terrain can
//!   come close to the eye;
//! - columns uniform in `asinh(c / d)` within a row, `d = sqrt(a² + h²)`,
//!   spacing `sqrt(c² + d²) / (focal * X')`; `cols` is what the neediest row
//!   wants, and a row that wants fewer keeps every `2^k`-th (the rest return
//!   at once);
//! - a walk down each solid interval from its top, `[0, low]` and for a dual
//!   column `[mid, high]`, over the part that projects into the view (clipped
//!   analytically), each step `1 / Z'` pixels of the interval's projected
//!   height at that point, so a far column takes a few points and a column
//!   seen end-on one. The floor walk stops half a unit below the four
//!   neighbouring samples' floors (at the grid spacing: only the samples next
//!   to a texel's edge walk its sides),
//!   where boxes would hide it, and the slab's walk skips the part every
//!   neighbour's slab (or floor) hides; without this most points of a horizon
//!   view were buried inside the terrain.
//!
//! A sample whose whole column (0..=256) is off screen returns before reading
//! the texture. A grid over [`MAX_GRID`] samples is scaled down (both axes
//! alike) with a warning; each density is capped at [`MAX_DENSITY`]. Results
//! depend only on the camera and the terrain, never on earlier frames, so an
//! edit shows in the next frame (edits refresh the tile maximum).
//! [`count_points`] is a CPU twin of the scatter that counts its work.

mod grid;
mod knobs;
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{COLOR_FORMAT, DEPTH_FORMAT, Shared, uniform_layout_entry};
pub use grid::{
    MAX_DENSITY, MAX_GRID, NEAR_RADIUS, PER_PIXEL, ScatterParams, TopMax, checked_density,
    count_points, scatter_grid, slab_points,
};
pub use knobs::{KNOBS, SWEEP};
use strata_camera::Camera;
use strata_level::Level;

/// Invocations per scatter workgroup (`WORKGROUP` in scattered.wgsl).
const WORKGROUP: u32 = 64;

pub struct Scattered {
    density: [f32; 3],
    tops: TopMax,
    params: wgpu::Buffer,
    scatter_layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
    screen: ScreenBuffer,
    clear: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    resolve: wgpu::RenderPipeline,
    /// Most samples one frame may have: [`MAX_GRID`] and the dispatch limits.
    max_samples: u64,
    max_groups: u32,
    /// Workgroups of this frame's scatter (x, y); (0, 0) when nothing is in view.
    groups: (u32, u32),
    warned: bool,
}

fn storage_entry(
    binding: u32,
    read_only: bool,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// One packed depth + info word per pixel, and the groups that bind it.
struct ScreenBuffer {
    bytes: u64,
    scatter_group: wgpu::BindGroup,
    resolve_group: wgpu::BindGroup,
}

impl ScreenBuffer {
    /// Sized by the shared targets.
    fn new(
        shared: &Shared,
        params: &wgpu::Buffer,
        scatter_layout: &wgpu::BindGroupLayout,
        resolve_layout: &wgpu::BindGroupLayout,
    ) -> anyhow::Result<Self> {
        let device = &shared.device;
        let bytes = u64::from(shared.width) * u64::from(shared.height) * 4;
        let max_binding = device.limits().max_storage_buffer_binding_size;
        if bytes > max_binding {
            anyhow::bail!(
                "scattered: a {}x{} screen buffer needs {bytes} bytes, over this adapter's \
                 storage binding limit of {max_binding}",
                shared.width,
                shared.height
            );
        }
        let screen = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("scattered screen"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let scatter_group = crate::frame::bind_group(
            device,
            "scattered",
            scatter_layout,
            &[params.as_entire_binding(), screen.as_entire_binding()],
        );
        let resolve_group = crate::frame::bind_group(
            device,
            "scattered resolve",
            resolve_layout,
            &[screen.as_entire_binding()],
        );
        Ok(ScreenBuffer {
            bytes,
            scatter_group,
            resolve_group,
        })
    }
}

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let density = checked_density(settings.scatter_density)?;
    let device = &shared.device;
    let limits = device.limits();
    let params = shared.uniform_buffer("scattered", bytemuck::bytes_of(&ScatterParams::default()));
    let scatter_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scattered"),
        entries: &[
            uniform_layout_entry(0),
            storage_entry(1, false, wgpu::ShaderStages::COMPUTE),
        ],
    });
    let module = shared.shader("scattered.wgsl")?;
    let layout = shared.pipeline_layout("scattered", &[&scatter_layout]);
    let compute = |entry: &str| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let (clear, scatter) = (compute("cs_clear"), compute("cs_scatter"));

    let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scattered resolve"),
        entries: &[storage_entry(0, true, wgpu::ShaderStages::FRAGMENT)],
    });
    let screen = ScreenBuffer::new(shared, &params, &scatter_layout, &resolve_layout)?;
    let resolve_module = shared.shader("scattered_resolve.wgsl")?;
    let resolve = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("scattered resolve"),
        layout: Some(&shared.pipeline_layout("scattered resolve", &[&resolve_layout])),
        vertex: wgpu::VertexState {
            module: &resolve_module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &resolve_module,
            entry_point: Some("fs_resolve"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let max_groups = limits.max_compute_workgroups_per_dimension;
    let dispatchable = u64::from(max_groups) * u64::from(max_groups) * u64::from(WORKGROUP);
    Ok(Box::new(Scattered {
        density,
        tops: TopMax::new(level),
        params,
        scatter_layout,
        resolve_layout,
        screen,
        clear,
        scatter,
        resolve,
        max_samples: MAX_GRID.min(dispatchable),
        max_groups,
        groups: (0, 0),
        warned: false,
    }))
}

impl Method for Scattered {
    fn name(&self) -> &'static str {
        "scattered"
    }

    fn update_settings(
        &mut self,
        _shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        // The density only sizes next frame's grid.
        self.density = checked_density(settings.scatter_density)?;
        Ok(true)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        self.screen = ScreenBuffer::new(
            shared,
            &self.params,
            &self.scatter_layout,
            &self.resolve_layout,
        )?;
        Ok(())
    }

    fn apply_edit(
        &mut self,
        _shared: &Shared,
        level: &Level,
        rects: &[strata_level::DirtyRect],
    ) -> anyhow::Result<()> {
        if level.width() != self.tops.size[0] || level.height() != self.tops.size[1] {
            self.tops = TopMax::new(level);
        }
        for r in rects {
            self.tops.update(level, r);
        }
        Ok(())
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        let (max_top, near_top) = self.tops.bounds(camera);
        let (params, warning) =
            scatter_grid(camera, self.density, max_top, near_top, self.max_samples);
        if let Some(w) = warning
            && !self.warned
        {
            eprintln!("warning: {w}");
            self.warned = true;
        }
        let groups = params.samples().div_ceil(u64::from(WORKGROUP));
        // groups <= max_groups^2 by `max_samples`, so y fits too.
        let x = groups.min(u64::from(self.max_groups));
        self.groups = if groups == 0 {
            (0, 0)
        } else {
            (x as u32, groups.div_ceil(x) as u32)
        };
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("scattered clear"),
                timestamp_writes: frame.timer.compute("scattered clear"),
            });
            pass.set_pipeline(&self.clear);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.screen.scatter_group, &[]);
            pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
        }
        if self.groups.0 > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("scattered scatter"),
                timestamp_writes: frame.timer.compute("scattered scatter"),
            });
            pass.set_pipeline(&self.scatter);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.screen.scatter_group, &[]);
            pass.dispatch_workgroups(self.groups.0, self.groups.1, 1);
        }
        super::common::draw_fullscreen(
            shared,
            frame,
            encoder,
            "scattered resolve",
            &self.resolve,
            &self.screen.resolve_group,
        );
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The screen buffer (4 bytes per pixel) and the grid uniform.
        RetainedBytes {
            gpu: self.screen.bytes + std::mem::size_of::<ScatterParams>() as u64,
            cpu: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tile_maximum_follows_edits() {
        let mut level = Level::flat(64, 64, 10, 1).unwrap();
        let mut tops = TopMax::new(&level);
        assert_eq!(tops.max_in([-100.0, -100.0], [100.0, 100.0]), 10.0);
        level.planes_mut().0[0] = 200;
        let rect = strata_level::DirtyRect {
            x: 0,
            y: 0,
            width: 1,
            height: 1,
        };
        tops.update(&level, &rect);
        assert_eq!(tops.max_in([0.0, 0.0], [3.0, 3.0]), 200.0);
        // Wrapping: texel (0, 0) is also (64, 64).
        assert_eq!(tops.max_in([60.0, 60.0], [65.0, 65.0]), 200.0);
        assert_eq!(tops.max_in([20.0, 20.0], [40.0, 40.0]), 10.0);
    }
}
