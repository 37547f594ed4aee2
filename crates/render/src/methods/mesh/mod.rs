//! `mesh` (§3.6): the greedy TIN of `strata-mesh`, rasterised.
//!
//! Setup fits the whole level (parallel, the method's preparation cost) and
//! uploads every chunk's three LODs into one index pool (`pool.rs`); the
//! fit itself is not kept. There is no vertex buffer: each u16 index names a
//! grid sample of its chunk and an altitude kind, and `mesh.wgsl` reads the
//! column from the shared terrain texture.
//!
//! Per frame: the chunk grid around the eye is walked in the unwrapped plane
//! (the map is a torus; a chunk near the edge is also seen at its wrapped
//! copies), each copy is frustum-culled by its box, takes LOD 0 within
//! [`LOD_DISTANCE`]`[0]`, LOD 1 within `[1]`, LOD 2 beyond (distance from the
//! eye to the box; superseded, see below), and the copies are drawn front to back, one
//! `draw_indexed` per LOD range with the copy's origin at its
//! `first_instance`. Borders are crack-free across LODs by construction.
//!
//! LOD by projected error (issue 17): a copy takes the coarsest LOD whose
//! max error (`τ·2^k` height units), seen square-on at the distance of the
//! copy's box from the eye, covers at most `mesh_lod_pixels` pixels
//! (default 1): resolution and field of view decide, not fixed distances.
//!
//! Colour is deferred where the adapter has compute (`deferred.rs`): the
//! raster pass writes depth and two words a pixel, one compute pass colours
//! every pixel; elsewhere, or with `mesh_fragment` (`mesh:0.5/fragment`),
//! each fragment is coloured in the raster pass by the same WGSL.
//!
//! Edits refit the dirty chunks from scratch (equal to a fresh fit of the
//! edited level) and rewrite only their slots, off the frame (`refits.rs`,
//! issue 35): `apply_edit` copies the dirty chunks' samples and queues
//! their fits on worker threads; each `prepare` uploads the fits finished
//! by then without waiting; [`Method::settle_edits`] waits for all of them.

use super::common::{begin_pass, forward_pipeline};
mod deferred;
mod fitter;
mod knobs;
pub mod paged;
mod paged_pool;
mod pool;
mod refits;
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{Shared, uniform_layout_entry};
use glam::{Vec3, Vec4};
pub use knobs::{KNOBS, SWEEP};
use pool::{Fitted, IndexPool, Slot};
use strata_camera::Camera;
use strata_level::model::decode_column;
use strata_level::{DirtyRect, Level};
use strata_mesh::{
    ChunkLayout, ChunkMesh, FitInSteps, FitOptions, LODS, LevelMesh, dirty_chunks,
    tolerance_for_quality,
};

/// The fixed distances the LOD pick used before issue 17 (LOD 0 within 250,
/// LOD 1 within 450, LOD 2 beyond): blind to resolution and field of view.
/// Kept for comparison only; [`lod_for`] replaced them.
pub const LOD_DISTANCE: [f32; 2] = [250.0, 450.0];

/// The coarsest LOD whose max error (`tolerance · 2^k` height units) seen
/// square-on at `distance` covers at most `pixels` on a camera with focal
/// length `focal_px`. A box the eye is inside (distance 0) takes LOD 0.
pub fn lod_for(tolerance: f64, distance: f32, focal_px: f32, pixels: f32) -> u8 {
    let mut lod = 0;
    for k in 1..LODS {
        let error = tolerance as f32 * (1u32 << k) as f32;
        if error * focal_px <= pixels * distance {
            lod = k as u8;
        }
    }
    lod
}

/// Per-draw record: the chunk copy's sample (0, 0) in unwrapped texels.
const DRAW_BYTES: u64 = 16;

/// The draw records' binding in group 1 (`draws` in `mesh.wgsl`; binding 1
/// is the paged terrain's levels in `paged.wgsl`).
const DRAWS_BINDING: u32 = 2;

/// One visible chunk copy.
#[derive(Clone, Copy, Debug)]
struct Draw {
    chunk: u32,
    lod: u8,
    distance: f32,
    origin: [i32; 2],
}

pub struct Mesh {
    pipeline: wgpu::RenderPipeline,
    group_layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    draws_buffer: wgpu::Buffer,
    /// Draw records `draws_buffer` holds.
    draws_capacity: u32,
    pool: IndexPool,
    slots: Vec<Slot>,
    layout: ChunkLayout,
    tolerance: f64,
    options: FitOptions,
    /// LOD tolerance in pixels (`mesh_lod_pixels`).
    lod_pixels: f32,
    /// The shaders' per-frame choices (the mesh's uniform).
    look: Look,
    /// The deferred frame (`None`: the fragment path).
    deferred: Option<deferred::Deferred>,
    /// This frame's visible copies, front to back (written by `prepare`).
    draws: Vec<Draw>,
    /// Edits' refits in flight (made at the first edit).
    refits: Option<refits::Refits>,
}

/// Altitude range of the vertices a chunk's indices name.
fn z_range(level: &Level, layout: &ChunkLayout, chunk: usize, mesh: &ChunkMesh) -> (u8, u8) {
    let (cx, cy) = layout.coords(chunk);
    let stride = layout.size_x + 1;
    let positions = stride * (layout.size_y + 1);
    let (wmask, hmask) = (level.width() - 1, level.height() - 1);
    let (mut lo, mut hi) = (u8::MAX, u8::MIN);
    for &i in &mesh.indices {
        let (x, y, kind) = strata_mesh::decode(i, stride, positions);
        let (heights, metas) = level.row((cy * layout.size_y + y) & hmask);
        let c = decode_column(
            heights,
            metas,
            ((cx * layout.size_x + x) & wmask) as usize,
            level.mid_rule,
        );
        let z = [c.low, c.high, c.mid][usize::from(kind.min(2))];
        lo = lo.min(z);
        hi = hi.max(z);
    }
    if lo > hi { (0, 0) } else { (lo, hi) }
}

fn draws_binding(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    capacity: u32,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let buffer = shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mesh draws"),
        size: u64::from(capacity.max(1)) * DRAW_BYTES,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group = shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mesh"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: DRAWS_BINDING,
                resource: buffer.as_entire_binding(),
            },
        ],
    });
    (buffer, group)
}

/// Fit `level` at `tolerance` on the rayon pool (reporting the fit's
/// progress to `shared`).
fn fit_all(shared: &Shared, level: &Level, tolerance: f64, options: FitOptions) -> LevelMesh {
    // Every 1/64th is enough for a progress bar and keeps the lock cold.
    let report = |done: usize, total: usize| {
        if done * 64 / total != (done - 1) * 64 / total {
            shared.progress.report("mesh", done as f32 / total as f32);
        }
    };
    let mesh = LevelMesh::fit_with_options(level, tolerance, options, &report);
    shared.progress.clear("mesh");
    mesh
}

/// Each chunk of `mesh` with its altitude range.
fn with_z_ranges(level: &Level, mesh: LevelMesh) -> (ChunkLayout, Vec<Fitted>) {
    let layout = mesh.layout;
    let chunks = mesh
        .chunks
        .into_iter()
        .enumerate()
        .map(|(i, m)| {
            let z = z_range(level, &layout, i, &m);
            (m, z)
        })
        .collect();
    (layout, chunks)
}

fn tolerance_of(settings: &MethodSettings) -> anyhow::Result<f64> {
    let q = settings.mesh_quality;
    tolerance_for_quality(f64::from(q))
        .ok_or_else(|| anyhow::anyhow!("mesh quality {q} is outside [0, 1] (max error 2^(4(1-q)))"))
}

fn options_of(settings: &MethodSettings) -> FitOptions {
    FitOptions {
        outline: settings.mesh_outline,
    }
}

fn lod_pixels_of(settings: &MethodSettings) -> anyhow::Result<f32> {
    let p = settings.mesh_lod_pixels;
    if p.is_finite() && p > 0.0 {
        Ok(p)
    } else {
        anyhow::bail!("mesh LOD tolerance {p} pixels is not a positive number")
    }
}

/// The fit a few chunks per step, then the upload (the browser's build).
struct MeshSteps {
    tolerance: f64,
    options: FitOptions,
    lod_pixels: f32,
    look: Look,
    fragment: bool,
    fit: Option<FitInSteps>,
}

/// Start the mesh's build in slices: [`super::contract::BuildSteps`].
pub fn build_in_steps(
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn super::contract::BuildSteps>> {
    Ok(Box::new(MeshSteps {
        tolerance: tolerance_of(settings)?,
        options: options_of(settings),
        lod_pixels: lod_pixels_of(settings)?,
        look: Look::of(settings),
        fragment: settings.mesh_fragment,
        fit: None,
    }))
}

impl super::contract::BuildSteps for MeshSteps {
    fn step(
        &mut self,
        shared: &Shared,
        level: &Level,
        budget_ms: f64,
    ) -> anyhow::Result<Option<Box<dyn Method>>> {
        let start = web_time::Instant::now();
        let fit = self.fit.get_or_insert_with(|| {
            LevelMesh::fit_in_steps_with(level, self.tolerance, self.options)
        });
        let done = fit.step(level, || start.elapsed().as_secs_f64() * 1e3 < budget_ms);
        shared.progress.report("mesh", fit.progress());
        if !done {
            return Ok(None);
        }
        shared.progress.clear("mesh");
        let mesh = self
            .fit
            .take()
            .and_then(FitInSteps::finish)
            .ok_or_else(|| anyhow::anyhow!("the mesh fit stopped before its last chunk"))?;
        let shading = (self.lod_pixels, self.look, self.fragment);
        from_fit(shared, level, self.tolerance, shading, mesh).map(Some)
    }
}

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let tolerance = tolerance_of(settings)?;
    let lod_pixels = lod_pixels_of(settings)?;
    let mesh = fit_all(shared, level, tolerance, options_of(settings));
    from_fit(
        shared,
        level,
        tolerance,
        (lod_pixels, Look::of(settings), settings.mesh_fragment),
        mesh,
    )
}

/// The choices the mesh's shaders take per frame from its uniform.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Look {
    /// The gradient-normal diagnostic (`mesh_gradient_normal`).
    gradient_normal: bool,
    /// Samples at texel centres, none moved to a wall (`mesh_texel_centres`).
    texel_centres: bool,
}

impl Look {
    pub(super) fn of(settings: &MethodSettings) -> Self {
        Look {
            gradient_normal: settings.mesh_gradient_normal,
            texel_centres: settings.mesh_texel_centres,
        }
    }
}

/// The method's uniform (`MeshParams` in `mesh_colour.wgsl`).
fn mesh_params(layout: &ChunkLayout, look: Look) -> [u32; 4] {
    let stride = layout.size_x + 1;
    [
        stride,
        stride * (layout.size_y + 1),
        u32::from(look.gradient_normal),
        u32::from(look.texel_centres),
    ]
}

/// Upload a fitted mesh and make the method; `shading` is the LOD tolerance
/// in pixels, the shaders' choices and the fragment path's.
fn from_fit(
    shared: &Shared,
    level: &Level,
    tolerance: f64,
    (lod_pixels, look, fragment): (f32, Look, bool),
    mesh: LevelMesh,
) -> anyhow::Result<Box<dyn Method>> {
    let options = mesh.options;
    let (layout, chunks) = with_z_ranges(level, mesh);
    let headroom = pool_headroom(&chunks);
    let (pool, slots) = IndexPool::build(&shared.device, &shared.queue, &chunks, headroom)?;
    drop(chunks);
    let device = &shared.device;
    let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("mesh"),
        entries: &[
            uniform_layout_entry(0),
            wgpu::BindGroupLayoutEntry {
                binding: DRAWS_BINDING,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    });
    let grid = mesh_params(&layout, look);
    let params = shared.uniform_buffer("mesh params", bytemuck::cast_slice(&grid));
    let draws_capacity = 256;
    let (draws_buffer, group) = draws_binding(shared, &group_layout, &params, draws_capacity);
    let pipeline = forward_pipeline(
        shared,
        "mesh",
        "mesh.wgsl",
        &group_layout,
        ("vs_mesh", "fs_mesh"),
    )?;
    let deferred = deferred_for(shared, fragment, &group_layout, &params)?;
    Ok(Box::new(Mesh {
        pipeline,
        group_layout,
        group,
        params,
        draws_buffer,
        draws_capacity,
        pool,
        slots,
        layout,
        tolerance,
        options,
        lod_pixels,
        look,
        deferred,
        draws: Vec::new(),
        refits: None,
    }))
}

/// The deferred frame where the adapter can take it and `fragment` (the
/// `mesh_fragment` setting) does not ask for the fragment path.
fn deferred_for(
    shared: &Shared,
    fragment: bool,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
) -> anyhow::Result<Option<deferred::Deferred>> {
    if fragment || !deferred::supported(shared) {
        return Ok(None);
    }
    deferred::Deferred::new(shared, layout, params).map(Some)
}

/// Spare tail for refits that grow: 1/16 of the level's indices, at least
/// room for a dense chunk (past it the pool grows by a GPU copy).
fn pool_headroom(chunks: &[Fitted]) -> u32 {
    let total: usize = chunks.iter().map(|(m, _)| m.indices.len()).sum();
    (total / 16).max(1 << 15) as u32
}

/// Whether the box `[lo, hi]` lies entirely outside one clip plane of `m`.
fn outside_frustum(m: &glam::Mat4, lo: Vec3, hi: Vec3) -> bool {
    let corners = (0..8).map(|k| {
        let p = Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        *m * Vec4::new(p.x, p.y, p.z, 1.0)
    });
    // Planes: -w <= x <= w, -w <= y <= w, 0 <= z <= w.
    let mut mask = [true; 6];
    for c in corners {
        let inside = [
            c.x >= -c.w,
            c.x <= c.w,
            c.y >= -c.w,
            c.y <= c.w,
            c.z >= 0.0,
            c.z <= c.w,
        ];
        for (o, i) in mask.iter_mut().zip(inside) {
            *o &= !i;
        }
    }
    mask.iter().any(|&o| o)
}

/// The chunk copies around `camera`'s eye whose box its frustum may see,
/// front to back, into `out`: the chunk grid walked in the unwrapped plane,
/// each copy's box from `z_of(chunk)`, its LOD by projected error.
fn visible_copies(
    layout: &ChunkLayout,
    camera: &Camera,
    (tolerance, lod_pixels): (f64, f32),
    mut z_of: impl FnMut(u32) -> (u8, u8),
    out: &mut Vec<Draw>,
) {
    out.clear();
    let m = camera.view_proj();
    let e = camera.position;
    // Farthest visible point: the far plane at the image corner.
    let (hw, hh) = (camera.width as f32 * 0.5, camera.height as f32 * 0.5);
    let reach =
        camera.far * (1.0 + (hw * hw + hh * hh) / (camera.focal_px * camera.focal_px)).sqrt();
    let (sx, sy) = (layout.size_x as i64, layout.size_y as i64);
    let (nx, ny) = (i64::from(layout.chunks_x), i64::from(layout.chunks_y));
    let range = |c: f32, size: i64| {
        let lo = ((c - reach - 1.0) as i64).div_euclid(size);
        let hi = ((c + reach) as i64).div_euclid(size);
        lo..=hi
    };
    for gy in range(e.y, sy) {
        for gx in range(e.x, sx) {
            let chunk = layout.index(gx.rem_euclid(nx) as u32, gy.rem_euclid(ny) as u32) as u32;
            let z = z_of(chunk);
            let origin = [(gx * sx) as i32, (gy * sy) as i32];
            // Samples stand at texel centres (0.5 .. size + 0.5), moved up
            // to half a texel to a wall beside them (`wall_shift` in
            // mesh.wgsl): 0 .. size + 1.
            let lo = Vec3::new(origin[0] as f32, origin[1] as f32, f32::from(z.0));
            let hi = lo + Vec3::new(sx as f32 + 1.0, sy as f32 + 1.0, f32::from(z.1 - z.0));
            if outside_frustum(&m, lo, hi) {
                continue;
            }
            let distance = (e.clamp(lo, hi) - e).length();
            let lod = lod_for(tolerance, distance, camera.focal_px, lod_pixels);
            out.push(Draw {
                chunk,
                lod,
                distance,
                origin,
            });
        }
    }
    out.sort_by(|a, b| a.distance.total_cmp(&b.distance));
}

/// Take `settings` in place where they keep the fit (`fit`: its tolerance
/// and options): the LOD tolerance and the normal diagnostic (rewriting
/// `params`). `Ok(false)`: a new quality or outline needs a new fit.
fn settings_in_place(
    shared: &Shared,
    settings: &MethodSettings,
    fit: (f64, FitOptions),
    (lod_pixels, look): (&mut f32, &mut Look),
    (layout, params): (&ChunkLayout, &wgpu::Buffer),
) -> anyhow::Result<bool> {
    let q = f64::from(settings.mesh_quality);
    let same_fit = tolerance_for_quality(q) == Some(fit.0) && options_of(settings) == fit.1;
    if same_fit {
        *lod_pixels = lod_pixels_of(settings)?;
        if Look::of(settings) != *look {
            *look = Look::of(settings);
            let grid = mesh_params(layout, *look);
            shared
                .queue
                .write_buffer(params, 0, bytemuck::cast_slice(&grid));
        }
    }
    Ok(same_fit)
}

impl Method for Mesh {
    fn name(&self) -> &'static str {
        "mesh"
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        // A new quality or outline is a new fit; the LOD tolerance, the
        // normal diagnostic and the colour path are taken in place.
        let same_fit = settings_in_place(
            shared,
            settings,
            (self.tolerance, self.options),
            (&mut self.lod_pixels, &mut self.look),
            (&self.layout, &self.params),
        )?;
        let fragment = self.deferred.is_none();
        if same_fit && settings.mesh_fragment != fragment {
            self.deferred = deferred_for(
                shared,
                settings.mesh_fragment,
                &self.group_layout,
                &self.params,
            )?;
        }
        Ok(same_fit)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        if let Some(d) = &mut self.deferred {
            d.resize(shared, &self.params);
        }
        Ok(())
    }

    fn draws_color_by_attachment(&self) -> bool {
        self.deferred.is_none()
    }

    fn store_color_into(
        &mut self,
        shared: &Shared,
        view: Option<&wgpu::TextureView>,
    ) -> anyhow::Result<bool> {
        let Some(d) = &mut self.deferred else {
            return Ok(view.is_none());
        };
        d.store_color_into(shared, &self.params, view);
        Ok(true)
    }

    fn apply_edit(
        &mut self,
        shared: &Shared,
        level: &Level,
        rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        let layout = ChunkLayout::of(level);
        if layout != self.layout {
            // Another map size: nothing local survives.
            let (layout, chunks) =
                with_z_ranges(level, fit_all(shared, level, self.tolerance, self.options));
            let headroom = pool_headroom(&chunks);
            let (pool, slots) = IndexPool::build(&shared.device, &shared.queue, &chunks, headroom)?;
            (self.layout, self.pool, self.slots) = (layout, pool, slots);
            // Refits in flight were of the old map.
            self.refits = None;
            let grid = mesh_params(&layout, self.look);
            shared
                .queue
                .write_buffer(&self.params, 0, bytemuck::cast_slice(&grid));
            return Ok(());
        }
        let ids = dirty_chunks(&layout, level.width(), level.height(), rects);
        let (tolerance, options) = (self.tolerance, self.options);
        self.refits
            .get_or_insert_with(|| refits::Refits::new(tolerance, options))
            .push(level, &layout, &ids)
    }

    fn settle_edits(&mut self, shared: &Shared) -> anyhow::Result<()> {
        match &mut self.refits {
            Some(r) => r.upload(shared, (&mut self.pool, &mut self.slots), true),
            None => Ok(()),
        }
    }

    fn pending_edits(&self) -> u64 {
        self.refits.as_ref().map_or(0, refits::Refits::pending)
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        if let Some(r) = &mut self.refits {
            r.upload(shared, (&mut self.pool, &mut self.slots), false)?;
        }
        let slots = &self.slots;
        visible_copies(
            &self.layout,
            camera,
            (self.tolerance, self.lod_pixels),
            |c| slots[c as usize].z,
            &mut self.draws,
        );
        let n = self.draws.len() as u32;
        if n > self.draws_capacity {
            let capacity = n.next_power_of_two();
            let (buffer, group) = draws_binding(shared, &self.group_layout, &self.params, capacity);
            (self.draws_buffer, self.group, self.draws_capacity) = (buffer, group, capacity);
        }
        if n > 0 {
            let records: Vec<[i32; 4]> = self
                .draws
                .iter()
                .map(|d| [d.origin[0], d.origin[1], 0, 0])
                .collect();
            shared
                .queue
                .write_buffer(&self.draws_buffer, 0, bytemuck::cast_slice(&records));
        }
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let Some(deferred) = &self.deferred else {
            let pass = begin_pass(shared, frame, encoder, "mesh");
            self.draw(shared, pass, &self.pipeline);
            return;
        };
        let pass = deferred.begin_raster(shared, frame, encoder);
        self.draw(shared, pass, &deferred.raster);
        deferred.record_colour(shared, frame, encoder);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        RetainedBytes {
            gpu: self.pool.gpu_bytes()
                + self.draws_buffer.size()
                + self.params.size()
                + self.deferred.as_ref().map_or(0, deferred::Deferred::bytes),
            cpu: self.pool.cpu_bytes()
                + (self.slots.capacity() * std::mem::size_of::<Slot>()
                    + self.draws.capacity() * std::mem::size_of::<Draw>()) as u64,
        }
    }
}

impl Mesh {
    /// Draw this frame's chunk copies into `pass` with `pipeline` (the
    /// fragment path's or the deferred raster pass's).
    fn draw(
        &self,
        shared: &Shared,
        mut pass: wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
    ) {
        if self.draws.is_empty() {
            return;
        }
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.set_index_buffer(self.pool.buffer.slice(..), wgpu::IndexFormat::Uint16);
        for (k, d) in self.draws.iter().enumerate() {
            let slot = &self.slots[d.chunk as usize];
            let k = k as u32;
            for &(s, e) in &slot.lods[usize::from(d.lod)] {
                if e > s {
                    pass.draw_indexed(slot.start + s..slot.start + e, 0, k..k + 1);
                }
            }
        }
    }
}

#[cfg(test)]
mod lod_tests {
    use super::lod_for;

    #[test]
    fn lod_follows_projected_error_not_distance() {
        // 320x200 at a 60-degree vertical field of view: focal 173 px.
        let focal = 100.0 / (30f32).to_radians().tan();
        // q = 0.5 (max error 4): LOD 1's 8 units cover 1 px at 1386 units,
        // LOD 2's 16 units at 2771; the old fixed pick took LOD 1 at 250.
        assert_eq!(lod_for(4.0, 0.0, focal, 1.0), 0);
        assert_eq!(lod_for(4.0, 250.0, focal, 1.0), 0);
        assert_eq!(lod_for(4.0, 1400.0, focal, 1.0), 1);
        assert_eq!(lod_for(4.0, 2800.0, focal, 1.0), 2);
        // Four times the resolution: finer at the same distance.
        assert_eq!(lod_for(4.0, 2800.0, 4.0 * focal, 1.0), 0);
        // A looser pixel tolerance or a coarser fit: coarser LODs sooner.
        assert_eq!(lod_for(4.0, 250.0, focal, 8.0), 1);
        assert_eq!(lod_for(4.0, 250.0, focal, 12.0), 2);
        assert_eq!(lod_for(1.0, 400.0, focal, 1.0), 1);
    }
}
