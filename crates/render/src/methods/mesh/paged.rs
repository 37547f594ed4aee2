//! `mesh` over paged terrain (issue 33): worlds of any size through a fixed
//! GPU budget.
//!
//! - **Texels** come from the page atlas of [`PagedTerrain`] (the same as
//!   `ray-exact`'s): `mesh.wgsl` composed `paged-read:` reads its vertex
//!   columns and colour window through the page table, writing no feedback
//!   (a vertex stage cannot). The CPU asks for the pages its chunk copies
//!   read instead ([`PagedTerrain::request`]): those of the chunk's samples
//!   and a margin of [`COLOUR_MARGIN`] texels around them for the colour
//!   window, merged with what the shadow pass's feedback asks for.
//! - **Fits** run on worker threads (`Fitter`), nearest chunk copy first,
//!   each reading only the pages its samples lie in; no frame waits on one.
//!   Without threads (a browser page: `PagedOptions::threads` 0) `prepare`
//!   fits queued chunks itself for `FIT_BUDGET_MS` (at least one chunk),
//!   the results handed back the same way.
//!   Fitted chunks go into an index pool of a fixed size (`PagedPool`),
//!   least recently drawn evicted first.
//! - **Budget**: the pool takes [`POOL_SHARE`] of `--gpu-budget` (after the
//!   draw records), the atlas's plan the rest; [`PagingStats`] reports the
//!   two together (`method_gpu_bytes` is the mesh's part).
//! - **No holes**: a chunk copy whose fit is not in the pool, or a page of
//!   whose is not resident, draws as its box (`mesh_paged_box.wgsl`): z = 0
//!   up to the highest top of the pages holding its samples, which holds its
//!   surface; every fragment of it counts as pending. The shadow map is the
//!   renderer's march (`shadow.wgsl`) composed `paged:` with feedback, its
//!   texels that read a missing page pending.
//! - **Equal to the whole world**: a chunk fitted from its pages is the
//!   whole-world fit's chunk, culled, LOD-picked and ordered the same way;
//!   once nothing is pending the image equals the whole-world `mesh` image
//!   bit for bit (tested on lavapipe and llvmpipe).
//! - **Edits** ([`Method::refresh_pages`]): the pages are refreshed, the
//!   pooled chunks whose samples lie in them are refitted at once, and fits
//!   in flight are dropped.
//!
//! [`PagingStats`]: crate::paged::PagingStats

use super::fitter::{Fitter, mesh_grid};
use super::paged_pool::PagedPool;
use super::{DRAW_BYTES, DRAWS_BINDING, Draw, Look, mesh_params, visible_copies};
use crate::frame::Shared;
use crate::methods::common::{begin_pass, forward_pipeline};
use crate::methods::contract::{Frame, Method, MethodSettings, RetainedBytes};
use crate::paged::{MethodShare, PAGE, PagedOptions, PagedTerrain};
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_mesh::{CHUNK, ChunkLayout, FitOptions};

/// The pyramid step the atlas is planned with: the mesh reads no pyramid
/// level, only the coarse level, so the smallest per-page pyramid.
pub const PYRAMID_STEP: u32 = 2;

/// Share of the budget (after the draw records) the index pool takes.
pub const POOL_SHARE: f64 = 0.5;

/// Draw records the budget reserves room for (more grow the buffer).
const DRAWS_RESERVED: u32 = 4096;

/// Texels around a chunk's samples whose pages must be resident before it
/// is drawn: the fragment stage's colour window (`colour_source` in
/// `mesh_colour.wgsl`: at most 3 texels back and 8 ahead across, and its
/// normal's neighbours) stays inside it, and so do the neighbours the vertex
/// stage's wall test reads (`wall_shift` in `mesh.wgsl`: one texel away).
pub const COLOUR_MARGIN: u32 = 16;

/// Vertices of a stand-in box: six faces of two triangles.
const BOX_VERTICES: u32 = 36;

/// Fitted chunks placed in the pool per frame, at most.
pub(super) const FITS_PER_FRAME: usize = 32;

/// Milliseconds a frame fits chunks on the calling thread where there are no
/// fit threads (a browser page): checked between chunks, so a frame takes at
/// least one queued chunk's fit.
pub(super) const FIT_BUDGET_MS: f64 = 4.0;

/// The smallest pool: room for a few dense chunks.
const MIN_POOL_BYTES: u64 = 1 << 20;

/// Bytes of the mesh's own uniforms (its parameters and the frame stamp).
const UNIFORM_BYTES: u64 = 32;

/// `paging`'s budget split: the options the atlas is planned with, and the
/// pool's bytes. A budget too small for both is refused with the smallest
/// that works.
pub fn split_budget(
    paging: &PagedOptions,
    source: &dyn crate::paged::PageSource,
) -> anyhow::Result<(PagedOptions, u64)> {
    let budget = paging.gpu_budget;
    // The mesh reads the map's own texels only: no level-of-detail pages.
    let paging = &PagedOptions {
        lod_pixels: 0.0,
        ..paging.clone()
    };
    let fixed = u64::from(DRAWS_RESERVED) * DRAW_BYTES + UNIFORM_BYTES;
    let atlas_smallest = PagedTerrain::smallest_budget(source, paging, PYRAMID_STEP);
    let smallest = fixed
        + ((atlas_smallest as f64 / (1.0 - POOL_SHARE)).ceil() as u64)
            .max((MIN_POOL_BYTES as f64 / POOL_SHARE).ceil() as u64);
    let rest = budget.saturating_sub(fixed);
    let pool = ((rest as f64 * POOL_SHARE) as u64) & !3;
    let atlas = rest - pool;
    if budget < smallest || atlas < atlas_smallest || pool < MIN_POOL_BYTES {
        anyhow::bail!(
            "a GPU budget of {budget} bytes cannot hold the paged mesh ({:.0} % for its index pool, the rest for the page atlas, coarse level, page table and feedback); the smallest budget that works is {smallest} bytes ({:.2} MiB)",
            POOL_SHARE * 100.0,
            smallest as f64 / 1048576.0
        );
    }
    let mut options = paging.clone();
    options.gpu_budget = atlas;
    Ok((options, pool))
}

/// The mesh over paged terrain.
pub struct PagedMesh {
    paged: Box<PagedTerrain>,
    budget: u64,
    pipeline: wgpu::RenderPipeline,
    box_pipeline: wgpu::RenderPipeline,
    shadow: Option<PagedShadow>,
    layout_mesh: wgpu::BindGroupLayout,
    layout_box: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    box_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    stamp_buffer: wgpu::Buffer,
    draws_buffer: wgpu::Buffer,
    draws_capacity: u32,
    pool: PagedPool,
    fitter: Fitter,
    layout: ChunkLayout,
    tolerance: f64,
    options: FitOptions,
    lod_pixels: f32,
    look: Look,
    stamp: u32,
    /// This frame's chunk copies drawn as meshes, front to back.
    draws: Vec<Draw>,
    /// This frame's stand-ins: copy and box top.
    boxes: Vec<(Draw, u8)>,
    /// Failed fits per chunk: after [`PagedOptions::read_tries`] the chunk
    /// stays a box (pending; its page's read error is the paging's to report).
    fit_failures: std::collections::HashMap<u32, u32>,
    fit_tries: u32,
}

/// The paged shadow-map pass.
struct PagedShadow {
    pipeline: wgpu::ComputePipeline,
    frame_group: wgpu::BindGroup,
    group: wgpu::BindGroup,
}

fn entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn bind(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

const READ: wgpu::BufferBindingType = wgpu::BufferBindingType::Storage { read_only: true };
const WRITE: wgpu::BufferBindingType = wgpu::BufferBindingType::Storage { read_only: false };
const UNIFORM: wgpu::BufferBindingType = wgpu::BufferBindingType::Uniform;

/// Build the paged mesh over `paged` (whose atlas is `shared`'s terrain
/// texture, planned with [`PYRAMID_STEP`] from [`split_budget`]'s options),
/// with an index pool of `pool_bytes` within `budget`; `threads` is the
/// paging's reader threads (fits get `fit_threads`).
pub fn build(
    shared: &Shared,
    paged: PagedTerrain,
    settings: &MethodSettings,
    budget: u64,
    pool_bytes: u64,
    threads: usize,
) -> anyhow::Result<Box<dyn Method>> {
    let tolerance = super::tolerance_of(settings)?;
    let lod_pixels = super::lod_pixels_of(settings)?;
    let options = super::options_of(settings);
    if settings.shadows && !shared.caps.compute {
        anyhow::bail!(
            "the paged mesh casts its shadow map with a compute pass, which this adapter lacks (try --no-shadows)"
        );
    }
    let device = &shared.device;
    let (w, h) = paged.source().size();
    let (chunks_x, chunks_y) = mesh_grid((w, h));
    let layout = ChunkLayout {
        size_x: CHUNK,
        size_y: CHUNK,
        chunks_x,
        chunks_y,
    };
    use wgpu::ShaderStages as S;
    let vf = S::VERTEX | S::FRAGMENT;
    let layout_mesh = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("paged mesh"),
        entries: &[
            entry(0, vf, UNIFORM),
            entry(1, vf, READ),
            entry(DRAWS_BINDING, S::VERTEX, READ),
            entry(9, vf, READ),
            entry(11, vf, READ),
        ],
    });
    let layout_box = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("paged mesh boxes"),
        entries: &[
            entry(DRAWS_BINDING, S::VERTEX, READ),
            entry(10, S::FRAGMENT, WRITE),
        ],
    });
    let grid = mesh_params(&layout, Look::of(settings));
    let params = shared.uniform_buffer("paged mesh params", bytemuck::cast_slice(&grid));
    let stamp_buffer = shared.uniform_buffer("paged mesh stamp", &[0u8; 16]);
    let pipeline = forward_pipeline(
        shared,
        "mesh",
        &format!("{}mesh_paged.wgsl", crate::shaders::PAGED_READ),
        &layout_mesh,
        ("vs_mesh", "fs_mesh"),
    )?;
    let box_pipeline = forward_pipeline(
        shared,
        "mesh boxes",
        "mesh_paged_box.wgsl",
        &layout_box,
        ("vs_mesh_box", "fs_mesh_box"),
    )?;
    let shadow = if shared.caps.compute {
        Some(paged_shadow(shared, &paged, &stamp_buffer)?)
    } else {
        None
    };
    let source = paged.source().clone();
    let fit_tries = paged.options().read_tries.max(1);
    let draws_capacity = DRAWS_RESERVED;
    let draws_buffer = draws_buffer(shared, draws_capacity);
    let paged = Box::new(paged);
    let (group, box_group) = groups(
        shared,
        (&layout_mesh, &layout_box),
        &params,
        &draws_buffer,
        &paged,
    );
    let mut mesh = PagedMesh {
        pool: PagedPool::new(device, pool_bytes),
        fitter: Fitter::new(Some(source), tolerance, options, fit_threads(threads)),
        paged,
        budget,
        pipeline,
        box_pipeline,
        shadow,
        layout_mesh,
        layout_box,
        group,
        box_group,
        params,
        stamp_buffer,
        draws_buffer,
        draws_capacity,
        layout,
        tolerance,
        options,
        lod_pixels,
        look: Look::of(settings),
        stamp: 0,
        draws: Vec::new(),
        boxes: Vec::new(),
        fit_failures: Default::default(),
        fit_tries,
    };
    mesh.report_share();
    Ok(Box::new(mesh))
}

/// Fit threads beside `readers` page readers: none where there are none
/// (fits run between frames), else half the cores, at least `readers`, at
/// most [`MAX_FIT_THREADS`] (a fit is far more work than a page read).
fn fit_threads(readers: usize) -> usize {
    if readers == 0 {
        return 0;
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    (cores / 2).max(readers).min(MAX_FIT_THREADS)
}

/// Fit threads for an edit's refits of the whole-world mesh: every core but
/// the render thread's (at least one, at most [`MAX_FIT_THREADS`]); none in
/// a browser page (refits run in `prepare`, within [`FIT_BUDGET_MS`]).
pub(super) fn refit_threads() -> usize {
    if cfg!(target_arch = "wasm32") {
        return 0;
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    cores.saturating_sub(1).clamp(1, MAX_FIT_THREADS)
}

/// Most fit threads.
const MAX_FIT_THREADS: usize = 8;

fn draws_buffer(shared: &Shared, capacity: u32) -> wgpu::Buffer {
    shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("paged mesh draws"),
        size: u64::from(capacity.max(1)) * DRAW_BYTES,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn groups(
    shared: &Shared,
    (layout_mesh, layout_box): (&wgpu::BindGroupLayout, &wgpu::BindGroupLayout),
    params: &wgpu::Buffer,
    draws: &wgpu::Buffer,
    paged: &PagedTerrain,
) -> (wgpu::BindGroup, wgpu::BindGroup) {
    let device = &shared.device;
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("paged mesh"),
        layout: layout_mesh,
        entries: &[
            bind(0, params),
            bind(1, &paged.levels),
            bind(DRAWS_BINDING, draws),
            bind(9, &paged.table),
            bind(11, &paged.params),
        ],
    });
    let box_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("paged mesh boxes"),
        layout: layout_box,
        entries: &[bind(DRAWS_BINDING, draws), bind(10, &paged.feedback)],
    });
    (group, box_group)
}

/// The renderer's shadow march over pages, with feedback.
fn paged_shadow(
    shared: &Shared,
    paged: &PagedTerrain,
    stamp: &wgpu::Buffer,
) -> anyhow::Result<PagedShadow> {
    let device = &shared.device;
    let (frame_layout, frame_group) =
        crate::shadow::frame_without_shadow_map(shared, "paged mesh shadow frame");
    let c = wgpu::ShaderStages::COMPUTE;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("paged mesh shadow"),
        entries: &[
            crate::frame::storage_texture_entry(0, wgpu::TextureFormat::R32Float),
            entry(1, c, READ),
            entry(9, c, READ),
            entry(10, c, WRITE),
            entry(11, c, READ),
            entry(12, c, UNIFORM),
        ],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("paged mesh shadow"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&shared.shadow_view),
            },
            bind(1, &paged.levels),
            bind(9, &paged.table),
            bind(10, &paged.feedback),
            bind(11, &paged.params),
            bind(12, stamp),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("paged mesh shadow"),
        bind_group_layouts: &[Some(&frame_layout), Some(&layout)],
        immediate_size: 0,
    });
    let module = shared.shader(&format!("{}mesh_paged_shadow.wgsl", crate::shaders::PAGED))?;
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("paged mesh shadow"),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some("cs_shadow_paged"),
        compilation_options: Default::default(),
        cache: None,
    });
    Ok(PagedShadow {
        pipeline,
        frame_group,
        group,
    })
}

/// Append the pages (row-major chunk ids of the page grid `grid`) covering
/// texels `[x0, x1] x [y0, y1]` (unwrapped, inclusive), each once.
fn pages_over(grid: (u32, u32), (x0, y0, x1, y1): (i64, i64, i64, i64), out: &mut Vec<u32>) {
    let page = i64::from(PAGE);
    let (gx, gy) = (i64::from(grid.0), i64::from(grid.1));
    let (px0, px1) = (x0.div_euclid(page), x1.div_euclid(page));
    let (py0, py1) = (y0.div_euclid(page), y1.div_euclid(page));
    for py in py0..=py1.min(py0 + gy - 1) {
        for px in px0..=px1.min(px0 + gx - 1) {
            out.push((py.rem_euclid(gy) * gx + px.rem_euclid(gx)) as u32);
        }
    }
}

impl PagedMesh {
    /// The mesh chunk's sample rectangle (chunk `chunk`, inclusive, the
    /// pair neighbour of its last column too), grown by `margin`.
    fn rect(&self, chunk: u32, margin: u32) -> (i64, i64, i64, i64) {
        let (cx, cy) = self.layout.coords(chunk as usize);
        let (x0, y0) = (i64::from(cx * CHUNK), i64::from(cy * CHUNK));
        let m = i64::from(margin);
        let side = i64::from(CHUNK);
        (x0 - m, y0 - m, x0 + side + 1 + m, y0 + side + m)
    }

    /// The highest top of the pages holding chunk `chunk`'s samples.
    fn box_top(&self, chunk: u32, scratch: &mut Vec<u32>) -> u8 {
        scratch.clear();
        pages_over(self.paged.grid(), self.rect(chunk, 0), scratch);
        scratch
            .iter()
            .map(|&p| self.paged.chunk_top(p))
            .max()
            .unwrap_or(u8::MAX)
    }

    /// Visible chunk copies for `camera`, front to back (as the whole
    /// mesh's, with a chunk not in the pool boxed from 0 to its pages' top).
    fn cull(&self, camera: &Camera) -> Vec<Draw> {
        let mut copies = Vec::new();
        let mut scratch = Vec::new();
        visible_copies(
            &self.layout,
            camera,
            (self.tolerance, self.lod_pixels),
            |chunk| match self.pool.get(chunk) {
                Some(entry) => entry.z,
                None => (0, self.box_top(chunk, &mut scratch)),
            },
            &mut copies,
        );
        copies
    }

    /// Place finished fits in the pool.
    fn take_fits(&mut self, queue: &wgpu::Queue) {
        for (chunk, _, fit) in self.fitter.poll(FITS_PER_FRAME, FIT_BUDGET_MS) {
            match fit {
                Ok((mesh, z)) => {
                    self.pool.insert(queue, chunk, &mesh, z, self.stamp);
                }
                Err(_) => *self.fit_failures.entry(chunk).or_insert(0) += 1,
            }
        }
    }

    /// Tell the paged terrain the mesh's bytes and fits in flight.
    fn report_share(&mut self) {
        let share = MethodShare {
            budget: self.budget,
            gpu_bytes: self.method_gpu_bytes(),
            in_flight: self.fitter.in_flight() as u32,
            evictions: self.pool.evictions,
        };
        self.paged.set_method_share(share);
    }

    fn method_gpu_bytes(&self) -> u64 {
        self.pool.gpu_bytes() + self.draws_buffer.size() + UNIFORM_BYTES
    }
}

impl Method for PagedMesh {
    fn name(&self) -> &'static str {
        "mesh"
    }

    fn apply_edit(&mut self, _: &Shared, _: &Level, _: &[DirtyRect]) -> anyhow::Result<()> {
        anyhow::bail!(
            "mesh draws paged terrain: edits reach it through its store (Renderer::refresh_pages)"
        )
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        super::settings_in_place(
            shared,
            settings,
            (self.tolerance, self.options),
            (&mut self.lod_pixels, &mut self.look),
            (&self.layout, &self.params),
        )
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        self.stamp = self.stamp.wrapping_add(1).max(1);
        let stamp = self.stamp;
        let copies = self.cull(camera);
        for c in &copies {
            self.pool.touch(c.chunk, stamp);
        }
        self.take_fits(&shared.queue);
        // The pages the copies read, nearest copy first.
        let (mut pages, mut scratch) = (Vec::new(), Vec::new());
        let mut seen = std::collections::HashSet::new();
        for c in &copies {
            scratch.clear();
            pages_over(
                self.paged.grid(),
                self.rect(c.chunk, COLOUR_MARGIN),
                &mut scratch,
            );
            pages.extend(scratch.iter().filter(|p| seen.insert(**p)));
        }
        self.paged.request(&pages, stamp);
        self.paged.begin_frame(shared, camera, stamp)?;
        shared.queue.write_buffer(
            &self.stamp_buffer,
            0,
            bytemuck::cast_slice(&[0, 0, stamp, 0]),
        );
        // Drawable: fitted, and every page it reads resident.
        self.draws.clear();
        self.boxes.clear();
        let mut wanted = Vec::new();
        seen.clear();
        for c in copies {
            let fitted = self.pool.get(c.chunk).is_some();
            scratch.clear();
            pages_over(
                self.paged.grid(),
                self.rect(c.chunk, COLOUR_MARGIN),
                &mut scratch,
            );
            if fitted && scratch.iter().all(|&p| self.paged.is_resident(p)) {
                self.draws.push(c);
            } else {
                let given_up = self
                    .fit_failures
                    .get(&c.chunk)
                    .is_some_and(|&n| n >= self.fit_tries);
                if !fitted && !given_up && seen.insert(c.chunk) {
                    wanted.push(c.chunk);
                }
                let top = self.box_top(c.chunk, &mut scratch);
                self.boxes.push((c, top));
            }
        }
        self.fitter.want(&wanted);
        let n = (self.draws.len() + self.boxes.len()) as u32;
        if n > self.draws_capacity {
            self.draws_capacity = n.next_power_of_two();
            self.draws_buffer = draws_buffer(shared, self.draws_capacity);
            (self.group, self.box_group) = groups(
                shared,
                (&self.layout_mesh, &self.layout_box),
                &self.params,
                &self.draws_buffer,
                &self.paged,
            );
        }
        if n > 0 {
            let side = CHUNK as i32;
            let records: Vec<[i32; 4]> = self
                .draws
                .iter()
                .map(|d| [d.origin[0], d.origin[1], 0, 0])
                .chain(
                    self.boxes
                        .iter()
                        .map(|(d, top)| [d.origin[0], d.origin[1], i32::from(*top), side]),
                )
                .collect();
            shared
                .queue
                .write_buffer(&self.draws_buffer, 0, bytemuck::cast_slice(&records));
        }
        self.report_share();
        Ok(())
    }

    fn record_shadow_map(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        let Some(shadow) = &self.shadow else {
            return false;
        };
        shared.shadow_map_written();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("paged mesh shadow"),
            timestamp_writes: frame.timer.compute("shadow"),
        });
        pass.set_pipeline(&shadow.pipeline);
        pass.set_bind_group(0, &shadow.frame_group, &[]);
        pass.set_bind_group(1, &shadow.group, &[]);
        let side = crate::frame::SHADOW_SIZE;
        pass.dispatch_workgroups(side.div_ceil(8), side.div_ceil(8), 1);
        true
    }

    fn shadow_map_is_partial(&self) -> bool {
        // Cast over whatever pages were resident: never another frame's.
        true
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        {
            let mut pass = begin_pass(shared, frame, encoder, "mesh");
            pass.set_bind_group(0, &shared.frame_group, &[]);
            if !self.draws.is_empty() {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(1, &self.group, &[]);
                pass.set_index_buffer(self.pool.buffer.slice(..), wgpu::IndexFormat::Uint16);
                for (k, d) in self.draws.iter().enumerate() {
                    let Some(entry) = self.pool.get(d.chunk) else {
                        continue;
                    };
                    let k = k as u32;
                    for &(s, e) in &entry.lods[usize::from(d.lod)] {
                        if e > s {
                            pass.draw_indexed(entry.start + s..entry.start + e, 0, k..k + 1);
                        }
                    }
                }
            }
            if !self.boxes.is_empty() {
                let first = self.draws.len() as u32;
                pass.set_pipeline(&self.box_pipeline);
                pass.set_bind_group(1, &self.box_group, &[]);
                pass.draw(0..BOX_VERTICES, first..first + self.boxes.len() as u32);
            }
        }
        self.paged.record_feedback(encoder);
    }

    fn frame_done(&mut self, shared: &Shared) -> anyhow::Result<()> {
        self.paged.read_feedback(shared)?;
        self.report_share();
        Ok(())
    }

    fn paged_terrain(&mut self) -> Option<&mut PagedTerrain> {
        Some(&mut self.paged)
    }

    fn refresh_pages(&mut self, shared: &Shared, chunks: &[u32]) -> anyhow::Result<()> {
        self.paged.refresh(shared, chunks)?;
        // Fits in flight may have read the old samples.
        self.fitter.invalidate();
        self.fit_failures.clear();
        // The pooled mesh chunks whose samples lie in a refreshed page.
        let mut touched = Vec::new();
        let (gx, gy) = (self.layout.chunks_x as i64, self.layout.chunks_y as i64);
        let grid = self.paged.grid();
        for &page in chunks {
            let (px, py) = (i64::from(page % grid.0), i64::from(page / grid.0));
            for my in 2 * py - 1..=2 * py + 1 {
                for mx in 2 * px - 1..=2 * px + 1 {
                    let c = (my.rem_euclid(gy) * gx + mx.rem_euclid(gx)) as u32;
                    if self.pool.get(c).is_some() && !touched.contains(&c) {
                        touched.push(c);
                    }
                }
            }
        }
        for c in touched {
            match self.fitter.fit_now(c) {
                Ok((mesh, z)) => {
                    if !self.pool.insert(&shared.queue, c, &mesh, z, self.stamp) {
                        // No room now: it draws as a box until refitted.
                        self.pool.remove(c);
                    }
                }
                Err(e) => {
                    self.pool.remove(c);
                    anyhow::bail!("refitting mesh chunk {c} after an edit: {e}");
                }
            }
        }
        self.report_share();
        Ok(())
    }

    fn retained_bytes(&self) -> RetainedBytes {
        let plan = self.paged.plan();
        RetainedBytes {
            gpu: plan.total() - plan.atlas_bytes + self.method_gpu_bytes(),
            cpu: ((self.draws.capacity() + self.boxes.capacity()) * std::mem::size_of::<Draw>())
                as u64,
        }
    }
}
