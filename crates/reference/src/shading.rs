//! The CPU colour reference: `shading.wgsl` evaluated on the CPU, in f32 as
//! the GPU does, at every reference hit (DESIGN §3's reference, now with
//! colour). Palette colour of the hit interval's terrain type, the interval's
//! height-field gradient normal, diffuse light with the shadow from the CPU
//! twin of the shadow map ([`ShadowMap`]), cave ambient under a slab, and fog.
//! Keep each function in step with its namesake in `shading.wgsl`.

use crate::ReferenceSettings;
use crate::raycast::{ErrorSlot, Tracer};
use crate::shadow_map::ShadowMap;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::Arc;
use strata_camera::Camera;
use strata_camera::light::{SKY, ShadowFrame};
use strata_level::model::decode_column;
use strata_level::source::{ColumnSource, SourceError, SourceTile};
use strata_level::{Column, World};

const AMBIENT: f32 = 0.45;
const CAVE_AMBIENT: f32 = 0.25;
const FOG_RANGE: f32 = 50.0;
const RAMP_FLOOR: f32 = 0.3;

/// Which interval a shaded point is on (`SURFACE_*` in `shading.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Surface {
    Floor,
    SlabTop,
    Ceiling,
}

/// The world's palette and per-type colour ranges (`Begin/End Colors`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TerrainRamps {
    /// The world's palette, 8-bit RGB.
    pub palette: [[u8; 3]; 256],
    /// First (darkest-lit) palette index of each terrain type's range.
    pub begin: [u8; 8],
    /// Last (brightest-lit) palette index of each terrain type's range.
    pub end: [u8; 8],
}

impl TerrainRamps {
    /// The ramps of a loaded or generated world.
    pub fn from_world(world: &World) -> Self {
        TerrainRamps {
            palette: world.palette.colors,
            begin: world.config.begin_colors,
            end: world.config.end_colors,
        }
    }

    /// The bytes a cache key needs.
    pub fn key_bytes(&self) -> Vec<u8> {
        let mut b: Vec<u8> = self.palette.iter().flatten().copied().collect();
        b.extend_from_slice(&self.begin);
        b.extend_from_slice(&self.end);
        b
    }

    /// `terrain_color`: ramp entry of type `t` picked by `light` in [0, 1].
    fn color(&self, t: u8, light: f32) -> Vec3 {
        let t = usize::from(t & 7);
        let (a, b) = (f32::from(self.begin[t]), f32::from(self.end[t]));
        let k = RAMP_FLOOR + (1.0 - RAMP_FLOOR) * light.clamp(0.0, 1.0);
        // WGSL's mix and round (ties to even).
        let idx = (a * (1.0 - k) + b * k).round_ties_even().clamp(0.0, 255.0);
        let [r, g, b] = self.palette[idx as usize];
        Vec3::new(f32::from(r), f32::from(g), f32::from(b)) / 255.0
    }
}

/// An RGB8 image, row-major, as the GPU's `Rgba8Unorm` target stores it
/// (alpha dropped).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ColorImage {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// RGB triples, row-major: `width * height * 3` bytes.
    pub rgb: Vec<u8>,
}

/// A unorm8 channel the way a GPU writes it: clamped, rounded to nearest.
fn unorm8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The last tile a thread's shading read.
#[derive(Default)]
struct Memo<'a> {
    key: (u64, u64),
    tile: Option<Arc<dyn SourceTile + 'a>>,
}

/// Everything the shading of one view needs.
pub struct Shader<'a> {
    source: &'a dyn ColumnSource,
    /// The tracer's: a column that cannot be read is kept there.
    errors: Arc<ErrorSlot>,
    ramps: &'a TerrainRamps,
    camera: &'a Camera,
    light: Vec3,
    shadow: Option<ShadowMap>,
}

impl<'a> Shader<'a> {
    /// Fit the shadow frame to `camera` and, with `shadows`, cast its map.
    pub fn new(
        tracer: &Tracer<'a>,
        ramps: &'a TerrainRamps,
        camera: &'a Camera,
        shadows: bool,
    ) -> Self {
        let frame = ShadowFrame::fit(camera, shadows);
        Shader {
            source: tracer.source(),
            errors: tracer.error_slot().clone(),
            ramps,
            camera,
            light: frame.light,
            shadow: shadows.then(|| ShadowMap::cast(tracer, &frame)),
        }
    }

    /// The CPU shadow map, when shadows are on.
    pub fn shadow_map(&self) -> Option<&ShadowMap> {
        self.shadow.as_ref()
    }

    /// The column at (x, y); a read error is kept (the image is then not
    /// the reference: [`render_color_checked`] returns it) and the column
    /// taken as empty ground. `memo` keeps the last tile read, so that a
    /// pixel's neighbours do not each ask the source's cache (a lock).
    fn column(&self, memo: &mut Memo<'a>, x: i64, y: i64) -> Column {
        if let Some(level) = self.source.as_level() {
            return level.column(x, y);
        }
        let (w, h) = self.source.size();
        let (rows, cols) = self.source.tile_shape();
        let (x, y) = ((x & i64::from(w - 1)) as u64, (y & i64::from(h - 1)) as u64);
        let key = (y / u64::from(rows), x / u64::from(cols));
        if memo.tile.is_none() || memo.key != key {
            match self.source.tile(key.0, key.1) {
                Ok(t) => {
                    memo.tile = Some(t);
                    memo.key = key;
                }
                Err(e) => {
                    self.errors.record(e);
                    memo.tile = None;
                }
            }
        }
        let Some(tile) = &memo.tile else {
            return Column {
                low: 0,
                mid: 0,
                high: 0,
                dual: false,
                lower_type: 0,
                upper_type: 0,
            };
        };
        let (hs, ms) = tile.planes();
        let start = (y % u64::from(rows)) as usize * cols as usize;
        let row = start..start + cols as usize;
        decode_column(
            &hs[row.clone()],
            &ms[row],
            (x % u64::from(cols)) as usize,
            self.source.mid_rule(),
        )
    }

    fn surface_kind(c: &Column, z: f32, dir_z: f32) -> Surface {
        let (low, mid, high) = (f32::from(c.low), f32::from(c.mid), f32::from(c.high));
        if !c.dual || z < 0.5 * (low + mid) {
            Surface::Floor
        } else if dir_z > 0.0 && z - mid < high - z {
            Surface::Ceiling
        } else {
            Surface::SlabTop
        }
    }

    fn interval_field(
        &self,
        memo: &mut Memo<'a>,
        x: i64,
        y: i64,
        kind: Surface,
        fallback: f32,
    ) -> f32 {
        let c = self.column(memo, x, y);
        match kind {
            Surface::Floor => f32::from(c.low),
            _ if !c.dual => fallback,
            Surface::Ceiling => f32::from(c.mid),
            Surface::SlabTop => f32::from(c.high),
        }
    }

    fn surface_normal(
        &self,
        memo: &mut Memo<'a>,
        x: i64,
        y: i64,
        kind: Surface,
        here: f32,
    ) -> Vec3 {
        let mut f = |dx, dy| self.interval_field(memo, x + dx, y + dy, kind, here);
        let gx = 0.5 * (f(1, 0) - f(-1, 0));
        let gy = 0.5 * (f(0, 1) - f(0, -1));
        if kind == Surface::Ceiling {
            Vec3::new(gx, gy, -1.0).normalize()
        } else {
            Vec3::new(-gx, -gy, 1.0).normalize()
        }
    }

    /// `shadow_factor`: 4-tap PCF of the map with the normal offset and the
    /// slope-scaled bias.
    fn shadow_factor(&self, p_surface: Vec3, n: Vec3) -> f32 {
        let Some(map) = &self.shadow else {
            return 1.0;
        };
        let f = &map.frame;
        let texel = f.texel;
        let p = p_surface + n * (1.5 * texel);
        let rel = p - f.origin;
        let uv = glam::Vec2::new(rel.dot(f.u), rel.dot(f.v)) / texel - 0.5;
        let ndl = n.dot(-self.light).max(0.05);
        let slope = ((1.0 - ndl * ndl).sqrt() / ndl).min(4.0);
        let t = rel.dot(self.light) - f.bias - slope * texel;
        let base = uv.floor();
        let frac = uv - base;
        let (i, j) = (base.x as i32, base.y as i32);
        let tap = |di, dj| match map.get(i + di, j + dj) {
            Some(blocker) if t > blocker => 0.0,
            _ => 1.0,
        };
        let mix = |a: f32, b: f32, k: f32| a * (1.0 - k) + b * k;
        mix(
            mix(tap(0, 0), tap(1, 0), frac.x),
            mix(tap(0, 1), tap(1, 1), frac.x),
            frac.y,
        )
    }

    fn fog_factor(&self, p: Vec3) -> f32 {
        let view_z = (p - self.camera.position).dot(self.camera.basis().forward);
        let far = self.camera.far;
        ((view_z - (far - FOG_RANGE)) / FOG_RANGE).clamp(0.0, 1.0)
    }

    /// `shade_column`: the colour of surface point `p` of column (x, y),
    /// found along a ray of direction `dir`.
    pub fn shade_column(&self, p: Vec3, x: i64, y: i64, dir: Vec3) -> Vec3 {
        self.shade_column_in(&mut Memo::default(), p, x, y, dir)
    }

    fn shade_column_in(&self, memo: &mut Memo<'a>, p: Vec3, x: i64, y: i64, dir: Vec3) -> Vec3 {
        let c = self.column(memo, x, y);
        let kind = Self::surface_kind(&c, p.z, dir.z);
        let here = f32::from(if kind == Surface::Ceiling {
            c.mid
        } else {
            c.high
        });
        let n = self.surface_normal(memo, x, y, kind, here);
        let t = if kind == Surface::Floor {
            c.lower_type
        } else {
            c.upper_type
        };
        let light = if c.dual && (p.z < f32::from(c.mid) || kind == Surface::Ceiling) {
            CAVE_AMBIENT
        } else {
            let diffuse = n.dot(-self.light).max(0.0);
            AMBIENT + (1.0 - AMBIENT) * diffuse * self.shadow_factor(p, n)
        };
        let color = self.ramps.color(t, light);
        color.lerp(Vec3::from(SKY), self.fog_factor(p))
    }

    /// The colour image of the view: every pixel's exact hit, shaded.
    pub fn render(&self, tracer: &Tracer) -> ColorImage {
        let camera = self.camera;
        let (w, h) = (camera.width as usize, camera.height as usize);
        let mut rgb = vec![0u8; 3 * w * h];
        let origin = camera.position.as_dvec3();
        let far = f64::from(camera.far);
        let focal = f64::from(camera.focal_px);
        let sky = SKY.map(unorm8);
        rgb.par_chunks_mut(3 * w).enumerate().for_each(|(j, row)| {
            let mut state = tracer.ray_state();
            let mut memo = Memo::default();
            for i in 0..w {
                let dir = camera
                    .image_direction(i as f32 + 0.5, j as f32 + 0.5)
                    .as_dvec3();
                let t_max = far * dir.length() / focal;
                let unit = dir.normalize();
                let px = match tracer.trace_in(
                    &mut state,
                    origin,
                    unit,
                    t_max,
                    &ReferenceSettings::default(),
                ) {
                    Some(hit) => {
                        let p = (origin + unit * hit.distance).as_vec3();
                        let [x, y] = hit.column;
                        self.shade_column_in(&mut memo, p, x, y, unit.as_vec3())
                            .to_array()
                            .map(unorm8)
                    }
                    None => sky,
                };
                row[3 * i..3 * i + 3].copy_from_slice(&px);
            }
        });
        ColorImage {
            width: camera.width,
            height: camera.height,
            rgb,
        }
    }
}

/// The colour reference of `camera`'s view, shadows on or off.
pub fn render_color(
    tracer: &Tracer,
    ramps: &TerrainRamps,
    camera: &Camera,
    shadows: bool,
) -> ColorImage {
    Shader::new(tracer, ramps, camera, shadows).render(tracer)
}

/// [`render_color`], failing when the tracer's source could not be read.
pub fn render_color_checked(
    tracer: &Tracer,
    ramps: &TerrainRamps,
    camera: &Camera,
    shadows: bool,
) -> Result<ColorImage, SourceError> {
    let image = render_color(tracer, ramps, camera, shadows);
    match tracer.error() {
        Some(e) => Err(e),
        None => Ok(image),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::Level;

    fn ramps() -> TerrainRamps {
        let mut palette = [[0u8; 3]; 256];
        for (i, c) in palette.iter_mut().enumerate() {
            *c = [i as u8, (255 - i) as u8, 7];
        }
        TerrainRamps {
            palette,
            begin: std::array::from_fn(|t| (t * 32) as u8),
            end: std::array::from_fn(|t| (t * 32 + 31) as u8),
        }
    }

    #[test]
    fn flat_ground_is_lit_by_the_sun_and_sky_is_sky() {
        // Flat ground of type 3 at height 10, looked at from above.
        let level = Level::flat(64, 64, 10, 3).unwrap();
        let cam = Camera::new(Vec3::new(32.0, 20.0, 40.0), 0.0, -30.0, 32, 20).unwrap();
        let tracer = Tracer::new(&level);
        let ramps = ramps();
        let img = render_color(&tracer, &ramps, &cam, true);
        // Up normal, unshadowed: light = 0.45 + 0.55 * n.(-l).
        let light = 0.45 + 0.55 * (-strata_camera::light::light_direction().z);
        let k = 0.3 + 0.7 * light;
        let idx = (96.0 * (1.0 - k) + 127.0 * k).round_ties_even() as usize;
        let bottom = &img.rgb[img.rgb.len() - 3..];
        assert_eq!(bottom, &[idx as u8, (255 - idx) as u8, 7]);
        // Looking level, the top row is above the horizon: sky.
        let level_cam = Camera::new(Vec3::new(32.0, 20.0, 40.0), 0.0, 0.0, 32, 20).unwrap();
        let sky = render_color(&tracer, &ramps, &level_cam, true);
        assert_eq!(&sky.rgb[..3], &SKY.map(unorm8));
    }

    #[test]
    fn a_wall_casts_a_shadow_on_the_ground_behind_it() {
        // A tall block in the middle of flat ground: points just down-light of
        // it are shadowed, points up-light are lit.
        let mut level = Level::flat(64, 64, 10, 3).unwrap();
        let (heights, _) = level.planes_mut();
        for y in 28..36 {
            for x in 28..36 {
                heights[y * 64 + x] = 80;
            }
        }
        // Looking down on both test points: the map is cast only where the
        // view can read it (`ShadowCover`).
        let cam = Camera::new(Vec3::new(32.0, 32.0, 120.0), 0.0, -90.0, 256, 256).unwrap();
        let tracer = Tracer::new(&level);
        let ramps = ramps();
        let shader = Shader::new(&tracer, &ramps, &cam, true);
        let l = strata_camera::light::light_direction();
        let down = Vec3::Z;
        // Down-light of the block (light travels along +x, +y).
        let behind = Vec3::new(40.5, 38.5, 10.0);
        let before = Vec3::new(24.5, 24.5, 10.0);
        assert!(l.x > 0.0 && l.y > 0.0);
        assert_eq!(shader.shadow_factor(behind, down), 0.0);
        assert_eq!(shader.shadow_factor(before, down), 1.0);
    }
}
