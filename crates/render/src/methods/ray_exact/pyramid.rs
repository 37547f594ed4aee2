//! The max-height pyramid on the GPU (`ray_exact_build.wgsl`): one storage
//! buffer laid out by `strata_maxmip::Layout`, filled by one compute dispatch
//! per level (level 1 from the terrain texture, each coarser one from the
//! level below), the twin of `strata_maxmip::Pyramid` bit for bit. The same
//! buffer holds, after the maxima, the cave pyramid (the twin of
//! `strata_maxmip::CavePyramid`: each tile's highest floor top and lowest
//! slab bottom, 16 bits a tile), built by the same dispatches. With the
//! texel plane asked for (`ExactOptions::texel_walk`), the buffer ends
//! with it (`strata_maxmip::TexelTops`: a byte per texel, built by the same
//! pipeline as a level 0).
//!
//! Creation builds every level in one submission. An edit queues its dirty
//! rectangles; the next frame's first pass rebuilds exactly the tiles over
//! them and their ancestors (one dispatch per level and rectangle), before
//! the shadow map and the march read the pyramid, so the first post-edit
//! frame equals a fresh build.

use super::super::build_bindings::BuildBindings;
use super::super::coalesce::coalesce;
use crate::frame::Shared;
use crate::timing::PassTimer;
use strata_level::{DirtyRect, Level};
use strata_maxmip::{Layout, LevelInfo, TexelTops};

/// Dispatches one submission can hold (uniform slots).
const MAX_SLOTS: usize = 256;
/// Most rectangles a frame's update dispatches for (each brings one
/// dispatch per level): a game's frame of 64 small edits as 64 x 8
/// dispatches cost 1.8 ms on the H100, their few bounding boxes' texels far
/// less (`compare --gameplay`).
const MAX_RECTS: usize = 4;

/// Twin of `BuildParams` in `ray_exact_build.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BuildParams {
    level: [u32; 4],
    child: [u32; 4],
    rect: [u32; 4],
}

pub struct GpuMaxMip {
    pub layout: Layout,
    pub buffer: wgpu::Buffer,
    /// Whether the buffer holds the cave pyramid after the maxima.
    caves: bool,
    /// The texel plane's first byte, when the buffer ends with one.
    texels: Option<u32>,
    pipeline: wgpu::ComputePipeline,
    frame_group: wgpu::BindGroup,
    group: wgpu::BindGroup,
    slots: wgpu::Buffer,
    slot_stride: u64,
    pending: Vec<DirtyRect>,
    /// Dispatches chosen by the last `prepare`: params and workgroup counts.
    scheduled: Vec<[u32; 2]>,
    /// GPU time of the full build at creation (timestamps), milliseconds.
    pub build_gpu_ms: Option<f64>,
}

impl GpuMaxMip {
    /// Create the buffer and build levels `step, 2 step, ..`: the levels a
    /// traversal visiting every `step`-th one reads (`EXACT_LOG_RATIO`), and
    /// no others; with `caves`, the cave pyramid after them (`ray-exact`'s
    /// march reads it; the fragment methods' beams do not).
    pub fn new(shared: &Shared, level: &Level, step: u32, caves: bool) -> anyhow::Result<Self> {
        Self::with_texels(shared, level, step, caves, false)
    }

    /// [`GpuMaxMip::new`], and with `texels` the texel plane after the rest
    /// where the map has one ([`TexelTops::fits`]) and the adapter binds
    /// it; [`GpuMaxMip::texel_plane`] says whether it did.
    pub fn with_texels(
        shared: &Shared,
        level: &Level,
        step: u32,
        caves: bool,
        texels: bool,
    ) -> anyhow::Result<Self> {
        let layout = Layout::with_step(level.width(), level.height(), step);
        let device = &shared.device;
        let limits = device.limits();
        let most = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        // The maxima, then the cave bounds (two bytes a tile); at least one
        // word, so that a map without tiles still binds a buffer.
        let planes = if caves { 3 } else { 1 };
        let bytes = (planes * u64::from(layout.bytes)).max(4);
        // The texel plane after them, on a 16-byte boundary; left out (the
        // march then walks the texels from the terrain) where it does not
        // fit the binding.
        let plane_at = bytes.next_multiple_of(16);
        let plane_end = plane_at + u64::from(level.width()) * u64::from(level.height());
        let texels = (texels
            && TexelTops::fits(level.width(), level.height())
            && plane_end <= most
            && plane_end <= u64::from(u32::MAX))
        .then_some(plane_at as u32);
        let bytes = if texels.is_some() { plane_end } else { bytes };
        if bytes > most {
            anyhow::bail!(
                "the max pyramid of a {}x{} map needs {bytes} bytes of storage buffer, more than this adapter binds",
                level.width(),
                level.height()
            );
        }
        let BuildBindings {
            buffer,
            slots,
            slot_stride,
            group_layout,
            group,
        } = BuildBindings::new(
            device,
            "ray-exact pyramid",
            "ray-exact build",
            bytes,
            std::mem::size_of::<BuildParams>() as u64,
            MAX_SLOTS,
        );
        let frame_group = super::super::voxel::pyramid::build_frame_group(shared, level)?;
        let module = shared.shader("ray_exact_build.wgsl")?;
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("ray-exact build"),
            layout: Some(&shared.pipeline_layout("ray-exact build", &[&group_layout])),
            module: &module,
            entry_point: Some("cs_maxmip"),
            compilation_options: Default::default(),
            cache: None,
        });
        let mut pyramid = GpuMaxMip {
            pending: vec![whole(level)],
            caves,
            texels,
            layout,
            buffer,
            pipeline,
            frame_group,
            group,
            slots,
            slot_stride,
            scheduled: Vec::new(),
            build_gpu_ms: None,
        };
        let timer = PassTimer::new(device, &shared.queue, shared.caps.timestamps);
        timer.reset();
        pyramid.prepare(shared);
        let mut encoder = device.create_command_encoder(&Default::default());
        pyramid.record(&mut encoder, timer.compute("ray-exact pyramid build"));
        timer.resolve(&mut encoder);
        shared.queue.submit([encoder.finish()]);
        crate::gpu::wait_idle(device)
            .map_err(|e| anyhow::anyhow!("waiting for the pyramid build failed: {e}"))?;
        pyramid.build_gpu_ms = timer.read_blocking(device)?;
        Ok(pyramid)
    }

    /// Queue the rectangles an edit changed (applied by the next frame).
    pub fn enqueue(&mut self, rects: &[DirtyRect]) {
        self.pending.extend_from_slice(rects);
    }

    /// Turn the queue into this frame's dispatches and write their parameters.
    pub fn prepare(&mut self, shared: &Shared) {
        self.scheduled.clear();
        if self.pending.is_empty() {
            return;
        }
        let levels = self.layout.levels.len().max(1) + usize::from(self.texels.is_some());
        // Many small rectangles (a game's frame of track stamps): merge
        // neighbours into their bounding boxes (exact: a larger rectangle
        // recomputes more tiles), never the whole map's 33 M texels.
        coalesce(&mut self.pending, MAX_RECTS.min(MAX_SLOTS / levels).max(1));
        let mut planes = Vec::new();
        if let Some(offset) = self.texels {
            planes.extend(
                self.pending
                    .iter()
                    .map(|r| texel_params(&self.layout, offset, r)),
            );
        }
        for info in &self.layout.levels {
            for rect in &self.pending {
                planes.push(params(&self.layout, info, rect, self.caves));
            }
        }
        let mut data = Vec::new();
        for p in planes {
            self.scheduled.push([p.rect[2].div_ceil(64), p.rect[3]]);
            let at = data.len();
            data.resize(at + self.slot_stride as usize, 0);
            data[at..at + std::mem::size_of::<BuildParams>()]
                .copy_from_slice(bytemuck::bytes_of(&p));
        }
        self.pending.clear();
        if !data.is_empty() {
            shared.queue.write_buffer(&self.slots, 0, &data);
        }
    }

    /// Are dispatches scheduled for the coming `record`?
    pub fn has_work(&self) -> bool {
        !self.scheduled.is_empty()
    }

    /// Record the scheduled dispatches in one compute pass, finest level
    /// first (wgpu orders dispatches that write and read the buffer).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        if self.scheduled.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("ray-exact pyramid"),
            timestamp_writes: timestamps,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.frame_group, &[]);
        for (i, [x, y]) in self.scheduled.iter().enumerate() {
            pass.set_bind_group(1, &self.group, &[(i as u64 * self.slot_stride) as u32]);
            pass.dispatch_workgroups(*x, *y, 1);
        }
    }

    /// Copy the maxima back (tests).
    pub fn read_back(&self, shared: &Shared) -> anyhow::Result<Vec<u32>> {
        let words = self.read_all(shared)?;
        Ok(words[..self.layout.bytes as usize / 4].to_vec())
    }

    /// Copy the cave bounds back (tests): `strata_maxmip::CavePyramid::words`.
    pub fn read_back_caves(&self, shared: &Shared) -> anyhow::Result<Vec<u32>> {
        anyhow::ensure!(self.caves, "this pyramid keeps no cave bounds");
        let words = self.read_all(shared)?;
        let first = self.cave_offset() as usize / 4;
        Ok(words[first..first + self.layout.bytes as usize / 2].to_vec())
    }

    fn read_all(&self, shared: &Shared) -> anyhow::Result<Vec<u32>> {
        crate::gpu::read_words(
            &shared.device,
            &shared.queue,
            &self.buffer,
            "ray-exact readback",
        )
    }

    /// Copy the texel plane back (tests): `strata_maxmip::TexelTops::words`.
    pub fn read_back_texels(&self, shared: &Shared) -> anyhow::Result<Vec<u32>> {
        let first = self
            .texels
            .ok_or_else(|| anyhow::anyhow!("this pyramid keeps no texel plane"))?;
        let words = self.read_all(shared)?;
        let (w, h) = (self.layout.map_width, self.layout.map_height);
        let first = first as usize / 4;
        Ok(words[first..first + (w * h) as usize / 4].to_vec())
    }

    /// The texel plane's first byte in the buffer, if it holds one.
    pub fn texel_plane(&self) -> Option<u32> {
        self.texels
    }

    /// The cave region's first byte in the buffer (after the maxima; the
    /// march reads it from `ExactParams::config[3]`).
    fn cave_offset(&self) -> u32 {
        self.layout.bytes
    }

    /// GPU bytes: the pyramid plus the dispatch parameter slots.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffer.size() + self.slots.size()
    }
}

fn whole(level: &Level) -> DirtyRect {
    DirtyRect {
        x: 0,
        y: 0,
        width: level.width(),
        height: level.height(),
    }
}

/// The dispatch over the texel plane's words (at byte `offset`) holding
/// the texels of `rect`: whole words of each of its rows.
fn texel_params(layout: &Layout, offset: u32, rect: &DirtyRect) -> BuildParams {
    let (x0, x1) = (rect.x / 4, (rect.x + rect.width.max(1) - 1) / 4);
    BuildParams {
        level: [
            offset,
            layout.map_width.trailing_zeros(),
            layout.map_height,
            0,
        ],
        // No child level and no cave bounds (`NO_CAVES`).
        child: [0, 0, layout.step, u32::MAX],
        rect: [x0, rect.y, x1 - x0 + 1, rect.height],
    }
}

/// The dispatch over the words of level `info` holding tiles over `rect`.
fn params(layout: &Layout, info: &LevelInfo, rect: &DirtyRect, caves: bool) -> BuildParams {
    let (k, s) = (info.log2_tile, layout.step);
    // The cave region's first byte, or none (`NO_CAVES` in the shader).
    let cave = if caves { layout.bytes } else { u32::MAX };
    let child = if k > s {
        let c = layout.level(k - s);
        [c.offset, c.width.trailing_zeros(), s, cave]
    } else {
        [0, 0, s, cave]
    };
    let r = layout.dirty_tiles(k, rect);
    let rect = if info.width >= 4 {
        // Word columns holding tiles x0..=x1, rows y0..=y1.
        [r.x0 / 4, r.y0, r.x1 / 4 - r.x0 / 4 + 1, r.y1 - r.y0 + 1]
    } else {
        // A level narrower than a word: all of it, as one row of words.
        [0, 0, info.bytes().div_ceil(4), 1]
    };
    BuildParams {
        level: [info.offset, info.width.trailing_zeros(), info.height, k],
        child,
        rect,
    }
}
