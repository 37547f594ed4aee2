//! `mesh`'s deferred frame (issue 36 item 3): the raster pass writes depth
//! and two words a covered pixel (`fs_mesh_gbuffer`: the TIN point's ray
//! parameter, its flat normal and vertex kind) into an `Rg32Uint` image, with
//! a fragment stage that does nothing else; then one compute pass
//! (`mesh_deferred.wgsl`) runs the colour step of `mesh_colour.wgsl` for
//! every pixel and writes the shared colour target through a storage view,
//! as the compute methods do. On the H100 the per-fragment colour walk was
//! half the mesh pass: the graphics path runs it on a few SMs and for every
//! fragment drawn, the compute pass on the whole chip once a pixel.
//!
//! Adapters without compute or storage textures keep the fragment path
//! (`fs_mesh`: the same colour step per fragment), and so does the paged
//! mesh (its stand-in boxes colour their fragments in the same pass).

use super::super::common::{begin_pass_into, compute_pipeline, dispatch_per_pixel};
use super::super::contract::Frame;
use crate::frame::{Shared, storage_texture_entry, texture_entry, uniform_layout_entry};

/// The G-buffer's format: two words a pixel (`mesh_pack` in `mesh_colour.wgsl`).
pub(super) const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

/// The G-buffer's binding in the colour pass's group 1, then the colour target's.
const GBUFFER_BINDING: u32 = 3;
const COLOR_BINDING: u32 = 4;

/// Whether `shared`'s adapter can take the deferred frame.
pub(super) fn supported(shared: &Shared) -> bool {
    shared.caps.compute && shared.caps.storage_textures
}

pub(super) struct Deferred {
    /// The raster pass writing depth and the G-buffer.
    pub(super) raster: wgpu::RenderPipeline,
    colour: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    gbuffer: wgpu::TextureView,
    bytes: u64,
    /// The caller's colour texture the colour pass stores into in place of
    /// the shared target (an embedding frame: `Method::store_color_into`).
    color_out: Option<wgpu::TextureView>,
}

/// The G-buffer at the shared targets' size, and the colour pass's group
/// (storing into the shared colour target).
fn targets(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
) -> (wgpu::TextureView, wgpu::BindGroup, u64) {
    let (_, gbuffer) = shared.target_texture(
        "mesh gbuffer",
        GBUFFER_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let group = colour_group(shared, layout, params, &gbuffer, &shared.color_view);
    let bytes = u64::from(shared.width) * u64::from(shared.height) * 8;
    (gbuffer, group, bytes)
}

/// The colour pass's group: the G-buffer in, `color` out.
fn colour_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    gbuffer: &wgpu::TextureView,
    color: &wgpu::TextureView,
) -> wgpu::BindGroup {
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("mesh colour"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: GBUFFER_BINDING,
                resource: wgpu::BindingResource::TextureView(gbuffer),
            },
            wgpu::BindGroupEntry {
                binding: COLOR_BINDING,
                resource: wgpu::BindingResource::TextureView(color),
            },
        ],
    })
}

impl Deferred {
    /// The deferred frame's pipelines and G-buffer; `raster_layout` is the
    /// mesh's group 1 (its parameters `params` and draw records).
    pub(super) fn new(
        shared: &Shared,
        raster_layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
    ) -> anyhow::Result<Self> {
        let raster = super::super::common::forward_pipeline_into(
            shared,
            "mesh gbuffer",
            "mesh.wgsl",
            raster_layout,
            ("vs_mesh", "fs_mesh_gbuffer"),
            GBUFFER_FORMAT,
        )?;
        let layout = shared
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("mesh colour"),
                entries: &[
                    uniform_layout_entry(0),
                    texture_entry(
                        GBUFFER_BINDING,
                        wgpu::TextureSampleType::Uint,
                        wgpu::TextureViewDimension::D2,
                    ),
                    storage_texture_entry(COLOR_BINDING, crate::frame::COLOR_FORMAT),
                ],
            });
        let colour = compute_pipeline(
            shared,
            "mesh colour",
            "mesh_deferred.wgsl",
            &shared.pipeline_layout("mesh colour", &[&layout]),
            "cs_mesh_colour",
        )?;
        let (gbuffer, group, bytes) = targets(shared, &layout, params);
        Ok(Deferred {
            raster,
            colour,
            layout,
            group,
            gbuffer,
            bytes,
            color_out: None,
        })
    }

    /// The shared targets changed size: a new G-buffer and colour binding.
    pub(super) fn resize(&mut self, shared: &Shared, params: &wgpu::Buffer) {
        (self.gbuffer, self.group, self.bytes) = targets(shared, &self.layout, params);
        self.color_out = None;
    }

    /// Store colour into `view` (the caller's `Rgba8Unorm` storage texture of
    /// the targets' size) or, with `None`, the shared colour target.
    pub(super) fn store_color_into(
        &mut self,
        shared: &Shared,
        params: &wgpu::Buffer,
        view: Option<&wgpu::TextureView>,
    ) {
        if self.color_out.as_ref() == view {
            return;
        }
        self.color_out = view.cloned();
        let color = self.color_out.as_ref().unwrap_or(&shared.color_view);
        self.group = colour_group(shared, &self.layout, params, &self.gbuffer, color);
    }

    /// Begin the raster pass: the G-buffer cleared to "no triangle" (0),
    /// the shared depth target to far.
    pub(super) fn begin_raster<'e>(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &'e mut wgpu::CommandEncoder,
    ) -> wgpu::RenderPass<'e> {
        let color = wgpu::RenderPassColorAttachment {
            view: &self.gbuffer,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        };
        begin_pass_into(shared, frame, encoder, "mesh", color)
    }

    /// Record the colour pass (after the raster pass).
    pub(super) fn record_colour(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        dispatch_per_pixel(
            shared,
            frame,
            encoder,
            "mesh colour",
            &self.colour,
            &self.group,
        );
    }

    /// Bytes of the G-buffer.
    pub(super) fn bytes(&self) -> u64 {
        self.bytes
    }
}
