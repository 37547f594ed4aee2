//! `ray-exact` and `ray-exact-fragment`: the exact march (issue 15). A
//! hierarchical 2D traversal over the max-height pyramid of column tops
//! ([`pyramid`], the twin of `strata_maxmip`), descending where the
//! ray dips to a tile's maximum, and at the finest level the exact
//! segment–interval test of the CPU reference: no step budget, only a
//! safety cap on iterations ([`ITERATION_CAP`]) whose hits are counted
//! ([`RayExact::stats`]). f32 throughout, relative to the 256-texel tile
//! holding the ray's start (`ray_exact_core.wgsl`), so depth on a
//! 16384-long wrapping map agrees with the f64 reference.
//!
//! `ray-exact` is a compute dispatch (colour into the shared target, depth
//! into an R32Float image, which [`Method::depth_image`] hands to
//! `Renderer::read_depth`); the shared full-screen depth blit copies it into
//! the shared depth target only on frames that ask for it
//! (`Renderer::set_depth_attachment`, `render_into`), and then *loads* the
//! target instead of clearing it first: the blit writes every pixel (compare
//! `Always`, sky = 1.0), so the image is the same, and on the H100 the clear
//! alone cost 0.073 ms of the blit's 0.149. (`STRATA_EXACT_DEPTH=blit`
//! restores the clear.) `ray-exact-fragment` is one full-screen fragment pass.
//! Both fill the shared shadow map with the same march along the light
//! ([`Method::record_shadow_map`]) instead of the renderer's 128-step march.
//!
//! The compute traversals visit every other level (tiles of 4, 16, 64 and
//! 256 texels), so `ray-exact` builds only those
//! ([`ExactOptions::pyramid_step`]): 2,236,928 bytes on the default
//! 2048x16384 world instead of 11,184,640 for every level, which
//! `ray-exact-fragment` (whose pipeline visits every level) keeps.
//!
//! On frames that cast the shadow map, `ray-exact` defers its shading
//! (`ray_exact_deferred.wgsl`): the march writes each pixel's hit (`t` and
//! column) and lists the 8x8-texel blocks of the map its shading will read;
//! the shadow pass casts only those blocks (one workgroup each, an indirect
//! dispatch); a third pass shades every hit exactly as the one-pass march
//! does. On the default views the visible surface reads 2-17 % of the map
//! where the view's cover ([`strata_camera::light::ShadowCover`]) holds
//! 25-86 %. Such a map is the method's own ([`Method::shadow_map_is_partial`]):
//! no other method reuses it. Frames that reuse a map, or have shadows off,
//! march and shade in one pass.
//!
//! Over the whole map the deferred frame also keeps the blocks earlier
//! frames cast (`shadow_keep.wgsl`, `keep::ShadowKeep`): the map's texels
//! lie on a lattice fixed to the light and sit in the texture at their
//! lattice index wrapped ([`strata_camera::light::ShadowFrame::slot`]), so a
//! block cast while the texel size and the plane were the same, and with no
//! other writer of the map since, holds what casting it again would. An edit
//! spoils only the blocks whose shadow rays cross the edited columns; the
//! next frame clears their tags (`keep.rs`).
//! The march lists only blocks that are not kept, and shades on the spot every
//! pixel whose blocks all are; the shading pass runs only over the 8x8 tiles
//! with a pixel left. A still view casts and shades nothing after its first
//! frame; a walking one casts the blocks that come into view.
//!
//! Those lists live on the GPU, so the CPU cannot tell a frame that nothing
//! is left to cast. `cover.rs` keeps a record of its own: once the view has
//! been still (the same camera and key) for two frames, the shadow pass
//! casts up to [`ExactOptions::cover_budget`] blocks of the view's cover a
//! frame ahead of the march, and when the record holds the whole cover
//! (which holds every texel a visible point's shading can read) the frame
//! marches and shades in one pass, as a frame with a reused map does: no
//! stamps, no hits, no shadow or shading pass. A still view gets there
//! within a few dozen frames (on the H100 its frame goes from 0.128 to
//! 0.107 ms, `bench/cover-whole/`); a moving one keeps the deferred frame.
//!
//! The compute variant over the whole map first searches a beam per 8x8-pixel
//! tile (`beam.rs`, `ray_exact_beam.wgsl`, issue 36): the least `t` at which
//! any ray of the tile may meet a solid point, and the march starts each of
//! its rays there, at the 4-texel tiles ([`BEAM_LEVEL`]); the deferred
//! frame's shadow blocks do the same along the light. The search
//! ([`ExactOptions::beam_search`], [`BeamSearch`]) is wide by default: the
//! tile's 64 invocations test 64 slices of its depth range at once, then 64
//! sub-slices of the first slice that may hold ground (a pre-pass of one
//! workgroup per tile, or in the march's own workgroup), where the first
//! pre-pass walked it serially, one invocation per tile. Same hits, bit for
//! bit; on the default views at 1280x800 (`strata exact-counts`) 9.05 march
//! iterations a pixel instead of 18.6 without a beam (11.1 serially) and
//! 9.4 a shadow ray instead of 17.0 (10.6): `bench/issue36-beam/wide/`.
//! `STRATA_EXACT_BEAM=off` ([`ExactOptions::beam`]) turns it off.
//!
//! A descent into the texels may test the texel it lands on in the same
//! iteration ([`ExactOptions::fused_descent`], `EXACT_FUSED_DESCENT`): same
//! hits, 20 % fewer iterations on paper and a 10 % faster march on lavapipe
//! (`bench/issue36-fused-descent/`), but a 9 % slower frame on the H100
//! (`bench/issue36-cave-skip/`): off by default.
//!
//! A tile whose highest top is above a camera ray is skipped all the same
//! where the ray passes between the tile's floors and slabs: under a bridge,
//! through a cave ([`ExactOptions::cave_skip`], `EXACT_CAVE_SKIP`; the cave
//! pyramid, `strata_maxmip::CavePyramid`, kept beside the maxima). The beams
//! test a box no wider than a texel against its texels
//! ([`ExactOptions::beam_texels`], `EXACT_BEAM_TEXELS`). Same hits; on the
//! H100 the frame goes from 0.1663 to 0.1607 ms (`bench/issue36-cave-skip/`).
//!
//! What bounds the march on the H100 (`bench/issue36-floors/`): the driver
//! gives it 31 registers a thread (`examples/pipeline_stats.rs`), so SMs
//! hold as many warps as they can, yet one more dependent load per
//! iteration costs 6 % of the march and 16 dependent multiply-adds 3 %:
//! each step's chain of dependent work is what the walk pays for. So a
//! step reads a tile's cave word beside its maximum rather than after it;
//! fetching the next steps' tiles ahead of need cost 30 % (more loads per
//! step), and so did testing wider beam boxes against their texels.
//!
//! The texel plane's walks ([`ExactOptions::texel_walk`], [`TexelWalk`],
//! `EXACT_TEXEL_BLOCKS`, `STRATA_EXACT_TEXEL_BLOCKS=plane|beside`) shorten
//! that chain: a ray that comes down into a 4x4-texel tile has the tile's
//! sixteen texel bytes (`strata_maxmip::TexelTops`, after the pyramids:
//! each column's top, or "decode" where it has a slab) in four loads side
//! by side, and tests each single-floor texel from them, fetching only the
//! columns with a slab. `plane` loads them once the ray comes down into
//! the tile, `beside` with the tile's maximum at every step over a 4x4
//! tile. Same hits and iterations; on paper (`strata exact-counts
//! --texel-walk`) half the fetches a warp waits on, yet on the H100 both
//! are slower (0.1557 ms a frame with the terrain walk, 0.1621 `plane`,
//! 0.1639 `beside`, one call; `bench/issue36-texel-blocks/`): the walk
//! issues more to wait less, and waiting is not what bounds it. Off.
//!
//! Measuring switches ([`ExactOptions`] and `exact_stats` in
//! [`crate::options::RenderOptions`], read at creation from the shared
//! frame; the `strata` binary sets them from `STRATA_EXACT_*`; H100 numbers
//! in `bench/ray-exact.md`): `exact_shadow` off keeps the renderer's shadow
//! pass; `depth` picks the depth pass (blit, points, or the blit loading
//! the old depth); `climb`, `log_ratio` change the traversal's climbing and
//! level ratio (same image); `exact_stats` prints the iteration statistics,
//! the build's and each update's GPU time to stderr when the method is
//! dropped. `shadow_reuse` (the renderer's) keeps the shadow map while its
//! frame and the terrain are unchanged.
//!
//! [`pyramid`]: pyramid

use super::common::{DepthCopy, dispatch_per_pixel, fullscreen_pipeline};
pub mod pyramid;
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{SHADOW_SIZE, Shared};
use crate::gpu::read_words;
use pyramid::GpuMaxMip;
use serde::Serialize;
use std::cell::{Cell, RefCell};
use strata_camera::Camera;
use strata_camera::light::ShadowFrame;
use strata_level::{DirtyRect, Level};

/// The pyramid level the whole map's compute traversals start at
/// (`EXACT_START_LEVEL`): tiles of 64 texels. `strata exact-counts` counts
/// 4 % fewer iterations than from the 256-texel tiles on the default views
/// (camera and shadow rays alike), with the same hits.
pub const START_LEVEL: u32 = 6;

/// The pyramid level camera rays start at from their tile's beam
/// (`EXACT_BEAM_LEVEL`, [`ExactOptions::beam`]): tiles of 4 texels. Near
/// the ground, where the beam leaves them, `strata exact-counts` counts
/// 10.1 iterations a pixel from there against 11.7 from `START_LEVEL`.
pub const BEAM_LEVEL: u32 = 2;

/// Most traversal iterations of one ray: a guard against a hang, never
/// reached on the protocol's views (counted in [`ExactStats`]).
pub const ITERATION_CAP: u32 = 4096;

/// What the march counted since creation (or the last [`RayExact::reset_stats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ExactStats {
    /// Camera rays stopped by [`ITERATION_CAP`] (must be 0).
    pub cap_hits: u32,
    /// Most iterations any camera ray took (compute variant only; 0 unless
    /// [`ExactOptions::iteration_stats`] or the renderer's `exact_stats`).
    pub most_iterations: u32,
    /// Shadow-map rays stopped by the cap (must be 0).
    pub shadow_cap_hits: u32,
    /// Most iterations any shadow-map ray took (as `most_iterations`).
    pub shadow_most_iterations: u32,
}

enum Variant {
    Compute {
        march: wgpu::ComputePipeline,
        /// Boxed: the variants stay of like size.
        depth: Box<DepthCopy>,
        mode: DepthMode,
        /// The frame that casts the shadow map between march and shading
        /// (with the exact shadow map).
        deferred: Option<Box<Deferred>>,
    },
    Fragment(wgpu::RenderPipeline),
}

pub struct RayExact {
    name: &'static str,
    levels: Levels,
    params: wgpu::Buffer,
    stats: wgpu::Buffer,
    /// The deferred frame's stamped shadow blocks and their list.
    marks: ShadowMarks,
    /// This frame's stamp (`ExactParams::config[2]`), never 0.
    stamp: u32,
    /// Which shadow blocks of earlier frames this frame keeps.
    keep: ShadowKeep,
    /// [`ExactOptions::shadow_keep`].
    keep_shadow: bool,
    /// The cover blocks this method's listed casts hold (`cover.rs`).
    cover: RefCell<CoverKeep>,
    /// This frame's plan for them (recorded with the shadow map, if cast)
    /// and the map it is for.
    cover_plan: RefCell<Option<(CoverPlan, ShadowFrame)>>,
    /// [`ExactOptions::cover_budget`].
    cover_budget: u32,
    /// [`ExactOptions::edit_keep`].
    edit_keep: bool,
    /// The last frame that cast the map found its cover whole and marched
    /// in one pass.
    covered: Cell<bool>,
    /// The renderer asked for the shadow map this frame; the deferred frame
    /// casts it between march and shading.
    shadow_due: Cell<bool>,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    variant: Variant,
    /// The beam pre-pass (compute over the whole map).
    beam: Option<Beam>,
    shadow: Option<ExactShadow>,
    /// The pyramid update was recorded this frame (before the shadow map).
    updated: Cell<bool>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    print_stats: bool,
    /// With `STRATA_EXACT_STATS=1` and timestamps: the pyramid updates are
    /// timed here (not in the frame's sum) and their GPU ms kept.
    update_timer: Option<crate::timing::PassTimer>,
    update_timed: Cell<bool>,
    update_ms: Vec<f64>,
}

pub use crate::options::{BeamSearch, DepthMode, ExactOptions, TexelWalk};

pub fn create(
    shared: &Shared,
    level: &Level,
    _settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let options = ExactOptions {
        compute: true,
        ..shared.options.exact
    };
    Ok(Box::new(build(shared, level, options)?))
}

pub fn create_fragment(
    shared: &Shared,
    level: &Level,
    _settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let options = ExactOptions {
        compute: false,
        ..shared.options.exact
    };
    Ok(Box::new(build(shared, level, options)?))
}

/// Build the method with explicit options.
pub fn build(shared: &Shared, level: &Level, options: ExactOptions) -> anyhow::Result<RayExact> {
    let pyramid = GpuMaxMip::with_texels(
        shared,
        level,
        options.pyramid_step(),
        true,
        options.texel_walk.reads_plane() && options.compute,
    )?;
    let mut table = exact_params(&pyramid.layout);
    if let Some(first) = pyramid.texel_plane() {
        // Index 0 (no pyramid level): the texel plane, as `texel_block_rows`
        // reads it (words across, their log2, rows).
        let words = level.width() / 4;
        table.levels[0] = [first, words.trailing_zeros(), words - 1, level.height() - 1];
    }
    build_on(shared, Levels::Whole(Box::new(pyramid)), table, options)
}

/// Build the method over paged terrain (`crate::paged`): the shared frame's
/// terrain texture must be `paged`'s atlas, made with this method's pyramid
/// step ([`ExactOptions::pyramid_step`]).
pub fn build_paged(
    shared: &Shared,
    paged: PagedTerrain,
    options: ExactOptions,
) -> anyhow::Result<RayExact> {
    if !options.exact_shadow {
        anyhow::bail!(
            "paged terrain needs the exact shadow map (the renderer's own shadow pass reads the whole map)"
        );
    }
    // The march starts at the 256-texel tile: the coarse level, one byte
    // per page; the finer levels are the pages' own.
    let table = ExactParams {
        config: [strata_maxmip::MAX_LEVEL, ITERATION_CAP, 0, 0],
        levels: [[0; 4]; 9],
        shadow_keep: [0; 4],
    };
    build_on(shared, Levels::Paged(Box::new(paged)), table, options)
}

fn build_on(
    shared: &Shared,
    levels: Levels,
    table: ExactParams,
    options: ExactOptions,
) -> anyhow::Result<RayExact> {
    let compute = options.compute;
    let device = &shared.device;
    // The deferred frame (compute, exact shadow map) lists shadow blocks.
    let deferred_frame = compute && options.exact_shadow && shared.caps.compute;
    let params = shared.uniform_buffer("ray-exact params", bytemuck::bytes_of(&table));
    let blocks = SHADOW_SIZE / MARK_BLOCK;
    let marks = ShadowMarks::new(device, blocks * blocks, deferred::pixel_tiles(shared));
    let stats = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ray-exact stats"),
        size: 16,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let name = if compute {
        "ray-exact"
    } else {
        "ray-exact-fragment"
    };
    let stages = if compute {
        wgpu::ShaderStages::COMPUTE
    } else {
        wgpu::ShaderStages::FRAGMENT
    };
    let mut entries = core_entries(stages, levels.is_paged());
    let depth = if compute {
        let depth = DepthCopy::new(shared, name, "ray-exact depth")?;
        Some(if options.depth == DepthMode::Points {
            depth.with_points(shared)?
        } else {
            depth
        })
    } else {
        None
    };
    let beam = if compute && !levels.is_paged() {
        Some(Beam::new(shared, (&params, &levels, &stats), options)?)
    } else {
        None
    };
    if compute {
        entries.extend(DepthCopy::layout_entries(3));
    }
    entries.extend(beam.as_ref().map(|_| bindings::beam_layout_entry()));
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(name),
        entries: &entries,
    });
    let group = march_group(
        shared,
        &layout,
        &params,
        &levels,
        &stats,
        depth.as_ref(),
        beam.as_ref().map(|b| &b.buffer),
    );
    let pipeline_layout = shared.pipeline_layout(name, &[&layout]);
    let variant = match depth {
        Some(depth) => Variant::Compute {
            march: exact_pipeline(
                shared,
                name,
                &levels,
                "ray_exact.wgsl",
                &pipeline_layout,
                "cs_ray_exact",
                options,
            )?,
            mode: options.depth,
            deferred: if deferred_frame {
                Some(Box::new(Deferred::new(
                    shared,
                    (&params, &levels, &stats, &marks),
                    &depth,
                    beam.as_ref().map(|b| &b.buffer),
                    options,
                )?))
            } else {
                None
            },
            depth: Box::new(depth),
        },
        None => Variant::Fragment(fullscreen_pipeline(
            shared,
            name,
            &levels.shader("ray_exact_fragment.wgsl"),
            &pipeline_layout,
            "fs_ray_exact",
        )?),
    };
    let shadow = if shared.caps.compute && options.exact_shadow {
        Some(ExactShadow::new(
            shared,
            (&params, &levels, &stats, &marks),
            options,
        )?)
    } else {
        None
    };
    Ok(RayExact {
        name,
        levels,
        params,
        stats,
        marks,
        stamp: 0,
        keep: ShadowKeep::new(),
        keep_shadow: options.shadow_keep,
        cover: RefCell::new(CoverKeep::new()),
        cover_plan: RefCell::new(None),
        cover_budget: options.cover_budget,
        edit_keep: options.edit_keep,
        covered: Cell::new(false),
        shadow_due: Cell::new(false),
        layout,
        group,
        variant,
        beam,
        shadow,
        updated: Cell::new(false),
        device: device.clone(),
        queue: shared.queue.clone(),
        print_stats: shared.options.exact_stats,
        update_timer: (shared.options.exact_stats && shared.caps.timestamps)
            .then(|| crate::timing::PassTimer::new(device, &shared.queue, true)),
        update_timed: Cell::new(false),
        update_ms: Vec::new(),
    })
}

impl RayExact {
    /// GPU bytes of the pyramid, or of the paged terrain but its atlas (the
    /// shared frame's terrain texture, counted there).
    fn levels_bytes(&self) -> u64 {
        match &self.levels {
            Levels::Whole(p) => p.gpu_bytes(),
            Levels::Paged(p) => p.plan().total() - p.plan().atlas_bytes,
        }
    }

    /// The GPU pyramid (tests compare it with `strata_maxmip`); `None` over
    /// paged terrain.
    pub fn pyramid(&self) -> Option<&GpuMaxMip> {
        match &self.levels {
            Levels::Whole(p) => Some(p),
            Levels::Paged(_) => None,
        }
    }

    /// The paged terrain, if the method draws one.
    pub fn paged(&self) -> Option<&PagedTerrain> {
        match &self.levels {
            Levels::Paged(p) => Some(p),
            Levels::Whole(_) => None,
        }
    }

    /// The paged terrain, to refresh after an edit or settle (tests).
    pub fn paged_mut(&mut self) -> Option<&mut PagedTerrain> {
        match &mut self.levels {
            Levels::Paged(p) => Some(p),
            Levels::Whole(_) => None,
        }
    }

    /// What the last deferred frame left to its later passes (waits for
    /// the GPU): the shadow blocks it cast (those its pixels read that no
    /// earlier frame's cast was kept for) and the pixel tiles the shading
    /// pass shaded (those with a pixel that read such a block).
    pub fn deferred_work(&self) -> anyhow::Result<(u32, u32)> {
        let words = read_words(
            &self.device,
            &self.queue,
            &self.marks.stamps,
            "deferred work",
        )?;
        let shade = (self.marks.shade_dispatch() / 4) as usize;
        Ok((words[0], words[shade]))
    }

    /// Whether the last frame that cast the shadow map found every block of
    /// its cover cast and marched and shaded in one pass (`cover.rs`).
    pub fn covered(&self) -> bool {
        self.covered.get()
    }

    /// The march's counters since creation or the last reset.
    pub fn stats(&self) -> anyhow::Result<ExactStats> {
        let w = read_words(&self.device, &self.queue, &self.stats, "ray-exact stats")?;
        Ok(ExactStats {
            cap_hits: w[0],
            most_iterations: w[1],
            shadow_cap_hits: w[2],
            shadow_most_iterations: w[3],
        })
    }

    /// Zero the counters.
    pub fn reset_stats(&self) {
        self.queue.write_buffer(&self.stats, 0, &[0u8; 16]);
    }

    /// Keep the last frame's update time (statistics mode only).
    fn read_update_time(&mut self) -> anyhow::Result<()> {
        if let (Some(timer), true) = (&self.update_timer, self.update_timed.get()) {
            self.update_timed.set(false);
            if let Some(ms) = timer.read_blocking(&self.device)? {
                self.update_ms.push(ms);
            }
        }
        Ok(())
    }

    /// The exact shadow pass: every texel of the view's cover, or (`listed`,
    /// the deferred frame) the blocks its march listed.
    fn record_shadow_pass(
        &self,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        listed: bool,
    ) {
        let Some(shadow) = &self.shadow else {
            return;
        };
        if listed {
            shadow.record_listed(frame, encoder, &self.marks);
        } else {
            // Every texel of the cover, none tagged: no block is kept.
            self.keep.forget();
            shadow.record_cover(frame, encoder);
        }
    }

    /// Whether frames that cast the shadow map take the deferred route
    /// (march, shadow blocks, shading): the compute variant with the exact
    /// shadow map, at a frame size whose hits fit the device.
    fn defers(&self) -> bool {
        matches!(
            &self.variant,
            Variant::Compute {
                deferred: Some(d),
                ..
            } if d.fits
        )
    }

    /// The compute variant's bind groups again, over its current images,
    /// beam and colour output (after a resize or a new colour output).
    fn rebind(&mut self, shared: &Shared) {
        let Variant::Compute {
            depth, deferred, ..
        } = &mut self.variant
        else {
            return;
        };
        let beam = self.beam.as_ref().map(|b| &b.buffer);
        if let Some(d) = deferred {
            let buffers = (&self.params, &self.levels, &self.stats, &self.marks);
            d.rebind(shared, buffers, depth, beam);
        }
        self.group = march_group(
            shared,
            &self.layout,
            &self.params,
            &self.levels,
            &self.stats,
            Some(depth),
            beam,
        );
    }

    /// Record the queued pyramid update once per frame, before anything reads it.
    fn record_update(&self, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if let Levels::Whole(pyramid) = &self.levels
            && !self.updated.get()
            && pyramid.has_work()
        {
            if let Some(timer) = &self.update_timer {
                timer.reset();
                pyramid.record(encoder, timer.compute("ray-exact pyramid update"));
                timer.resolve(encoder);
                self.update_timed.set(true);
            } else {
                pyramid.record(encoder, frame.timer.compute("ray-exact pyramid update"));
            }
        }
        self.updated.set(true);
    }
}

impl Method for RayExact {
    fn name(&self) -> &'static str {
        self.name
    }

    fn apply_edit(
        &mut self,
        _shared: &Shared,
        level: &Level,
        rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        match &mut self.levels {
            Levels::Whole(pyramid) => {
                pyramid.enqueue(rects);
                // The next frame clears the kept blocks whose shadow rays
                // cross the edited columns (or, for A/B, forgets them all).
                if self.edit_keep {
                    self.keep.edited(rects, (level.width(), level.height()));
                } else {
                    self.keep.forget();
                }
                Ok(())
            }
            Levels::Paged(_) => anyhow::bail!(
                "{} draws paged terrain: edits reach it through its store (PagedTerrain::refresh)",
                self.name
            ),
        }
    }

    fn update_settings(&mut self, _: &Shared, _: &MethodSettings) -> anyhow::Result<bool> {
        // No knob: nothing to change.
        Ok(true)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        if let Variant::Compute {
            depth, deferred, ..
        } = &mut self.variant
        {
            depth.resize(shared);
            if let Some(beam) = &mut self.beam {
                beam.resize(shared, (&self.params, &self.levels, &self.stats));
            }
            if let Some(d) = deferred {
                d.hits = deferred::hits_buffer(shared);
                d.fits = deferred::hits_fit(shared);
            }
            let tiles = deferred::pixel_tiles(shared);
            if tiles > self.marks.tiles {
                // Room for the new frame's tiles (the tags go with the old
                // list: nothing is kept).
                let blocks = SHADOW_SIZE / MARK_BLOCK;
                self.marks = ShadowMarks::new(&shared.device, blocks * blocks, tiles);
                self.keep.forget();
                if let Some(shadow) = &mut self.shadow {
                    let buffers = (&self.params, &self.levels, &self.stats, &self.marks);
                    shadow.rebind(shared, buffers);
                }
            }
            self.rebind(shared);
        }
        Ok(())
    }

    fn draws_color_by_attachment(&self) -> bool {
        matches!(self.variant, Variant::Fragment(_))
    }

    fn store_color_into(
        &mut self,
        shared: &Shared,
        view: Option<&wgpu::TextureView>,
    ) -> anyhow::Result<bool> {
        let Variant::Compute { depth, .. } = &mut self.variant else {
            return Ok(view.is_none());
        };
        if depth.set_color_out(view) {
            self.rebind(shared);
        }
        Ok(true)
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        self.read_update_time()?;
        self.updated.set(false);
        self.shadow_due.set(false);
        // A new stamp each frame: last frame's marks no longer count.
        self.stamp = self.stamp.wrapping_add(1).max(1);
        match &mut self.levels {
            Levels::Whole(pyramid) => pyramid.prepare(shared),
            Levels::Paged(paged) => paged.begin_frame(shared, camera, self.stamp)?,
        }
        shared
            .queue
            .write_buffer(&self.params, 8, bytemuck::bytes_of(&self.stamp));
        // The texel size and plane this frame's map has (the renderer fits
        // the same frame; whether shadows are on changes neither).
        let fit = ShadowFrame::fit(camera, true);
        let keep = self.keep_shadow && matches!(self.levels, Levels::Whole(_)) && self.defers();
        let keyed = self.keep.key(&fit, shared.shadow_map_writes(), keep);
        let key = keyed.key;
        if !keyed.spoiled.is_empty() {
            // Before anything of this frame reads the tags.
            self.marks.clear_tags(&shared.queue, &keyed.spoiled);
            self.cover.get_mut().drop_slots(&keyed.spoiled);
        }
        self.plan_cover(key, camera, fit);
        shared.queue.write_buffer(
            &self.params,
            std::mem::offset_of!(ExactParams, shadow_keep) as u64,
            bytemuck::bytes_of(&key),
        );
        // No block or tile listed yet: the march lists them, and the shadow
        // and shading passes dispatch one workgroup per listed one.
        let none = bytemuck::cast_slice(&[0u32, 1, 1]);
        shared.queue.write_buffer(&self.marks.stamps, 0, none);
        let shade = self.marks.shade_dispatch();
        shared.queue.write_buffer(&self.marks.stamps, shade, none);
        Ok(())
    }

    fn record_shadow_map(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        if self.shadow.is_none() {
            return false;
        }
        self.record_update(frame, encoder);
        self.keep.wrote(shared.shadow_map_written());
        if self.defers() {
            if !self.record_cover_ahead(shared, frame, encoder) {
                // Cast in `record`, between the march and the shading.
                self.shadow_due.set(true);
            }
        } else {
            self.record_shadow_pass(frame, encoder, false);
        }
        true
    }

    fn shadow_map_is_partial(&self) -> bool {
        self.defers()
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        self.record_update(frame, encoder);
        match &self.variant {
            Variant::Compute {
                march,
                depth,
                mode,
                deferred,
            } => {
                if let Some(beam) = &self.beam {
                    beam.record(shared, frame, encoder);
                }
                match (deferred, self.shadow_due.replace(false)) {
                    (Some(d), true) if d.fits => {
                        let label = "ray-exact march";
                        dispatch_per_pixel(shared, frame, encoder, label, &d.march, &d.group);
                        self.record_shadow_pass(frame, encoder, true);
                        let label = "ray-exact shade";
                        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                            label: Some(label),
                            timestamp_writes: frame.timer.compute(label),
                        });
                        pass.set_pipeline(&d.shade);
                        pass.set_bind_group(0, &shared.frame_group, &[]);
                        pass.set_bind_group(1, &d.shade_group, &[]);
                        // The tiles the march left to it.
                        pass.dispatch_workgroups_indirect(
                            &self.marks.stamps,
                            self.marks.shade_dispatch(),
                        );
                    }
                    _ => dispatch_per_pixel(
                        shared,
                        frame,
                        encoder,
                        "ray-exact march",
                        march,
                        &self.group,
                    ),
                }
                let label = "ray-exact depth";
                match mode {
                    DepthMode::Blit => depth.record_blit(shared, frame, encoder, label, true),
                    DepthMode::Points => depth.record_with(shared, frame, encoder, label, true),
                    DepthMode::BlitLoad => depth.record(shared, frame, encoder, label),
                }
            }
            Variant::Fragment(pipeline) => super::common::draw_fullscreen(
                shared,
                frame,
                encoder,
                "ray-exact-fragment",
                pipeline,
                &self.group,
            ),
        }
        if let Levels::Paged(paged) = &self.levels {
            paged.record_feedback(encoder);
        }
    }

    fn frame_done(&mut self, shared: &Shared) -> anyhow::Result<()> {
        match &mut self.levels {
            Levels::Paged(paged) => paged.read_feedback(shared),
            Levels::Whole(_) => Ok(()),
        }
    }

    fn paged_terrain(&mut self) -> Option<&mut PagedTerrain> {
        self.paged_mut()
    }

    fn retained_bytes(&self) -> RetainedBytes {
        let depth = match &self.variant {
            Variant::Compute {
                depth, deferred, ..
            } => {
                let hits = deferred.as_ref().map_or(0, |d| d.hits.size());
                depth.bytes()
                    + hits
                    + self.marks.bytes()
                    + self.beam.as_ref().map_or(0, Beam::bytes)
            }
            Variant::Fragment(_) => self.marks.bytes(),
        };
        RetainedBytes {
            gpu: self.levels_bytes()
                + std::mem::size_of::<ExactParams>() as u64
                + self.stats.size()
                + depth,
            cpu: 0,
        }
    }

    fn depth_image(&self) -> Option<&wgpu::Texture> {
        match &self.variant {
            Variant::Compute { depth, .. } => Some(depth.texture()),
            Variant::Fragment(_) => None,
        }
    }
}

impl Drop for RayExact {
    fn drop(&mut self) {
        if !self.print_stats {
            return;
        }
        let _ = self.read_update_time();
        match self.stats() {
            Ok(s) => eprintln!(
                "{} stats: {} build_gpu_ms {:?} update_gpu_ms {:?} pyramid_bytes {}",
                self.name,
                serde_json::to_string(&s).unwrap_or_default(),
                self.pyramid().and_then(|p| p.build_gpu_ms),
                self.update_ms,
                self.pyramid().map_or(0, |p| p.layout.bytes)
            ),
            Err(e) => eprintln!("{} stats: {e}", self.name),
        }
    }
}

mod beam;
mod bindings;
mod cover;
mod deferred;
mod keep;
mod params;
pub mod replay;
mod shadow;
use crate::paged::PagedTerrain;
use beam::Beam;
pub use bindings::Levels;
use bindings::{core_entries, exact_pipeline, march_group};
use cover::{CoverKeep, CoverPlan};
use deferred::{Deferred, MARK_BLOCK, ShadowMarks};
use keep::ShadowKeep;
pub(crate) use params::{ExactParams, exact_params};
use shadow::ExactShadow;

#[cfg(test)]
mod tests;

/// `strata tune` measures it at its one configuration.
pub static SWEEP: super::knobs::Sweep = super::knobs::Sweep {
    order: 6,
    knob: "none",
    full: &[],
    quick: &[],
    at_paper_size: false,
};
