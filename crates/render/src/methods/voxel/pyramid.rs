//! The occupancy pyramid on the GPU (`voxel_build.wgsl`): one storage buffer
//! laid out by `strata_occupancy::Layout`, filled by compute passes that
//! build level-0 tile columns from the terrain texture and reduce upward.
//!
//! All work goes through one queue of level-0 tile-column rectangles and a
//! per-frame texel budget: creation runs the whole queue in budget-sized
//! submissions (waiting on each, so no single submission is long), edits
//! queue their dirty tile columns and each frame takes what the budget
//! allows, re-reducing the ancestors of exactly what it rebuilt.

use super::super::build_bindings::BuildBindings;
use super::super::coalesce::coalesce;
use crate::frame::{Globals, LevelShape, Shared};
use std::collections::VecDeque;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_occupancy::{Layout, TileRange, VoxelSize};
use web_time::Instant;

/// Default level-0 texels rebuilt per frame (and per creation submission).
pub const DEFAULT_BUDGET_TEXELS: u64 = 1 << 20;
/// Dispatches recorded per submission (uniform slots).
const MAX_SLOTS: usize = 256;
/// Most queued tile ranges kept apart: more (a game's frame of 64 track
/// stamps, each its own range) merge into bounding boxes, so the queue never
/// outgrows what a frame's slots take. It did: 64 ranges a frame in, about
/// 36 out, and after 600 frames of `compare --gameplay` the occupancy lagged
/// the terrain by more than the check's frames.
const MAX_RANGES: usize = 8;

/// Twin of `BuildParams` in `voxel_build.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BuildParams {
    voxel: [u32; 4],
    dims: [u32; 4],
    tiles: [u32; 4],
    child: [u32; 4],
    origin: [u32; 4],
}

/// One dispatch: rebuild (level 0) or re-reduce (coarser) tile columns of a level.
#[derive(Clone, Copy, Debug)]
struct Dispatch {
    level: usize,
    range: TileRange,
}

pub struct GpuPyramid {
    pub layout: Layout,
    pub buffer: wgpu::Buffer,
    leaf: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    /// Group 0 for the build: the shared frame's layout over a private
    /// globals buffer that carries only the level shape (the build must not
    /// depend on a camera having been set).
    frame_group: wgpu::BindGroup,
    group: wgpu::BindGroup,
    slots: wgpu::Buffer,
    slot_stride: u64,
    budget_texels: u64,
    pending: VecDeque<TileRange>,
    /// Dispatches chosen by the last `prepare`, recorded by `record`.
    scheduled: Vec<Dispatch>,
    /// Wall time of the initial build (creation), milliseconds.
    pub build_ms: f64,
}

impl GpuPyramid {
    /// Create the buffer and build the whole pyramid, in submissions of at
    /// most `budget_texels` level-0 texels each.
    pub fn new(
        shared: &Shared,
        level: &Level,
        voxel: VoxelSize,
        budget_texels: u64,
    ) -> anyhow::Result<Self> {
        let layout = Layout::new(level.width(), level.height(), voxel)?;
        let limits = shared.device.limits();
        let bytes = layout.bytes();
        let max = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if bytes > max {
            anyhow::bail!(
                "voxel grid ({voxel}) on a {}x{} map needs a {:.1} MiB occupancy buffer, but this adapter \
                 binds at most {:.1} MiB of storage buffer; use a coarser --voxel-size such as 4,8,2",
                level.width(),
                level.height(),
                bytes as f64 / MIB,
                max as f64 / MIB
            );
        }
        if budget_texels == 0 {
            anyhow::bail!("the voxel build budget must be at least one texel per frame");
        }
        let device = &shared.device;
        let BuildBindings {
            buffer,
            slots,
            slot_stride,
            group_layout,
            group,
        } = BuildBindings::new(
            device,
            "voxel occupancy",
            "voxel build",
            bytes,
            std::mem::size_of::<BuildParams>() as u64,
            MAX_SLOTS,
        );
        let frame_group = build_frame_group(shared, level)?;
        let module = shared.shader("voxel_build.wgsl")?;
        let pipeline_layout = shared.pipeline_layout("voxel build", &[&group_layout]);
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let mut pyramid = GpuPyramid {
            leaf: pipeline("cs_leaf"),
            reduce: pipeline("cs_reduce"),
            layout,
            buffer,
            frame_group,
            group,
            slots,
            slot_stride,
            budget_texels,
            pending: VecDeque::new(),
            scheduled: Vec::new(),
            build_ms: 0.0,
        };
        let start = Instant::now();
        pyramid.pending.push_back(pyramid.layout.all_tiles(0));
        while pyramid.is_pending() {
            pyramid.prepare(shared);
            let mut encoder = device.create_command_encoder(&Default::default());
            pyramid.record(&mut encoder, None);
            shared.queue.submit([encoder.finish()]);
            wait(device)?;
        }
        pyramid.build_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(pyramid)
    }

    /// Is level-0 work still queued?
    pub fn is_pending(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Queue the tile columns that edits inside `rects` touch.
    pub fn enqueue(&mut self, rects: &[DirtyRect]) -> anyhow::Result<()> {
        for rect in rects {
            self.pending.push_back(self.layout.dirty_tiles(rect)?);
        }
        Ok(())
    }

    fn texels_per_column(&self) -> u64 {
        let v = self.layout.voxel;
        u64::from(v.x * 8) * u64::from(v.y * 8)
    }

    /// Take this frame's share of the queue (within the texel budget) and
    /// write its dispatch parameters.
    pub fn prepare(&mut self, shared: &Shared) {
        self.scheduled.clear();
        let per_column = self.texels_per_column();
        let levels = self.layout.levels.len();
        if self.pending.len() > MAX_RANGES {
            let mut ranges: Vec<TileRange> = self.pending.drain(..).collect();
            coalesce(&mut ranges, MAX_RANGES);
            self.pending = ranges.into();
        }
        let mut budget = self.budget_texels;
        let mut leaves = Vec::new();
        // Each leaf piece brings one dispatch per level: stop while slots remain.
        while leaves.len() < MAX_SLOTS / levels {
            let Some(mut r) = self.pending.pop_front() else {
                break;
            };
            let cols = u64::from(r.x1 - r.x0 + 1);
            // Whole tile rows fit while they fit; a lone row wider than the budget is split.
            let rows_fit = budget / (cols * per_column);
            if rows_fit == 0 {
                if !leaves.is_empty() {
                    self.pending.push_front(r);
                    break;
                }
                let cols_fit = (budget / per_column).max(1) as u32;
                let mut head = r;
                head.y1 = head.y0;
                head.x1 = head.x0 + cols_fit - 1;
                if head.x1 < r.x1 {
                    // The rest of this row, then the remaining rows.
                    let mut rest_row = r;
                    rest_row.y1 = r.y0;
                    rest_row.x0 = head.x1 + 1;
                    if r.y1 > r.y0 {
                        let mut rest = r;
                        rest.y0 = r.y0 + 1;
                        self.pending.push_front(rest);
                    }
                    self.pending.push_front(rest_row);
                } else if r.y1 > r.y0 {
                    let mut rest = r;
                    rest.y0 = r.y0 + 1;
                    self.pending.push_front(rest);
                }
                leaves.push(head);
                break;
            }
            let rows = u64::from(r.y1 - r.y0 + 1);
            if rows > rows_fit {
                let mut rest = r;
                rest.y0 = r.y0 + rows_fit as u32;
                r.y1 = rest.y0 - 1;
                self.pending.push_front(rest);
            }
            budget -= u64::from(r.columns()) * per_column;
            leaves.push(r);
            if budget == 0 {
                break;
            }
        }
        // Leaves first, then each level's ancestors of them, finest first.
        for level in 0..levels {
            for leaf in &leaves {
                let mut r = *leaf;
                for _ in 0..level {
                    r = r.parent();
                }
                self.scheduled.push(Dispatch { level, range: r });
            }
        }
        let mut data = vec![0u8; self.slot_stride as usize * self.scheduled.len()];
        for (i, d) in self.scheduled.iter().enumerate() {
            let p = self.params(d);
            let at = i * self.slot_stride as usize;
            data[at..at + std::mem::size_of::<BuildParams>()]
                .copy_from_slice(bytemuck::bytes_of(&p));
        }
        if !data.is_empty() {
            shared.queue.write_buffer(&self.slots, 0, &data);
        }
    }

    fn params(&self, d: &Dispatch) -> BuildParams {
        let v = self.layout.voxel;
        let info = self.layout.levels[d.level];
        let child = if d.level > 0 {
            let c = self.layout.levels[d.level - 1];
            [c.tiles[0], c.tiles[1], c.tiles[2], c.offset]
        } else {
            [0; 4]
        };
        BuildParams {
            voxel: [v.x, v.y, v.z, 0],
            dims: [info.dims[0], info.dims[1], info.dims[2], info.offset],
            tiles: [info.tiles[0], info.tiles[1], info.tiles[2], 0],
            child,
            origin: [d.range.x0, d.range.y0, d.range.x1 - d.range.x0 + 1, 0],
        }
    }

    /// Record the dispatches `prepare` chose, in one compute pass (wgpu puts
    /// a barrier between dispatches that write and read the buffer).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if self.scheduled.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("voxel occupancy build"),
            timestamp_writes: timestamps,
        });
        pass.set_bind_group(0, &self.frame_group, &[]);
        for (i, d) in self.scheduled.iter().enumerate() {
            pass.set_bind_group(1, &self.group, &[(i as u64 * self.slot_stride) as u32]);
            let cols_x = d.range.x1 - d.range.x0 + 1;
            let cols_y = d.range.y1 - d.range.y0 + 1;
            if d.level == 0 {
                pass.set_pipeline(&self.leaf);
                pass.dispatch_workgroups(cols_x, cols_y, 1);
            } else {
                pass.set_pipeline(&self.reduce);
                let words = self.layout.levels[d.level].column_words();
                pass.dispatch_workgroups(words.div_ceil(64), cols_x * cols_y, 1);
            }
        }
    }

    /// Are dispatches scheduled for the coming `record`?
    pub fn has_work(&self) -> bool {
        !self.scheduled.is_empty()
    }

    /// Copy the whole buffer back (tests and checks).
    pub fn read_back(&self, shared: &Shared) -> anyhow::Result<Vec<u32>> {
        crate::gpu::read_words(
            &shared.device,
            &shared.queue,
            &self.buffer,
            "voxel readback",
        )
    }

    /// GPU bytes: the pyramid plus the dispatch parameter slots.
    pub fn gpu_bytes(&self) -> u64 {
        self.layout.bytes() + self.slot_stride * MAX_SLOTS as u64
    }
}

const MIB: f64 = 1024.0 * 1024.0;

/// Block until the GPU is idle (device errors surface through the
/// renderer's own error sink on its next wait).
fn wait(device: &wgpu::Device) -> anyhow::Result<()> {
    crate::gpu::wait_idle(device)
        .map_err(|e| anyhow::anyhow!("waiting for the voxel build failed: {e}"))?;
    Ok(())
}

/// A frame bind group whose globals carry the level's shape (all the
/// build's `decode_column` reads) over the shared terrain texture.
pub(crate) fn build_frame_group(shared: &Shared, level: &Level) -> anyhow::Result<wgpu::BindGroup> {
    // Any camera will do: only `Globals::level` is read by the build.
    let camera = Camera::new(glam::Vec3::new(0.0, 0.0, 300.0), 0.0, 0.0, 1, 1)?;
    let shadow = crate::shadow::ShadowFrame::fit(&camera, false);
    let globals = Globals::new(&camera, &LevelShape::of(level), &shadow);
    let buffer = shared.uniform_buffer("voxel build globals", bytemuck::bytes_of(&globals));
    Ok(crate::frame::bind_group(
        &shared.device,
        "voxel build frame",
        &shared.frame_layout,
        &[
            buffer.as_entire_binding(),
            shared.shading.as_entire_binding(),
            wgpu::BindingResource::TextureView(&shared.terrain.view),
            wgpu::BindingResource::TextureView(&shared.shadow_view),
        ],
    ))
}
