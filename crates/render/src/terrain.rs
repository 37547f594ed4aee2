//! The terrain on the GPU, in the one layout every method reads.
//!
//! An `Rgba8Uint` 2D texture array with one texel per texel *pair* of the map:
//! `(height even, meta even, height odd, meta odd)`, so one fetch decodes a
//! column (pairs decode together anyway). Rows are split into layers of
//! `min(height, 2048)` rows: a 2048x16384 map is 8 layers of 1024x2048,
//! within WebGPU's default limits (2D side <= 8192, <= 256 layers). WGSL:
//! `surface.wgsl::terrain_pair` wraps x and y and picks the layer.

use strata_level::{DirtyRect, Level};

/// Rows per texture layer (at most; fewer for shorter maps).
pub const MAX_LAYER_ROWS: u32 = 2048;

/// Where a map's rows go on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TerrainLayout {
    pub map_width: u32,
    pub map_height: u32,
    /// Texture width: one texel per pair.
    pub pairs: u32,
    pub layer_rows: u32,
    pub layers: u32,
}

impl TerrainLayout {
    pub fn new(level: &Level, limits: &wgpu::Limits) -> anyhow::Result<Self> {
        let (w, h) = (level.width(), level.height());
        let pairs = w / 2;
        let layer_rows = h.min(MAX_LAYER_ROWS);
        let layers = h / layer_rows;
        let max = limits.max_texture_dimension_2d;
        if pairs > max || layers > limits.max_texture_array_layers {
            anyhow::bail!(
                "map {w}x{h} needs a {pairs}x{layer_rows}x{layers} terrain texture array; \
                 this device allows sides up to {max} and {} layers",
                limits.max_texture_array_layers
            );
        }
        Ok(TerrainLayout {
            map_width: w,
            map_height: h,
            pairs,
            layer_rows,
            layers,
        })
    }

    /// log2 of the rows per layer (the shader splits y with a shift and a mask).
    pub fn layer_shift(&self) -> u32 {
        self.layer_rows.trailing_zeros()
    }

    /// GPU bytes of the texture (one layer more than the map needs for
    /// one-layer maps: see [`TerrainTexture::new`]).
    pub fn bytes(&self) -> u64 {
        u64::from(self.pairs) * u64::from(self.layer_rows) * u64::from(self.layers.max(2)) * 4
    }
}

/// The terrain texture and its layout.
pub struct TerrainTexture {
    pub layout: TerrainLayout,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl TerrainTexture {
    /// Create the texture and upload the whole level.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, level: &Level) -> anyhow::Result<Self> {
        let layout = TerrainLayout::new(level, &device.limits())?;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("terrain"),
            size: wgpu::Extent3d {
                width: layout.pairs,
                height: layout.layer_rows,
                // wgpu's GL backend makes a one-layer texture a GL_TEXTURE_2D,
                // which a `texture_2d_array` binding then does not see (it
                // read zeros): allocate a second, unused layer for maps of
                // at most `MAX_LAYER_ROWS` rows.
                depth_or_array_layers: layout.layers.max(2),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("terrain"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let terrain = TerrainTexture {
            layout,
            texture,
            view,
        };
        let whole = DirtyRect {
            x: 0,
            y: 0,
            width: level.width(),
            height: level.height(),
        };
        terrain.upload(queue, level, &[whole])?;
        Ok(terrain)
    }

    /// Upload the given rectangles of `level` (already edited): one
    /// `write_texture` per rectangle and layer, widened to whole pairs only.
    pub fn upload(
        &self,
        queue: &wgpu::Queue,
        level: &Level,
        rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        let l = &self.layout;
        if level.width() != l.map_width || level.height() != l.map_height {
            anyhow::bail!(
                "edited level is {}x{}, the GPU terrain {}x{}",
                level.width(),
                level.height(),
                l.map_width,
                l.map_height
            );
        }
        let (heights, metas) = (level.heights(), level.metas());
        let w = l.map_width as usize;
        let mut data = Vec::new();
        for r in rects {
            if r.width == 0 || r.height == 0 {
                continue;
            }
            let x_end = r.x.checked_add(r.width).filter(|&e| e <= l.map_width);
            let y_end = r.y.checked_add(r.height).filter(|&e| e <= l.map_height);
            let (Some(x_end), Some(y_end)) = (x_end, y_end) else {
                anyhow::bail!(
                    "dirty rectangle {r:?} reaches outside the {}x{} map",
                    l.map_width,
                    l.map_height
                );
            };
            let p0 = r.x / 2;
            let p1 = x_end.div_ceil(2);
            let mut y = r.y;
            while y < y_end {
                let layer = y / l.layer_rows;
                let row0 = y % l.layer_rows;
                let rows = (l.layer_rows - row0).min(y_end - y);
                data.clear();
                for yy in y..y + rows {
                    let start = yy as usize * w;
                    for p in p0..p1 {
                        let e = start + 2 * p as usize;
                        data.extend_from_slice(&[
                            heights[e],
                            metas[e],
                            heights[e + 1],
                            metas[e + 1],
                        ]);
                    }
                }
                queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture: &self.texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d {
                            x: p0,
                            y: row0,
                            z: layer,
                        },
                        aspect: wgpu::TextureAspect::All,
                    },
                    &data,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(4 * (p1 - p0)),
                        rows_per_image: Some(rows),
                    },
                    wgpu::Extent3d {
                        width: p1 - p0,
                        height: rows,
                        depth_or_array_layers: 1,
                    },
                );
                y += rows;
            }
        }
        Ok(())
    }
}
