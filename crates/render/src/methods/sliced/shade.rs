//! Plain `sliced`'s deferred frame: the slices write each pixel's nearest
//! kept slice (its rank + 1, `fs_slice_mark_steep`) and depth, and one pass
//! then shades that slice's point once a pixel (`shaders/sliced_shade.wgsl`),
//! before the gap pass draws over it.
//!
//! Why: a slice fragment decides in its shader whether it is kept (it
//! discards air), so its depth is written after the shader has run, and
//! every solid slice a pixel's ray crosses behind the nearest one was shaded
//! too unless an earlier draw had already put a nearer depth there. The
//! marks cost a word per fragment instead of the shading: on the H100 the
//! marks alone took 3.9-6.5 ms on the steep views where the plain slice
//! pass took 7.1-12.2 (`bench/issue36-sliced/gaps/h100-beam/`).
//! `sliced:N/forward` keeps the shading in the slice fragments, for A/B.
//!
//! The shading runs as a compute pass where the adapter has compute and
//! storage textures and the frame's targets are the shared ones (the whole
//! chip, not the graphics path's few SMs); otherwise as a full-screen
//! triangle in the pass that then draws the gaps. Where the gap pass has
//! its beam, the compute pass walks the gaps itself on frames whose rows
//! walk (`sliced_shade_walk.wgsl`) and a depth copy puts the walks' depths
//! in the depth target: no gap pass on the graphics path.

use super::super::common::{
    DepthCopy, begin_pass_over, begin_pass_with_depth, compute_pipeline, dispatch_per_pixel,
    fullscreen_pipeline_colour_only,
};
use super::super::contract::Frame;
use super::super::march_beam::MarchBeam;
use super::refine::MARK_FORMAT;
use super::tiles::SliceTiles;
use crate::frame::{
    COLOR_FORMAT, Shared, storage_texture_entry, texture_entry, uniform_layout_entry,
};

/// Bindings of the shading's group 1: the footprint uniform (slice count),
/// the marks, and (compute) the colour target; the walking pass adds the
/// tile grid (1), the beam's starts (2), the block maxima (3), the slices'
/// depth (6) and the depth image it writes (7).
const MARKS_BINDING: u32 = 4;
const COLOR_BINDING: u32 = 5;
const DEPTH_BINDING: u32 = 6;
const DEPTH_OUT_BINDING: u32 = 7;

/// What draws over the shaded slices in the same frame (the gap pass's rows).
pub type DrawOver<'a> = &'a dyn Fn(&mut wgpu::RenderPass<'_>);

pub struct Shade {
    /// The full-screen triangle's pipeline and group (every adapter).
    fragment: (wgpu::RenderPipeline, wgpu::BindGroupLayout),
    /// The compute pipeline and its layout, where the adapter has both.
    compute: Option<(wgpu::ComputePipeline, wgpu::BindGroupLayout)>,
    /// The compute pass that also walks the gaps (with `compute`, where the
    /// gap pass has a beam).
    walk: Option<ComputeWalk>,
    targets: Targets,
}

/// `cs_sliced_shade_walk`: its pipeline, layout and group, and the depth
/// image it writes with the copy that puts it in the depth target.
struct ComputeWalk {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    depth: DepthCopy,
}

/// What the walking pass reads besides the marks: the slicer's tiles (the
/// grid uniform, the block maxima) and the gap pass's beam (the starts).
pub type WalkInputs<'a> = (&'a SliceTiles, &'a MarchBeam);

/// The marks image and the groups that read it, at the targets' size.
struct Targets {
    marks: wgpu::TextureView,
    fragment_group: wgpu::BindGroup,
    compute_group: Option<wgpu::BindGroup>,
    bytes: u64,
}

fn layout(device: &wgpu::Device, label: &str, storage: bool) -> wgpu::BindGroupLayout {
    let mut entries = vec![
        uniform_layout_entry(0),
        texture_entry(
            MARKS_BINDING,
            wgpu::TextureSampleType::Uint,
            wgpu::TextureViewDimension::D2,
        ),
    ];
    if storage {
        entries.push(storage_texture_entry(COLOR_BINDING, COLOR_FORMAT));
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

fn group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    marks: &wgpu::TextureView,
    color: Option<&wgpu::TextureView>,
) -> wgpu::BindGroup {
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: MARKS_BINDING,
            resource: wgpu::BindingResource::TextureView(marks),
        },
    ];
    entries.extend(color.map(|view| wgpu::BindGroupEntry {
        binding: COLOR_BINDING,
        resource: wgpu::BindingResource::TextureView(view),
    }));
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sliced shade"),
        layout,
        entries: &entries,
    })
}

impl ComputeWalk {
    fn new(
        shared: &Shared,
        params: &wgpu::Buffer,
        marks: &wgpu::TextureView,
        inputs: WalkInputs<'_>,
    ) -> anyhow::Result<Self> {
        let device = &shared.device;
        let uint_texture = |binding| {
            texture_entry(
                binding,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2,
            )
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sliced shade walk"),
            entries: &[
                uniform_layout_entry(0),
                uniform_layout_entry(1),
                MarchBeam::compute_layout_entry(),
                uint_texture(3),
                uint_texture(MARKS_BINDING),
                storage_texture_entry(COLOR_BINDING, COLOR_FORMAT),
                texture_entry(
                    DEPTH_BINDING,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2,
                ),
                storage_texture_entry(DEPTH_OUT_BINDING, wgpu::TextureFormat::R32Float),
            ],
        });
        let pipeline = compute_pipeline(
            shared,
            "sliced shade",
            "sliced_shade_walk.wgsl",
            &shared.pipeline_layout("sliced shade walk", &[&layout]),
            "cs_sliced_shade_walk",
        )?;
        let depth = DepthCopy::new(shared, "sliced", "sliced depth copy")?;
        let group = Self::group(shared, &layout, params, marks, inputs, &depth);
        Ok(ComputeWalk {
            pipeline,
            layout,
            group,
            depth,
        })
    }

    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        marks: &wgpu::TextureView,
        (tiles, beam): WalkInputs<'_>,
        depth: &DepthCopy,
    ) -> wgpu::BindGroup {
        let view = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        // The depth copy's bindings are the colour target (the shared one)
        // and its depth image.
        let [color, depth_out] = depth.bindings(shared, COLOR_BINDING);
        let depth_out = wgpu::BindGroupEntry {
            binding: DEPTH_OUT_BINDING,
            ..depth_out
        };
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sliced shade walk"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: tiles.params.as_entire_binding(),
                },
                beam.binding(),
                view(3, tiles.blocks_view()),
                view(MARKS_BINDING, marks),
                color,
                view(DEPTH_BINDING, &shared.depth_view),
                depth_out,
            ],
        })
    }
}

impl Shade {
    /// `params`: the slicer's footprint uniform (its slice count); `walk`:
    /// what the compute pass needs to walk the gaps too (none: the gap pass
    /// walks them).
    pub fn new(
        shared: &Shared,
        params: &wgpu::Buffer,
        walk: Option<WalkInputs<'_>>,
    ) -> anyhow::Result<Self> {
        let device = &shared.device;
        let fragment_layout = layout(device, "sliced shade", false);
        let fragment = fullscreen_pipeline_colour_only(
            shared,
            "sliced shade",
            "sliced_shade.wgsl",
            &shared.pipeline_layout("sliced shade", &[&fragment_layout]),
            "fs_sliced_shade",
        )?;
        let compute = if shared.caps.compute && shared.caps.storage_textures {
            let compute_layout = layout(device, "sliced shade compute", true);
            let pipeline = compute_pipeline(
                shared,
                "sliced shade",
                "sliced_shade_compute.wgsl",
                &shared.pipeline_layout("sliced shade compute", &[&compute_layout]),
                "cs_sliced_shade",
            )?;
            Some((pipeline, compute_layout))
        } else {
            None
        };
        let targets = Self::targets(shared, params, &fragment_layout, compute.as_ref());
        let walk = match walk.filter(|_| compute.is_some() && shared.caps.depth_loads) {
            Some(inputs) => Some(ComputeWalk::new(shared, params, &targets.marks, inputs)?),
            None => None,
        };
        Ok(Shade {
            fragment: (fragment, fragment_layout),
            compute,
            walk,
            targets,
        })
    }

    fn targets(
        shared: &Shared,
        params: &wgpu::Buffer,
        fragment_layout: &wgpu::BindGroupLayout,
        compute: Option<&(wgpu::ComputePipeline, wgpu::BindGroupLayout)>,
    ) -> Targets {
        let (_, marks) = shared.target_texture(
            "sliced marks",
            MARK_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        Targets {
            fragment_group: group(shared, fragment_layout, params, &marks, None),
            compute_group: compute
                .map(|(_, layout)| group(shared, layout, params, &marks, Some(&shared.color_view))),
            marks,
            bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
        }
    }

    /// A marks image at the shared targets' new size (`walk`: the walking
    /// pass's inputs, resized before).
    pub fn resize(&mut self, shared: &Shared, params: &wgpu::Buffer, walk: Option<WalkInputs<'_>>) {
        self.targets = Self::targets(shared, params, &self.fragment.1, self.compute.as_ref());
        if let (Some(w), Some(inputs)) = (&mut self.walk, walk) {
            w.depth.resize(shared);
            w.group = ComputeWalk::group(
                shared,
                &w.layout,
                params,
                &self.targets.marks,
                inputs,
                &w.depth,
            );
        }
    }

    /// The slice pass's colour target: the marks, cleared to 0 (no slice).
    pub fn marks_attachment(&self) -> wgpu::RenderPassColorAttachment<'_> {
        wgpu::RenderPassColorAttachment {
            view: &self.targets.marks,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        }
    }

    /// After the slice pass: every pixel's colour (the sky where no slice
    /// was kept), then the gaps: walked in the compute pass where it can
    /// (`gaps`, the gap pass's drawing, is then not called), else `gaps` in
    /// a pass over the frame's colour and depth.
    pub fn record(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        gaps: Option<DrawOver<'_>>,
    ) {
        let own_targets = frame.targets.color.is_none() && frame.targets.depth.is_none();
        if let Some(walk) = self.walk.as_ref().filter(|_| own_targets && gaps.is_some()) {
            dispatch_per_pixel(
                shared,
                frame,
                encoder,
                "sliced shade",
                &walk.pipeline,
                &walk.group,
            );
            walk.depth
                .copy_into_target(shared, frame, encoder, "sliced depth copy", false);
            return;
        }
        let compute = self
            .compute
            .as_ref()
            .zip(self.targets.compute_group.as_ref())
            .filter(|_| frame.targets.color.is_none());
        if let Some(((pipeline, _), group)) = compute {
            dispatch_per_pixel(shared, frame, encoder, "sliced shade", pipeline, group);
            if let Some(gaps) = gaps {
                let mut pass = begin_pass_over(shared, frame, encoder, "sliced gaps");
                pass.set_bind_group(0, &shared.frame_group, &[]);
                gaps(&mut pass);
            }
            return;
        }
        // The colour cleared to sky, the slices' depth kept.
        let mut pass =
            begin_pass_with_depth(shared, frame, encoder, "sliced shade", wgpu::LoadOp::Load);
        pass.set_pipeline(&self.fragment.0);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.targets.fragment_group, &[]);
        pass.draw(0..3, 0..1);
        if let Some(gaps) = gaps {
            gaps(&mut pass);
        }
    }

    /// Bytes of the marks image and the walking pass's depth image.
    pub fn gpu_bytes(&self) -> u64 {
        self.targets.bytes + self.walk.as_ref().map_or(0, |w| w.depth.bytes())
    }
}
