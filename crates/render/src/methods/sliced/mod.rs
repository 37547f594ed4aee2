//! `sliced` (§3.3): `slices` horizontal quads over the camera's footprint at
//! z = 256 - k·256/N (k = 1..N), one instanced draw; each fragment keeps its
//! point where the decoded column is solid (floor column or slab) and
//! discards it elsewhere. Depth-tested like any geometry. Each slice is drawn
//! as one quad per 32 x 32 tile of the footprint, and tiles that are all air
//! at the slice's altitude are dropped (`tiles.rs`).
//!
//! `sliced:N/refine` draws the same slices into a marks image instead and
//! adds one full-screen pass that puts the exact surface crossing behind
//! each pixel's nearest kept slice (`refine.rs`).
//!
//! Plain `sliced` draws its slices as marks (the nearest kept slice's rank)
//! and shades each pixel's once afterwards (`shade.rs`); `sliced:N/forward`
//! shades every kept fragment in the slice pass, as the paper's slicer does.
//!
//! Grazing rays cross the slices several texels apart, and a thin wall or a
//! peak between two crossings is missed. Plain `sliced` walks those rays'
//! gaps once per pixel after the slices, over the bands of rows where they
//! lie (`rows.rs`, `gaps.rs`); `sliced:N/fragwalk` walks each slice
//! fragment's own gap instead, as issue 36 first did. The refined slicer's
//! marks walk theirs in the fragment, on frames that have such rows.

use super::common::{
    begin_pass, begin_pass_into, forward_pipeline, forward_pipeline_into, index_buffer,
};
use super::forward::{self, Z_MAX};
use super::march_beam::MarchBeam;
mod gaps;
mod knobs;
mod refine;
mod rows;
mod shade;
mod tiles;
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{Shared, texture_entry, uniform_layout_entry};
use gaps::Gaps;
pub use knobs::{KNOBS, SWEEP};
use refine::{MARK_FORMAT, Refine};
use rows::row_bands;
use shade::Shade;
use strata_camera::Camera;
use strata_level::Level;
use tiles::SliceTiles;

/// Most texel columns a slice fragment whose point is air walks along its
/// pixel's ray towards it from the previous slice's crossing, where grazing
/// rays cross the slices more than two texels apart (`sliced.wgsl::slice_hit`:
/// `sliced:N/fragwalk` and the refined slicer's marks),
/// at most the culling tiles' side. 32: the slices cover rays without gaps
/// down to slopes of about 1/48 at 512 slices (the first slice a ray meets
/// walks from the eye however far; the rays of longer gaps are left to the
/// refine pass's whole-ray search).
pub const GAP_TEXELS: u32 = 32;

/// More slices than this sample far below the 256 quantised altitudes and
/// only multiply overdraw; refuse them rather than draw for seconds.
pub const MAX_SLICES: u32 = 1 << 16;

pub struct Sliced {
    /// The slices: each fragment's point test (`fs_sliced_steep`, then the
    /// gap pass), its test and gap walk (`fs_sliced`, `/fragwalk`), or its
    /// mark (`fs_slice_mark`, refined).
    pipeline: wgpu::RenderPipeline,
    /// The refined slicer's marks without the walk (`fs_slice_mark_steep`),
    /// on frames where no ray can walk; `None` otherwise.
    steep_marks: Option<wgpu::RenderPipeline>,
    /// Plain `sliced`'s gap pass (not with `/fragwalk` or refined).
    gaps: Option<Gaps>,
    /// Plain `sliced`'s deferred shading (not with `/forward`, `/fragwalk`
    /// or refined): `pipeline` writes marks.
    shade: Option<Shade>,
    /// This frame's bands of rows where a ray may walk, top to bottom.
    walking_rows: Vec<std::ops::Range<u32>>,
    /// `settings.march_beam` at creation (a change rebuilds).
    march_beam: bool,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    /// The tile maxima that drop air tiles, and the grid over the footprint.
    tiles: SliceTiles,
    /// Tiles per slice in the next draw.
    tiles_per_slice: u32,
    /// [`QUAD_INDICES`].
    quad: wgpu::Buffer,
    slices: u32,
    /// `sliced_refine`: `pipeline` marks the kept slices and this pass refines.
    refine: Option<Refine>,
    /// Whether the footprint is empty this frame (nothing to draw).
    empty: bool,
}

fn checked_slices(settings: &MethodSettings) -> anyhow::Result<u32> {
    let slices = settings.slices;
    if slices == 0 || slices > MAX_SLICES {
        anyhow::bail!("slices must be in 1..={MAX_SLICES} (got {slices})");
    }
    Ok(slices)
}

/// The slices' layout: uniforms at bindings 0 and 1 (the footprint, the
/// tile grid), integer textures at 2 and 3 (the tile and block maxima).
fn uniforms_and_textures_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let uint_texture = |binding| {
        texture_entry(
            binding,
            wgpu::TextureSampleType::Uint,
            wgpu::TextureViewDimension::D2,
        )
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            uniform_layout_entry(0),
            uniform_layout_entry(1),
            uint_texture(2),
            uint_texture(3),
        ],
    })
}

/// The layout of a per-pixel walk's group (`sliced_walk.wgsl`, the gap and
/// refine passes): the footprint and tile grid uniforms (0, 1), the block
/// maxima (3), the beam's tile starts (2, with a beam) and `textures`, more
/// integer textures (the refine pass's marks).
fn walk_layout(
    device: &wgpu::Device,
    label: &str,
    beam: bool,
    textures: &[u32],
) -> wgpu::BindGroupLayout {
    let uint_texture = |binding| {
        texture_entry(
            binding,
            wgpu::TextureSampleType::Uint,
            wgpu::TextureViewDimension::D2,
        )
    };
    let mut entries = vec![
        uniform_layout_entry(0),
        uniform_layout_entry(1),
        uint_texture(3),
    ];
    entries.extend(textures.iter().map(|&b| uint_texture(b)));
    if beam {
        entries.push(MarchBeam::layout_entry());
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// A group of [`walk_layout`]: `textures` the views at its extra bindings.
fn walk_group(
    device: &wgpu::Device,
    (label, layout): (&str, &wgpu::BindGroupLayout),
    (params, tiles): (&wgpu::Buffer, &SliceTiles),
    beam: Option<&MarchBeam>,
    textures: &[(u32, &wgpu::TextureView)],
) -> wgpu::BindGroup {
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: tiles.params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::TextureView(tiles.blocks_view()),
        },
    ];
    entries.extend(
        textures
            .iter()
            .map(|&(binding, view)| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(view),
            }),
    );
    entries.extend(beam.map(MarchBeam::binding));
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The beam of a per-pixel walk, where the adapter runs it and the settings
/// keep it (`sliced:512/nobeam`: the walks begin at the near plane).
fn walk_beam(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
    label: &'static str,
) -> anyhow::Result<Option<MarchBeam>> {
    if settings.march_beam && MarchBeam::available(shared, level) {
        Ok(Some(MarchBeam::new(shared, level, label)?))
    } else {
        Ok(None)
    }
}

/// The slices' group: the footprint uniform, the tile grid uniform and the
/// tile maxima.
fn slices_binding(
    shared: &Shared,
    params: &wgpu::Buffer,
    tiles: &SliceTiles,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let device = &shared.device;
    let layout = uniforms_and_textures_layout(device, "sliced");
    let group = crate::frame::bind_group(
        device,
        "sliced",
        &layout,
        &[
            params.as_entire_binding(),
            tiles.params.as_entire_binding(),
            wgpu::BindingResource::TextureView(tiles.view()),
            wgpu::BindingResource::TextureView(tiles.blocks_view()),
        ],
    );
    (layout, group)
}

/// A quad's two triangles over its corners (bits: x 1, y 2), as
/// `sliced.wgsl` places them.
const QUAD_INDICES: [u16; 6] = [0, 1, 2, 2, 1, 3];

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let slices = checked_slices(settings)?;
    let params = shared.uniform_buffer(
        "sliced",
        bytemuck::bytes_of(&forward::FootprintParams::default()),
    );
    let tiles = SliceTiles::new(shared, level);
    let (layout, group) = slices_binding(shared, &params, &tiles);
    let marks = |entry| {
        forward_pipeline_into(
            shared,
            "sliced marks",
            "sliced.wgsl",
            &layout,
            ("vs_sliced", entry),
            MARK_FORMAT,
        )
    };
    let plain = |entry| {
        forward_pipeline(
            shared,
            "sliced",
            "sliced.wgsl",
            &layout,
            ("vs_sliced", entry),
        )
    };
    let walk_in_fragments = settings.sliced_fragment_walk;
    let mut shade = None;
    let (pipeline, steep_marks, gaps, refine) = if settings.sliced_refine {
        let steep = if walk_in_fragments {
            None
        } else {
            Some(marks("fs_slice_mark_steep")?)
        };
        let refine = Refine::new(shared, level, settings, &params, &tiles)?;
        (marks("fs_slice_mark")?, steep, None, Some(refine))
    } else if walk_in_fragments {
        (plain("fs_sliced")?, None, None, None)
    } else {
        let gaps = Gaps::new(shared, level, settings, &params, &tiles)?;
        if settings.sliced_forward_shading {
            (plain("fs_sliced_steep")?, None, Some(gaps), None)
        } else {
            let walk = gaps.beam().map(|beam| (&tiles, beam));
            shade = Some(Shade::new(shared, &params, walk)?);
            (marks("fs_slice_mark_steep")?, None, Some(gaps), None)
        }
    };
    Ok(Box::new(Sliced {
        pipeline,
        steep_marks,
        gaps,
        shade,
        walking_rows: Vec::new(),
        march_beam: settings.march_beam,
        group,
        params,
        tiles,
        tiles_per_slice: 1,
        quad: index_buffer(shared, "sliced quad", &QUAD_INDICES),
        slices,
        refine,
        empty: true,
    }))
}

/// Whether `settings` take plain `sliced`'s deferred shading ([`Shade`]).
fn deferred(settings: &MethodSettings) -> bool {
    !settings.sliced_refine && !settings.sliced_fragment_walk && !settings.sliced_forward_shading
}

/// The slice index (0 = the top one, z = 256 - 256/N) nearest altitude `z`.
fn slice_near(z: f32, slices: u32) -> u32 {
    let k = ((Z_MAX - z) * slices as f32 / Z_MAX).round() - 1.0;
    k.clamp(0.0, (slices - 1) as f32) as u32
}

impl Method for Sliced {
    fn name(&self) -> &'static str {
        "sliced"
    }

    fn apply_edit(
        &mut self,
        shared: &Shared,
        level: &Level,
        rects: &[strata_level::DirtyRect],
    ) -> anyhow::Result<()> {
        self.tiles.apply_edit(shared, level, rects);
        if let Some(gaps) = &mut self.gaps {
            gaps.apply_edit(rects);
        }
        if let Some(refine) = &mut self.refine {
            refine.apply_edit(rects);
        }
        Ok(())
    }

    fn update_settings(
        &mut self,
        _shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        let slices = checked_slices(settings)?;
        if settings.sliced_refine != self.refine.is_some()
            || settings.march_beam != self.march_beam
            || settings.sliced_fragment_walk != (self.gaps.is_none() && self.steep_marks.is_none())
            || deferred(settings) != self.shade.is_some()
        {
            // Another pipeline: a rebuild.
            return Ok(false);
        }
        self.slices = slices;
        Ok(true)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        if let Some(refine) = &mut self.refine {
            refine.resize(shared, &self.params, &self.tiles);
        }
        if let Some(gaps) = &mut self.gaps {
            gaps.resize(shared, &self.params, &self.tiles);
        }
        if let Some(shade) = &mut self.shade {
            let walk = self.gaps.as_ref().and_then(Gaps::beam);
            shade.resize(shared, &self.params, walk.map(|beam| (&self.tiles, beam)));
        }
        Ok(())
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        // The quads span the bound; the sample count clamp is painted's concern.
        let mut f = forward::footprint(camera, None);
        self.empty = f.size[0] == 0 || f.size[1] == 0;
        f.count[1] = self.slices;
        f.count[2] = slice_near(camera.position.z, self.slices);
        f.count[3] = GAP_TEXELS.min(self.tiles.side());
        self.walking_rows = row_bands(camera, self.slices)
            .into_iter()
            .filter(|band| band.walks)
            .map(|band| band.rows.start.min(shared.height)..band.rows.end.min(shared.height))
            .filter(|rows| !rows.is_empty())
            .collect();
        if let Some(gaps) = &mut self.gaps {
            gaps.prepare(shared);
        }
        if let Some(refine) = &mut self.refine {
            refine.prepare(shared);
        }
        self.tiles_per_slice = self
            .tiles
            .prepare(shared, [f.origin[0], f.origin[1]], f.extent());
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&f));
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if let Some(refine) = &self.refine {
            self.record_marks(shared, frame, encoder, refine.marks_attachment());
            refine.record(shared, frame, encoder);
            return;
        }
        // The beam's pyramid follows every frame's edits; the beam and the
        // gap pass run on frames with walking rows only.
        let walks = !self.walking_rows.is_empty();
        if let Some(gaps) = &self.gaps {
            gaps.record_beam(shared, frame, encoder, walks);
        }
        let draw_gaps = self
            .gaps
            .as_ref()
            .filter(|_| walks && !self.empty)
            .map(|gaps| {
                move |pass: &mut wgpu::RenderPass<'_>| {
                    for rows in &self.walking_rows {
                        gaps.draw(shared, pass, rows.clone());
                    }
                }
            });
        if let Some(shade) = &self.shade {
            self.record_marks(shared, frame, encoder, shade.marks_attachment());
            shade.record(shared, frame, encoder, draw_gaps.as_ref().map(|f| f as _));
            return;
        }
        let mut pass = begin_pass(shared, frame, encoder, "sliced");
        if self.empty {
            return;
        }
        self.draw_slices(shared, &mut pass);
        if let Some(draw_gaps) = &draw_gaps {
            draw_gaps(&mut pass);
        }
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The 48-byte footprint uniform, the quad's 12 bytes of indices, the
        // tile maxima (kept on the CPU too, for edits), the refined slicer's
        // marks image, the gap pass's beam (its pyramid and starts), and the
        // plain slicer's marks image.
        let refine = self.refine.as_ref().map(Refine::retained_bytes);
        let quad = std::mem::size_of_val(&QUAD_INDICES) as u64;
        RetainedBytes {
            gpu: forward::PARAMS_BYTES
                + quad
                + self.tiles.gpu_bytes()
                + refine.map_or(0, |r| r.gpu)
                + self.gaps.as_ref().map_or(0, Gaps::gpu_bytes)
                + self.shade.as_ref().map_or(0, Shade::gpu_bytes),
            cpu: self.tiles.cpu_bytes(),
        }
    }
}

impl Sliced {
    /// The slices' pass into a marks image (`marks`, the refined slicer's
    /// or the deferred shading's) and the depth target.
    fn record_marks(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        marks: wgpu::RenderPassColorAttachment<'_>,
    ) {
        let mut pass = begin_pass_into(shared, frame, encoder, "sliced", marks);
        if !self.empty {
            self.draw_slices(shared, &mut pass);
        }
    }

    /// The slices, one instanced draw of a quad per slice and tile (slices
    /// nearest the eye's altitude first).
    fn draw_slices(&self, shared: &Shared, pass: &mut wgpu::RenderPass<'_>) {
        let pipeline = match &self.steep_marks {
            Some(steep) if self.walking_rows.is_empty() => steep,
            _ => &self.pipeline,
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        // At most MAX_SLICES x MAX_TILES_PER_SLICE = 2^30 instances.
        pass.set_index_buffer(self.quad.slice(..), wgpu::IndexFormat::Uint16);
        pass.draw_indexed(0..6, 0, 0..self.slices * self.tiles_per_slice);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slice_altitudes_follow_the_paper() {
        // N = 256: slice k sits at 256 - k, so index j at 255 - j.
        assert_eq!(slice_near(255.0, 256), 0);
        assert_eq!(slice_near(0.0, 256), 255);
        assert_eq!(slice_near(100.0, 512), 311);
        assert_eq!(slice_near(1000.0, 512), 0);
        assert_eq!(slice_near(-5.0, 512), 511);
    }
}
