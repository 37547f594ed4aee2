//! The shared 1024² shadow map: a directional light's depth map over the
//! camera's footprint, rendered once per frame by the ray-march core
//! (`shaders/shadow.wgsl`) before the method's passes, and sampled with 4-tap
//! PCF by `shading.wgsl`.

use crate::frame::{SHADOW_SIZE, Shared, storage_texture_entry};
use glam::Vec3;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};

/// Texels per side of a finest max-height block of the shadow march's skip
/// pyramid (doubled while the grid would exceed the adapter's texture
/// limit); level `k` has blocks of `block << k`. Small blocks let the march
/// skip close to the terrain, where most of its samples were.
const SKIP_BLOCK: u32 = 2;
/// Pyramid levels at most (blocks of 2 .. 64 texels).
const SKIP_LEVELS: u32 = 6;

/// Conservative max-height pyramid for the shadow march: cell (i, j) of level
/// `k` holds the highest solid altitude in its block *and its 8 neighbours*
/// (wrapping like the level), so a light ray above that value can travel one
/// block width horizontally without meeting terrain. Every solid point of a
/// column lies at or below the larger raw height byte of its pair, so the raw
/// height plane bounds it and no decoding is needed.
struct SkipPyramid {
    /// Finest block side, texels.
    block: u32,
    /// Undilated block maxima per level (kept to update edits incrementally).
    blocks: Vec<Vec<u8>>,
    /// Cells per level, (x, y).
    dims: Vec<(u32, u32)>,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// The level's highest raw height: the top of the band the march clips to.
    max_height: u8,
}

impl SkipPyramid {
    fn new(shared: &Shared, level: &Level) -> anyhow::Result<Self> {
        let (w, h) = (level.width(), level.height());
        let limit = shared.device.limits().max_texture_dimension_2d;
        let mut block = SKIP_BLOCK;
        while w / block > limit || h / block > limit {
            block *= 2;
        }
        if w % block != 0 || h % block != 0 {
            anyhow::bail!(
                "the shadow skip pyramid needs level sides that are multiples of {block}, got {w}x{h}"
            );
        }
        // Small levels get fewer levels (each must divide the level).
        let mut levels = 1;
        while levels < SKIP_LEVELS && w % (block << levels) == 0 && h % (block << levels) == 0 {
            levels += 1;
        }
        let dims: Vec<(u32, u32)> = (0..levels)
            .map(|k| (w / (block << k), h / (block << k)))
            .collect();
        let blocks = dims
            .iter()
            .map(|&(cx, cy)| vec![0u8; (cx * cy) as usize])
            .collect();
        let texture = shared.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow skip pyramid"),
            size: wgpu::Extent3d {
                width: dims[0].0,
                height: dims[0].1,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let mut pyramid = SkipPyramid {
            block,
            blocks,
            dims,
            texture,
            view,
            max_height: 0,
        };
        pyramid.update(
            shared,
            level,
            &[DirtyRect {
                x: 0,
                y: 0,
                width: w,
                height: h,
            }],
        );
        Ok(pyramid)
    }

    /// Recompute the blocks of every level touching `rects` and upload their
    /// dilated values (the touched cells plus one ring, wrapping).
    fn update(&mut self, shared: &Shared, level: &Level, rects: &[DirtyRect]) {
        let (w, h) = (level.width(), level.height());
        let heights = level.heights();
        for r in rects {
            for k in 0..self.blocks.len() {
                let bs = self.block << k;
                let (cx, cy) = self.dims[k];
                let xs = wrapped_ranges(
                    i64::from(r.x / bs),
                    i64::from((r.x + r.width).div_ceil(bs)),
                    cx,
                );
                let ys = wrapped_ranges(
                    i64::from(r.y / bs),
                    i64::from((r.y + r.height).div_ceil(bs)),
                    cy,
                );
                let (finer, this) = self.blocks.split_at_mut(k);
                let this = &mut this[0];
                for &(y0, y1) in &ys {
                    for &(x0, x1) in &xs {
                        for by in y0..y1 {
                            for bx in x0..x1 {
                                let m = if k == 0 {
                                    let x = (bx * bs) as usize;
                                    (by * bs..(by + 1) * bs)
                                        .map(|y| {
                                            let row = (y % h) as usize * w as usize + x;
                                            heights[row..row + bs as usize]
                                                .iter()
                                                .copied()
                                                .max()
                                                .unwrap_or(0)
                                        })
                                        .max()
                                        .unwrap_or(0)
                                } else {
                                    let f = &finer[k - 1];
                                    let fx = self.dims[k - 1].0;
                                    let at = |dx: u32, dy: u32| {
                                        f[((2 * by + dy) * fx + 2 * bx + dx) as usize]
                                    };
                                    at(0, 0).max(at(1, 0)).max(at(0, 1)).max(at(1, 1))
                                };
                                this[(by * cx + bx) as usize] = m;
                            }
                        }
                    }
                }
                // Upload the touched cells and the ring their dilation reaches.
                let xs = wrapped_ranges(
                    i64::from(r.x / bs) - 1,
                    i64::from((r.x + r.width).div_ceil(bs)) + 1,
                    cx,
                );
                let ys = wrapped_ranges(
                    i64::from(r.y / bs) - 1,
                    i64::from((r.y + r.height).div_ceil(bs)) + 1,
                    cy,
                );
                for &(y0, y1) in &ys {
                    for &(x0, x1) in &xs {
                        let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
                        for y in y0..y1 {
                            let rows =
                                [(y + cy - 1) % cy, y, (y + 1) % cy].map(|y| (y * cx) as usize);
                            for x in x0..x1 {
                                let cols = [(x + cx - 1) % cx, x, (x + 1) % cx].map(|x| x as usize);
                                let mut m = 0u8;
                                for r in rows {
                                    for c in cols {
                                        m = m.max(this[r + c]);
                                    }
                                }
                                out.push(m);
                            }
                        }
                        shared.queue.write_texture(
                            wgpu::TexelCopyTextureInfo {
                                texture: &self.texture,
                                mip_level: k as u32,
                                origin: wgpu::Origin3d { x: x0, y: y0, z: 0 },
                                aspect: wgpu::TextureAspect::All,
                            },
                            &out,
                            wgpu::TexelCopyBufferLayout {
                                offset: 0,
                                bytes_per_row: Some(x1 - x0),
                                rows_per_image: Some(y1 - y0),
                            },
                            wgpu::Extent3d {
                                width: x1 - x0,
                                height: y1 - y0,
                                depth_or_array_layers: 1,
                            },
                        );
                    }
                }
            }
        }
        let last = self.blocks.len() - 1;
        self.max_height = self.blocks[last].iter().copied().max().unwrap_or(0);
    }

    fn bytes(&self) -> u64 {
        self.dims.iter().map(|&(x, y)| u64::from(x * y)).sum()
    }
}

/// `[lo, hi)` on a ring of `n` cells as at most two plain ranges.
fn wrapped_ranges(lo: i64, hi: i64, n: u32) -> Vec<(u32, u32)> {
    let n64 = i64::from(n);
    if hi - lo >= n64 {
        return vec![(0, n)];
    }
    let start = lo.rem_euclid(n64);
    let end = start + (hi - lo);
    if end <= n64 {
        vec![(start as u32, end as u32)]
    } else {
        vec![(start as u32, n), (0, (end - n64) as u32)]
    }
}

/// Direction the sunlight travels (down and across the map).
pub fn light_direction() -> Vec3 {
    Vec3::new(0.45, 0.3, -0.84).normalize()
}

/// Where this frame's shadow map lies: a square on a plane perpendicular to
/// the light, far enough up the light that all terrain lies in front of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFrame {
    pub enabled: bool,
    pub light: Vec3,
    /// Corner of the map's square (texel (0, 0)'s outer corner).
    pub origin: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    /// World units per texel.
    pub texel: f32,
    /// Depth bias, world units: how far behind the blocker a point must be to be in shadow.
    pub bias: f32,
}

impl ShadowFrame {
    /// Fit the map to the part of the view frustum inside the altitude slab
    /// [0, 255]: the eye and the corner rays, each clipped to the slab and
    /// the far plane, projected onto the light's plane.
    pub fn fit(camera: &Camera, enabled: bool) -> Self {
        let light = light_direction();
        let u = light.cross(Vec3::Z).normalize();
        let v = light.cross(u).normalize();
        let (w, h) = (camera.width as f32, camera.height as f32);
        let mut points = vec![camera.position];
        for (px, py) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h), (0.5 * w, 0.5 * h)] {
            let d = camera.image_direction(px, py);
            // View depth is t * focal along the unnormalised direction.
            let t_far = camera.far / camera.focal_px;
            let (mut t0, mut t1) = (0.0f32, t_far);
            if d.z.abs() > 1e-9 {
                let ta = -camera.position.z / d.z;
                let tb = (255.0 - camera.position.z) / d.z;
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
            if t0 <= t1 {
                points.push(camera.position + d * t0);
                points.push(camera.position + d * t1);
            }
        }
        // The footprint on the ground below the eye matters too (shadows cast
        // onto what the corner rays reach come from terrain between them).
        points.push(Vec3::new(camera.position.x, camera.position.y, 0.0));
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
        for p in &points {
            let q = glam::Vec2::new(p.dot(u), p.dot(v));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        // A margin for casters just outside the footprint; a square map.
        let side = (hi - lo).max_element() + 32.0;
        let centre = 0.5 * (lo + hi);
        let texel = side / SHADOW_SIZE as f32;
        // Put the plane well above every altitude: 600 units up the light.
        let along = points.iter().map(|p| p.dot(light)).fold(f32::MAX, f32::min) - 600.0;
        let origin = u * (centre.x - 0.5 * side) + v * (centre.y - 0.5 * side) + light * along;
        ShadowFrame {
            enabled,
            light,
            origin,
            u,
            v,
            texel,
            // With the normal offset in `shading.wgsl`, a texel plus half a
            // unit (the march's bisection error) keeps lit surfaces lit.
            bias: texel + 0.5,
        }
    }
}

/// The compute pass that fills the shadow map.
pub struct ShadowPass {
    pipeline: wgpu::ComputePipeline,
    frame_group: wgpu::BindGroup,
    out_group: wgpu::BindGroup,
    pyramid: SkipPyramid,
    params: wgpu::Buffer,
}

impl ShadowPass {
    pub fn new(shared: &Shared, level: &Level) -> anyhow::Result<Self> {
        let pyramid = SkipPyramid::new(shared, level)?;
        let params = shared.uniform_buffer("shadow params", &shadow_params(&pyramid));
        // Group 0 here omits the shadow map: it cannot be sampled and written
        // in the same pass.
        let device = &shared.device;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow frame"),
            entries: &[
                crate::frame::uniform_layout_entry(0),
                crate::frame::texture_entry(
                    2,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D2Array,
                ),
            ],
        });
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow frame"),
            layout: &frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: shared.globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&shared.terrain.view),
                },
            ],
        });
        let out_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow out"),
            entries: &[
                storage_texture_entry(0, wgpu::TextureFormat::R32Float),
                crate::frame::texture_entry(
                    1,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D2,
                ),
                crate::frame::uniform_layout_entry(2),
            ],
        });
        let out_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow out"),
            layout: &out_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&shared.shadow_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&pyramid.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&frame_layout), Some(&out_layout)],
            immediate_size: 0,
        });
        let module = shared.shader("shadow.wgsl")?;
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("shadow"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_shadow"),
            compilation_options: Default::default(),
            cache: None,
        });
        Ok(ShadowPass {
            pipeline,
            frame_group,
            out_group,
            pyramid,
            params,
        })
    }

    /// The level changed inside `rects` (already applied to `level`): refresh
    /// the skip pyramid there, or the march would skip over raised terrain.
    pub fn apply_edit(&mut self, shared: &Shared, level: &Level, rects: &[DirtyRect]) {
        self.pyramid.update(shared, level, rects);
        shared
            .queue
            .write_buffer(&self.params, 0, &shadow_params(&self.pyramid));
    }

    /// GPU bytes of the skip pyramid (the shadow map itself is in [`Shared`]).
    pub fn gpu_bytes(&self) -> u64 {
        self.pyramid.bytes() + 16
    }

    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timer: &crate::timing::PassTimer) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shadow map"),
            timestamp_writes: timer.compute("shadow"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.frame_group, &[]);
        pass.set_bind_group(1, &self.out_group, &[]);
        pass.dispatch_workgroups(SHADOW_SIZE.div_ceil(8), SHADOW_SIZE.div_ceil(8), 1);
    }
}

/// `ShadowParams` in shadow.wgsl: finest block side, pyramid levels, the
/// level's highest altitude, unused.
fn shadow_params(p: &SkipPyramid) -> Vec<u8> {
    let v = [p.block, p.dims.len() as u32, u32::from(p.max_height), 0];
    bytemuck::cast_slice(&v).to_vec()
}
