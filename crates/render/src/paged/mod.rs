//! Paged terrain: worlds of any size through a fixed GPU budget (issue 33).
//!
//! The world is cut into pages of 256x256 texels (a store's chunks). A few
//! are resident at a time in an atlas, which stands in for the whole-map
//! terrain texture of the shared frame, so every shader that includes
//! `frame.wgsl` still binds it. Shaders composed with the `paged:` prefix
//! (`shaders::compose`) read texel pairs and the exact march's pyramid through
//! a page table instead of the whole map:
//!
//! - **always resident**: the coarse level (each chunk's highest top, from a
//!   store's summaries without reading a chunk), the page table, and the
//!   feedback buffer; their size follows the number of chunks (9 bytes per
//!   chunk: 0.6 MB for a 65536² world);
//! - **per page**: the texels (128 KiB in the atlas) and the page's own
//!   pyramid below the 256-texel tile;
//! - **no holes**: a ray that goes down into a chunk that is not resident
//!   meets the chunk's coarse box (every column at its highest top), so it
//!   stops there rather than showing sky through terrain it has not seen; the
//!   pixel counts as *pending*, and the chunk is asked for;
//! - **feedback**: each frame records the chunks its rays asked for (camera
//!   rays and the shadow map's alike) and the frame stamp of every slot it
//!   read; [`PagedTerrain`] reads that back after the frame, has the
//!   [`Streamer`] read the asked-for pages (nearest the eye first, with the
//!   view's footprint prefetched), and uploads at most
//!   [`PagedOptions::upload_pages`] a frame into free slots or the least
//!   recently read ones (never a slot the last read-back frame used);
//! - **budget**: [`BudgetPlan`] turns `--gpu-budget` into slots, counting every
//!   byte above (the atlas, the levels, the table, the feedback and its
//!   read-back copy, the parameters). The frame's own targets and shadow map
//!   are the renderer's, the same for every world, and reported apart.
//!
//! - **level of detail**: a source may also have coarser copies of the map
//!   (`strata_level::lod`: level k holds the highest-topped texel pair of
//!   each 2^k block; a store keeps them as `lod/{k}` arrays). Their pages
//!   have ids after the chunks' ([`PageIds`]) and share the atlas. Where a
//!   camera ray's footprint has grown to 2^k texels ([`PagedOptions::lod_pixels`]
//!   pixels of it), the exact march reads level k: a tile of 2^k texels is
//!   one column, tile maxima come from level k's page pyramids; shadow rays
//!   take the level of a shadow-map texel. A horizon view then reads a few
//!   pages per octave of distance instead of every chunk out to the far
//!   plane. Its error against the CPU reference is measured
//!   (`tests/paged.rs`, `strata fly`), not assumed.
//!
//! With the camera still, pending pixels fall to zero within a few frames and
//! the image then equals the whole-world render bit for bit where no ray's
//! footprint reaches 2 texels (the paper's far plane of 600 never does: the
//! focal length is 512 pixels): the march and shading are the same WGSL over
//! the same bytes (tested on lavapipe).

mod footprint;
pub mod pages;
pub mod remote;
pub mod residency;
pub mod source;
pub mod streamer;

pub use pages::PageIds;
pub use remote::RemoteChunks;
pub use residency::{BudgetPlan, Residency};
#[cfg(not(target_arch = "wasm32"))]
pub use source::StorePages;
pub use source::{
    AsyncPages, LevelPages, PAGE, PageData, PageRef, PageSource, Planes, page_pyramid_layout,
};
pub use streamer::Streamer;

use crate::frame::Shared;
use crate::terrain::{TerrainLayout, TerrainTexture};
use residency::{FEEDBACK_HEADER, MAX_REQUESTS};
use serde::Serialize;
use std::collections::HashMap;
use std::sync::Arc;
use strata_camera::Camera;

/// The methods that draw paged terrain ([`crate::Renderer::new_paged`]).
pub const PAGED_METHODS: &[&str] = &["ray-exact", "ray-exact-fragment", "mesh"];

/// How a paged renderer spends its GPU memory and upload bandwidth.
#[derive(Clone, Debug)]
pub struct PagedOptions {
    /// Bytes the paged terrain may keep on the GPU (everything that grows
    /// with the world or the pages; see [`BudgetPlan`]).
    pub gpu_budget: u64,
    /// Most pages uploaded per frame.
    pub upload_pages: u32,
    /// Reader threads (0: read on the render thread, between frames).
    pub threads: usize,
    /// Tries before a chunk that fails to read is given up (its pixels stay
    /// pending; the error is reported once).
    pub read_tries: u32,
    /// Level of detail: a ray takes coarser copies of the map
    /// (`strata_level::lod`) where its footprint is 2^k texels of at most
    /// this many pixels (1: a coarse texel is never wider than a pixel);
    /// 0 draws every ray from the map's texels. A far plane of 600 (the
    /// paper's) never reaches a footprint of 2 texels at the fixed focal
    /// length of 512 pixels, so the protocol's images are unchanged.
    pub lod_pixels: f32,
}

impl Default for PagedOptions {
    fn default() -> Self {
        PagedOptions {
            gpu_budget: DEFAULT_GPU_BUDGET,
            upload_pages: 64,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get().clamp(1, 4)),
            read_tries: 3,
            lod_pixels: 1.0,
        }
    }
}

/// `--gpu-budget`'s default natively: 256 MiB.
pub const DEFAULT_GPU_BUDGET: u64 = 256 << 20;

/// Twin of `PagedParams` in `paged.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PagedParams {
    grid: [u32; 4],
    atlas: [u32; 4],
    offsets: [[u32; 4]; 2],
    lod: [f32; 4],
    lod_pages: [[u32; 4]; 3],
}

/// What the paging did, for reports and the viewer's overlay.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PagingStats {
    /// The budget, bytes.
    pub gpu_budget: u64,
    /// Bytes the paged terrain keeps on the GPU (≤ the budget).
    pub gpu_bytes: u64,
    /// Slots in the atlas.
    pub slots: u32,
    /// Pages resident now.
    pub resident_pages: u32,
    /// Bytes of the resident pages (texels and pyramids).
    pub resident_bytes: u64,
    /// Pages uploaded before the last frame.
    pub uploaded_pages: u32,
    /// Bytes uploaded before the last frame (texels, pyramids, table entries).
    pub uploaded_bytes: u64,
    /// Pixels of the last read-back frame drawn from a missing page (the
    /// paged mesh: fragments of its stand-in boxes, an upper bound).
    pub pending_pixels: u32,
    /// Shadow-map texels of that frame cast through a missing page (the
    /// pixels that sample them are not counted above).
    pub pending_shadow_texels: u32,
    /// Chunks that frame asked for.
    pub requests: u32,
    /// Chunks queued or being read.
    pub in_flight: u32,
    /// Pages placed since creation.
    pub total_uploads: u64,
    /// Pages evicted since creation.
    pub total_evictions: u64,
    /// Chunks that failed to read (after retries), and the first error.
    pub read_errors: u32,
    /// The first read error, naming the chunk.
    pub first_error: Option<String>,
    /// Bytes the method keeps in the budget beside the paged terrain (the
    /// mesh's index pool and draw records; counted in `gpu_bytes`).
    pub method_gpu_bytes: u64,
    /// The method's own work queued or running (the mesh's chunk fits;
    /// counted in `in_flight`).
    pub method_in_flight: u32,
    /// The method's own evictions since creation (the mesh's pooled chunks).
    pub method_evictions: u64,
}

/// The paged terrain's GPU data, its residency and its streamer.
pub struct PagedTerrain {
    plan: BudgetPlan,
    source: Arc<dyn PageSource>,
    /// Chunks across and down.
    grid: (u32, u32),
    /// Ids of the pages of every level.
    ids: PageIds,
    step: u32,
    options: PagedOptions,
    atlas: wgpu::Texture,
    /// The coarse level then the slot pyramids (`maxmip` in `paged.wgsl`).
    pub(crate) levels: wgpu::Buffer,
    pub(crate) table: wgpu::Buffer,
    pub(crate) feedback: wgpu::Buffer,
    pub(crate) params: wgpu::Buffer,
    readback: wgpu::Buffer,
    residency: Residency,
    tops: Vec<u8>,
    streamer: Streamer,
    /// The stamp of the frame being recorded, and of the newest frame whose
    /// feedback was read (pages it read are kept).
    stamp: u32,
    read_stamp: u32,
    /// A frame copied its feedback to `readback`, not yet read.
    readback_due: std::cell::Cell<bool>,
    /// The stamp of the frame whose feedback `readback` holds.
    readback_stamp: std::cell::Cell<u32>,
    /// In a browser, where a map completes only after the page yields:
    /// the map of `readback` asked for and not yet read (no frame copies
    /// into it meanwhile), and its result once it came.
    map: Option<MapState>,
    /// The eye's map position this frame (placement prefers near pages).
    eye: glam::Vec2,
    /// Tries so far per failing chunk.
    failures: HashMap<u32, u32>,
    /// Chunks an edit changed while a read of them was in flight: that
    /// read's page is old and is dropped when it arrives.
    stale: std::collections::HashSet<u32>,
    /// The last read-back frame's requests, most wanted first.
    requested: Vec<u32>,
    stats: PagingStats,
    /// Pages a CPU reader asked for ([`PagedTerrain::request`]).
    cpu_requests: Vec<u32>,
    /// The method's share of the budget ([`PagedTerrain::set_method_share`]).
    method_share: MethodShare,
}

impl PagingStats {
    /// Whether the last read-back frame drew nothing from a missing page
    /// (its pixels, or the shadow texels they sample).
    pub fn converged(&self) -> bool {
        self.pending_pixels == 0 && self.pending_shadow_texels == 0
    }
}

impl PagedTerrain {
    /// The atlas for `source` at `options.gpu_budget`, and the plan. The
    /// atlas goes into the shared frame as its terrain texture (see the
    /// module docs); `step` is the pyramid step of the method reading it.
    pub fn atlas(
        device: &wgpu::Device,
        source: &dyn PageSource,
        options: &PagedOptions,
        step: u32,
    ) -> anyhow::Result<(TerrainTexture, BudgetPlan)> {
        let (w, h) = source.size();
        let chunks = (w / PAGE) * (h / PAGE);
        let ids = page_ids(source, options);
        let limits = device.limits();
        let plan = BudgetPlan::new(
            options.gpu_budget,
            chunks,
            ids.total(),
            page_pyramid_layout(step).bytes,
            std::mem::size_of::<PagedParams>() as u64,
            limits.max_texture_array_layers,
            limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size),
        )
        .map_err(anyhow::Error::msg)?;
        let (across, down) = plan.layer_pages();
        let layout = TerrainLayout {
            map_width: w,
            map_height: h,
            pairs: across * PAGE / 2,
            layer_rows: down * PAGE,
            layers: plan.layers,
        };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("page atlas"),
            size: wgpu::Extent3d {
                width: layout.pairs,
                height: layout.layer_rows,
                depth_or_array_layers: layout.layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("page atlas"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        Ok((
            TerrainTexture {
                layout,
                texture,
                view,
            },
            plan,
        ))
    }

    /// The paged terrain over `shared` (whose terrain texture is the atlas
    /// [`PagedTerrain::atlas`] made with `plan`).
    pub fn new(
        shared: &Shared,
        source: Arc<dyn PageSource>,
        plan: BudgetPlan,
        options: PagedOptions,
        step: u32,
    ) -> anyhow::Result<Self> {
        let device = &shared.device;
        let (w, h) = source.size();
        let grid = (w / PAGE, h / PAGE);
        let tops = source
            .chunk_tops()
            .map_err(|e| anyhow::anyhow!("reading the coarse level: {e}"))?;
        if tops.len() != (grid.0 * grid.1) as usize {
            anyhow::bail!(
                "the coarse level has {} entries for {}x{} chunks",
                tops.len(),
                grid.0,
                grid.1
            );
        }
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, size: u64, usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage,
                mapped_at_creation: false,
            })
        };
        let levels = buffer("page levels", plan.levels_bytes, U::STORAGE | U::COPY_DST);
        let table = buffer("page table", plan.table_bytes, U::STORAGE | U::COPY_DST);
        let ids = page_ids(source.as_ref(), &options);
        if ids.total() != plan.pages {
            anyhow::bail!(
                "the plan counts {} pages; the source has {}",
                plan.pages,
                ids.total()
            );
        }
        let feedback_words = FEEDBACK_HEADER + MAX_REQUESTS + plan.slots + plan.pages;
        let feedback = buffer(
            "page feedback",
            4 * u64::from(feedback_words),
            U::STORAGE | U::COPY_DST | U::COPY_SRC,
        );
        let readback = buffer(
            "page feedback read-back",
            4 * u64::from(FEEDBACK_HEADER + MAX_REQUESTS + plan.slots),
            U::MAP_READ | U::COPY_DST,
        );
        let layout = page_pyramid_layout(step);
        let mut offsets = [[0u32; 4]; 2];
        for info in &layout.levels {
            let k = info.log2_tile as usize;
            if k < 8 {
                offsets[k / 4][k % 4] = info.offset;
            }
        }
        let params_data = PagedParams {
            grid: [
                grid.0.ilog2(),
                plan.chunks.div_ceil(4) * 4,
                plan.pyramid_stride,
                MAX_REQUESTS,
            ],
            atlas: [
                plan.across_log2,
                plan.per_layer_log2,
                FEEDBACK_HEADER + MAX_REQUESTS,
                FEEDBACK_HEADER + MAX_REQUESTS + plan.slots,
            ],
            offsets,
            lod: [
                options.lod_pixels.recip().min(1e6) * f32::from(options.lod_pixels > 0.0),
                options.lod_pixels.recip().min(1e6) * f32::from(options.lod_pixels > 0.0),
                0.0,
                0.0,
            ],
            lod_pages: {
                let mut first = ids.first_ids();
                first[2][3] = ids.levels();
                first
            },
        };
        // Storage, not uniform: see `paged.wgsl`.
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("paged params"),
            size: std::mem::size_of::<PagedParams>() as u64,
            usage: U::STORAGE | U::COPY_DST,
            mapped_at_creation: false,
        });
        shared
            .queue
            .write_buffer(&params, 0, bytemuck::bytes_of(&params_data));
        let mut padded = tops.clone();
        padded.resize(tops.len().div_ceil(4) * 4, 0);
        shared.queue.write_buffer(&levels, 0, &padded);
        // Buffers start zeroed: nothing resident, nothing asked for.
        let streamer = Streamer::new(source.clone(), ids, step, options.threads);
        let stats = PagingStats {
            gpu_budget: plan.budget,
            gpu_bytes: plan.total(),
            slots: plan.slots,
            ..Default::default()
        };
        Ok(PagedTerrain {
            plan,
            source,
            grid,
            ids,
            step,
            options,
            atlas: shared.terrain.texture.clone(),
            levels,
            table,
            feedback,
            params,
            readback,
            residency: Residency::new(plan.pages, plan.slots),
            tops,
            streamer,
            stamp: 0,
            read_stamp: 0,
            readback_due: std::cell::Cell::new(false),
            readback_stamp: std::cell::Cell::new(0),
            map: None,
            eye: glam::Vec2::ZERO,
            failures: HashMap::new(),
            stale: Default::default(),
            requested: Vec::new(),
            stats,
            cpu_requests: Vec::new(),
            method_share: MethodShare::default(),
        })
    }

    /// The plan the budget became.
    pub fn plan(&self) -> &BudgetPlan {
        &self.plan
    }

    /// What the paging did up to the last read-back frame.
    pub fn stats(&self) -> PagingStats {
        let mut s = self.stats.clone();
        s.resident_pages = self.residency.resident() as u32;
        s.resident_bytes = u64::from(s.resident_pages)
            * (residency::PAGE_ATLAS_BYTES + u64::from(self.plan.pyramid_stride));
        s.in_flight = self.streamer.in_flight() as u32;
        self.method_share.add_to(&mut s);
        s
    }

    /// The page table as the GPU holds it (tests).
    pub fn residency(&self) -> &Residency {
        &self.residency
    }

    /// Before recording the frame stamped `stamp`: read the last frame's
    /// feedback if not yet read, want what it asked for and what the view's
    /// footprint holds, upload finished pages, and clear the counters.
    pub fn begin_frame(
        &mut self,
        shared: &Shared,
        camera: &Camera,
        stamp: u32,
    ) -> anyhow::Result<()> {
        self.read_feedback(shared)?;
        self.stamp = stamp;
        self.eye = camera.position.truncate();
        let wanted = self.wanted(camera);
        self.streamer.want(&wanted);
        self.upload(shared, self.options.upload_pages as usize, 4.0);
        shared
            .queue
            .write_buffer(&self.feedback, 0, &[0u8; 4 * FEEDBACK_HEADER as usize]);
        Ok(())
    }

    /// Record the copy of this frame's feedback for [`PagedTerrain::read_feedback`].
    /// In a browser a frame whose read-back buffer is still being mapped
    /// records none (its feedback is skipped; the next one's is read).
    pub fn record_feedback(&self, encoder: &mut wgpu::CommandEncoder) {
        if self.map.is_some() || self.readback_due.get() && cfg!(target_arch = "wasm32") {
            return;
        }
        encoder.copy_buffer_to_buffer(&self.feedback, 0, &self.readback, 0, self.readback.size());
        self.readback_due.set(true);
        self.readback_stamp.set(self.stamp);
    }

    /// Read the recorded frame's feedback (blocks until that frame is done;
    /// in a browser, where nothing blocks, a frame or two later): pending
    /// pixels, requests, and which slots it read.
    pub fn read_feedback(&mut self, shared: &Shared) -> anyhow::Result<()> {
        #[cfg(target_arch = "wasm32")]
        let raw = {
            let Some(raw) = self.poll_feedback()? else {
                return Ok(());
            };
            raw
        };
        #[cfg(not(target_arch = "wasm32"))]
        let raw = {
            if !self.readback_due.replace(false) {
                return Ok(());
            }
            crate::gpu::read_buffer(
                &shared.device,
                &crate::gpu::ErrorSink::default(),
                &self.readback,
                self.readback.size(),
            )?
        };
        let _ = shared;
        let words: &[u32] = bytemuck::cast_slice(&raw);
        let n = (words[1]).min(MAX_REQUESTS) as usize;
        self.stats.pending_pixels = words[0];
        self.stats.requests = words[1];
        self.stats.pending_shadow_texels = words[2];
        let list = &words[FEEDBACK_HEADER as usize..FEEDBACK_HEADER as usize + n];
        self.requested = list
            .iter()
            .copied()
            .filter(|&c| c < self.plan.pages)
            .collect();
        let first_stamp = (FEEDBACK_HEADER + MAX_REQUESTS) as usize;
        for (slot, &s) in words[first_stamp..].iter().enumerate() {
            if s != 0 {
                self.residency.touch(slot as u32, s);
            }
        }
        self.read_stamp = self.readback_stamp.get();
        Ok(())
    }

    /// In a browser: ask for the map of a recorded frame's feedback (its
    /// copy was submitted with that frame), or take it once it came.
    #[cfg(target_arch = "wasm32")]
    fn poll_feedback(&mut self) -> anyhow::Result<Option<Vec<u8>>> {
        let Some(map) = &self.map else {
            if self.readback_due.get() {
                let state = MapState::default();
                let sink = Arc::clone(&state);
                self.readback
                    .slice(..)
                    .map_async(wgpu::MapMode::Read, move |r| {
                        if let Ok(mut s) = sink.lock() {
                            *s = Some(r);
                        }
                    });
                self.map = Some(state);
            }
            return Ok(None);
        };
        let Some(result) = map.lock().ok().and_then(|mut s| s.take()) else {
            return Ok(None);
        };
        self.map = None;
        self.readback_due.set(false);
        result.map_err(|e| anyhow::anyhow!("mapping the page feedback failed: {e}"))?;
        let raw = self
            .readback
            .slice(..)
            .get_mapped_range()
            .map_err(|e| anyhow::anyhow!("reading the page feedback failed: {e}"))?
            .to_vec();
        self.readback.unmap();
        Ok(Some(raw))
    }

    /// Upload up to `most` finished pages.
    fn upload(&mut self, shared: &Shared, most: usize, budget_ms: f64) {
        self.stats.uploaded_pages = 0;
        self.stats.uploaded_bytes = 0;
        for (chunk, page) in self.streamer.poll(most, budget_ms) {
            if self.stale.remove(&chunk) || self.residency.slot_of(chunk).is_some() {
                // Read before an edit, or placed meanwhile (by `refresh`).
                continue;
            }
            match page {
                Ok(page) => self.place(shared, chunk, &page),
                Err(e) => {
                    let tries = self.failures.entry(chunk).or_insert(0);
                    *tries += 1;
                    if *tries == self.options.read_tries {
                        self.stats.read_errors += 1;
                        if self.stats.first_error.is_none() {
                            self.stats.first_error =
                                Some(format!("{} failed to read: {e}", self.describe(chunk)));
                        }
                    }
                }
            }
        }
    }

    /// Put `page` (chunk `chunk`) in a slot, if one is free or unused.
    fn place(&mut self, shared: &Shared, chunk: u32, page: &PageData) {
        let keep_from = self.read_stamp;
        let eye = self.eye;
        let ids = self.ids;
        let distance = move |c: u32| ids.distance(eye, c);
        let Some(placed) = self.residency.place(chunk, self.stamp, keep_from, distance) else {
            return;
        };
        if let Some(old) = placed.evicted {
            self.write_entry(shared, old);
            self.stats.total_evictions += 1;
        }
        self.write_page(shared, placed.slot, page);
        self.write_entry(shared, chunk);
        self.stats.uploaded_pages += 1;
        self.stats.uploaded_bytes += page.bytes() as u64 + 8;
        self.stats.total_uploads += 1;
    }

    fn write_page(&self, shared: &Shared, slot: u32, page: &PageData) {
        let (layer, x, y) = self.plan.slot_origin(slot);
        shared.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.atlas,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: layer },
                aspect: wgpu::TextureAspect::All,
            },
            &page.pairs,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(PAGE / 2 * 4),
                rows_per_image: Some(PAGE),
            },
            wgpu::Extent3d {
                width: PAGE / 2,
                height: PAGE,
                depth_or_array_layers: 1,
            },
        );
        let offset = u64::from(self.plan.chunks.div_ceil(4) * 4)
            + u64::from(slot) * u64::from(self.plan.pyramid_stride);
        shared
            .queue
            .write_buffer(&self.levels, offset, &page.pyramid);
    }

    fn write_entry(&self, shared: &Shared, chunk: u32) {
        let e = self.residency.table()[chunk as usize];
        shared
            .queue
            .write_buffer(&self.table, 4 * u64::from(chunk), bytemuck::bytes_of(&e));
    }

    /// The source changed inside `chunks` (an edit, already written there,
    /// coarse levels included): refresh their coarse level and the resident
    /// pages over them, of every level, now, so the next frame shows the edit.
    pub fn refresh(&mut self, shared: &Shared, chunks: &[u32]) -> anyhow::Result<()> {
        let mut coarse = Vec::new();
        for &chunk in chunks {
            if chunk >= self.plan.chunks {
                anyhow::bail!(
                    "chunk {chunk} is outside the {}-chunk world",
                    self.plan.chunks
                );
            }
            let page = self.reread(shared, chunk)?;
            let top = page.top(self.step);
            if self.tops[chunk as usize] != top {
                self.tops[chunk as usize] = top;
                // Rewrite the word holding it.
                let w = (chunk / 4 * 4) as usize;
                let mut word = [0u8; 4];
                for (i, b) in word.iter_mut().enumerate() {
                    *b = self.tops.get(w + i).copied().unwrap_or(0);
                }
                shared.queue.write_buffer(&self.levels, w as u64, &word);
            }
            coarse.extend(self.ids.above(chunk));
        }
        coarse.sort_unstable();
        coarse.dedup();
        for page in coarse {
            // Only what the GPU holds or is reading: the rest reads fresh.
            if self.residency.slot_of(page).is_some() || self.streamer.is_in_flight(page) {
                self.reread(shared, page)?;
            }
        }
        Ok(())
    }

    /// Read page `id` again after an edit: rewrite its slot if resident,
    /// drop a read in flight (it may predate the edit).
    fn reread(&mut self, shared: &Shared, id: u32) -> anyhow::Result<PageData> {
        let (level, cx, cy) = self
            .ids
            .locate(id)
            .ok_or_else(|| anyhow::anyhow!("page {id} is outside the world"))?;
        let page = self
            .source
            .read_lod_page(level, cx, cy, self.step)
            .map_err(|e| anyhow::anyhow!("re-reading {} after an edit: {e}", self.describe(id)))?;
        if let Some(slot) = self.residency.slot_of(id) {
            self.write_page(shared, slot, &page);
        } else if self.streamer.is_in_flight(id) {
            self.stale.insert(id);
        }
        self.failures.remove(&id);
        Ok(page)
    }

    /// Page `id` in words: "chunk (x, y)", or "level-of-detail 2 page (x, y)".
    fn describe(&self, id: u32) -> String {
        match self.ids.locate(id) {
            Some((0, cx, cy)) => format!("chunk ({cx}, {cy})"),
            Some((k, cx, cy)) => format!("level-of-detail {k} page ({cx}, {cy})"),
            None => format!("page {id}"),
        }
    }

    /// The ids of the pages of every level.
    pub fn ids(&self) -> &PageIds {
        &self.ids
    }
}

/// A buffer map's result once its callback ran (a browser's read-back).
type MapState = Arc<std::sync::Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// The page ids of `source` drawn with `options`: coarse levels only with
/// the level of detail on.
fn page_ids(source: &dyn PageSource, options: &PagedOptions) -> PageIds {
    let (w, h) = source.size();
    let levels = if options.lod_pixels > 0.0 {
        source.lod_levels()
    } else {
        0
    };
    PageIds::new((w / PAGE, h / PAGE), levels)
}

/// A method's share of the GPU budget beside the paged terrain (the paged
/// mesh's index pool): the atlas was planned for the rest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MethodShare {
    /// The whole budget (the atlas's plan has the part left to it).
    pub budget: u64,
    /// Bytes the method keeps on the GPU within it.
    pub gpu_bytes: u64,
    /// The method's work queued or running.
    pub in_flight: u32,
    /// The method's own evictions since creation.
    pub evictions: u64,
}

impl MethodShare {
    fn add_to(&self, s: &mut PagingStats) {
        if self.budget == 0 {
            return;
        }
        s.gpu_budget = self.budget;
        s.gpu_bytes += self.gpu_bytes;
        s.method_gpu_bytes = self.gpu_bytes;
        s.in_flight += self.in_flight;
        s.method_in_flight = self.in_flight;
        s.method_evictions = self.evictions;
    }
}

/// Pages read by CPU-placed draws (the paged mesh, issue 33): its vertex
/// stage reads texels through the page table without feedback, so it asks
/// for pages here and marks the resident ones in use.
impl PagedTerrain {
    /// Ask for `chunks` (most wanted first) at the next
    /// [`PagedTerrain::begin_frame`], after the frame feedback's requests
    /// and before the view's footprint; the resident ones count as read by
    /// frame `stamp` (not evicted for pages read less recently).
    pub fn request(&mut self, chunks: &[u32], stamp: u32) {
        self.cpu_requests.clear();
        for &c in chunks {
            match self.residency.slot_of(c) {
                Some(slot) => self.residency.touch(slot, stamp),
                None if c < self.plan.chunks => self.cpu_requests.push(c),
                None => {}
            }
        }
    }

    /// Whether `chunk`'s page is in the atlas.
    pub fn is_resident(&self, chunk: u32) -> bool {
        self.residency.slot_of(chunk).is_some()
    }

    /// The highest top of `chunk` (the always-resident coarse level).
    pub fn chunk_top(&self, chunk: u32) -> u8 {
        self.tops.get(chunk as usize).copied().unwrap_or(u8::MAX)
    }

    /// The options it was made with.
    pub fn options(&self) -> &PagedOptions {
        &self.options
    }

    /// Chunks (pages) across and down.
    pub fn grid(&self) -> (u32, u32) {
        self.grid
    }

    /// Where pages come from.
    pub fn source(&self) -> &Arc<dyn PageSource> {
        &self.source
    }

    /// The method's share of the budget, reported with the paging's own
    /// bytes in [`PagedTerrain::stats`].
    pub fn set_method_share(&mut self, share: MethodShare) {
        self.method_share = share;
    }

    /// The smallest budget whose plan holds a world of `source`'s size,
    /// drawn with `options` (its levels of detail count in the page table),
    /// with pyramids of `step` (what [`BudgetPlan::new`] refuses below).
    pub fn smallest_budget(source: &dyn PageSource, options: &PagedOptions, step: u32) -> u64 {
        let (w, h) = source.size();
        BudgetPlan::smallest(
            (w / PAGE) * (h / PAGE),
            page_ids(source, options).total(),
            page_pyramid_layout(step).bytes,
            std::mem::size_of::<PagedParams>() as u64,
        )
    }
}
