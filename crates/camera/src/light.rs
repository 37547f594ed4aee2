//! The scene's light, shared by the CPU colour reference and every GPU
//! method: the sun's direction, the sky colour and the frame of the 1024²
//! shadow map (fitted to the camera). The GPU fills the map in
//! `strata-render`'s `shadow.wgsl`; `strata-reference` casts its CPU twin.

use crate::Camera;
use glam::Vec3;

/// Side of the shared shadow map, texels.
pub const SHADOW_SIZE: u32 = 1024;
/// The map's square moves over the light's lattice of texels in steps of
/// this many texels, so its 8x8-texel blocks are lattice blocks (a cast
/// block can be kept by a later frame).
pub const SHADOW_BLOCK: u32 = 8;
/// The map's plane lies a multiple of this many units along the light.
pub const SHADOW_PLANE_STEP: f32 = 256.0;
/// Texel sizes come in steps of 2^(1/32) (2.2 %), so a moving view keeps
/// its texel size, and so its lattice, across most frames. (Steps of 9 %
/// made the square so much wider than the footprint that a paged horizon
/// view's shadow rays outgrew the test's 64-page budget.)
const TEXEL_STEPS_PER_OCTAVE: f32 = 32.0;

/// The texel size of a map whose square must span `side` units about its
/// middle, when the middle may sit up to a block off: the next step of
/// [`TEXEL_STEPS_PER_OCTAVE`] up.
fn shadow_texel_size(side: f32) -> f32 {
    let needed = side / (SHADOW_SIZE - 2 * SHADOW_BLOCK) as f32;
    let step = (needed.log2() * TEXEL_STEPS_PER_OCTAVE).ceil();
    (step / TEXEL_STEPS_PER_OCTAVE).exp2()
}

/// Background colour where rays miss (linear 0..1 RGB).
pub const SKY: [f32; 3] = [0.62, 0.74, 0.86];

/// Direction the sunlight travels (down and across the map).
pub fn light_direction() -> Vec3 {
    Vec3::new(0.45, 0.3, -0.84).normalize()
}

/// Where this frame's shadow map lies: a square on a plane perpendicular to
/// the light, far enough up the light that all terrain lies in front of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFrame {
    /// Whether shadows are on this frame; when off, every point is shaded as lit.
    pub enabled: bool,
    /// Unit direction the light travels ([`light_direction`]).
    pub light: Vec3,
    /// Corner of the map's square (texel (0, 0)'s outer corner):
    /// `anchor + (u lattice.x + v lattice.y) texel`.
    pub origin: Vec3,
    /// The point of the map's plane the lattice counts from: the light times
    /// the plane's distance along it, a multiple of [`SHADOW_PLANE_STEP`].
    pub anchor: Vec3,
    /// Texel (0, 0)'s index on the light's world-fixed lattice of texels of
    /// this size: multiples of [`SHADOW_BLOCK`]. A lattice texel's centre,
    /// and so what it holds, is the same in every frame of the same texel
    /// size and plane ([`ShadowFrame::texel_centre`]), which lets a frame keep
    /// the texels an earlier one cast; the map stores texel (i, j) at
    /// [`ShadowFrame::slot`].
    pub lattice: [i32; 2],
    /// Unit vector along the map's texel x axis, perpendicular to the light.
    pub u: Vec3,
    /// Unit vector along the map's texel y axis, perpendicular to `u` and the light.
    pub v: Vec3,
    /// World units per texel.
    pub texel: f32,
    /// World units per texel of a map fitted to the footprint exactly (the
    /// footprint's side / [`SHADOW_SIZE`]), before `texel`'s rounding up to
    /// a step: paged terrain's shadow rays take their level of detail from
    /// it, so the level does not jump by a step as the view moves.
    pub lod_texel: f32,
    /// Depth bias, world units: how far behind the blocker a point must be to be in shadow.
    pub bias: f32,
    /// The texels a visible point can sample: the rest are never cast.
    pub cover: ShadowCover,
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
        let texel = shadow_texel_size(side);
        // Texel (0, 0) on the lattice, a block corner, so that the map's
        // middle lies within a block of the footprint's centre; the texel
        // size leaves a block's slack for it.
        let block = (SHADOW_BLOCK as f32) * texel;
        let half = 0.5 * SHADOW_SIZE as f32 * texel;
        let lattice = [
            ((centre.x - half) / block).floor() as i32 * SHADOW_BLOCK as i32,
            ((centre.y - half) / block).floor() as i32 * SHADOW_BLOCK as i32,
        ];
        // Put the plane well above every altitude: at least 600 units up the
        // light, on a step, so it moves only when the view moves far.
        let along = points.iter().map(|p| p.dot(light)).fold(f32::MAX, f32::min) - 600.0;
        let anchor = light * ((along / SHADOW_PLANE_STEP).floor() * SHADOW_PLANE_STEP);
        let origin = anchor + u * (lattice[0] as f32 * texel) + v * (lattice[1] as f32 * texel);
        let mut frame = ShadowFrame {
            enabled,
            light,
            origin,
            anchor,
            lattice,
            u,
            v,
            texel,
            lod_texel: side / SHADOW_SIZE as f32,
            // With the normal offset in `shading.wgsl`, a texel plus half a
            // unit (the march's bisection error) keeps lit surfaces lit.
            bias: texel + 0.5,
            cover: ShadowCover::EVERY_TEXEL,
        };
        frame.cover = ShadowCover::of_view(camera, &frame);
        frame
    }

    /// Texel (i, j)'s centre on the map's plane, from its lattice index (in
    /// f32, as `frame.wgsl`'s `shadow_texel_centre` computes it): the same
    /// point in every frame with this texel size and plane.
    pub fn texel_centre(&self, i: u32, j: u32) -> Vec3 {
        let at = |n: u32, first: i32| (first.wrapping_add(n as i32) as f32 + 0.5) * self.texel;
        self.anchor + self.u * at(i, self.lattice[0]) + self.v * at(j, self.lattice[1])
    }

    /// Where the map's texture stores texel (i, j): its lattice index
    /// wrapped to the map's side, so a texel keeps its place in the texture
    /// while the map's square moves over the lattice with the view.
    pub fn slot(&self, i: u32, j: u32) -> (u32, u32) {
        let wrap = |n: u32, first: i32| (first.wrapping_add(n as i32) as u32) & (SHADOW_SIZE - 1);
        (wrap(i, self.lattice[0]), wrap(j, self.lattice[1]))
    }

    /// The map's texel coordinates of world point `p` (texel (i, j) spans
    /// [i, i + 1) x [j, j + 1)).
    pub fn texel_coords(&self, p: glam::DVec3) -> glam::DVec2 {
        let rel = p - self.origin.as_dvec3();
        let texel = f64::from(self.texel);
        glam::DVec2::new(rel.dot(self.u.as_dvec3()), rel.dot(self.v.as_dvec3())) / texel
    }

    /// Whether texel (i, j) is cast this frame ([`ShadowFrame::cover`]).
    pub fn casts(&self, i: u32, j: u32) -> bool {
        self.cover.covers(i, j)
    }
}

/// Most half-planes of a [`ShadowCover`] (the outline of the view's slice of
/// space has at most a dozen edges; dropping one only covers more).
pub const MAX_COVER_EDGES: usize = 16;

/// Shadow texels kept beyond the outline of what the view sees: shading
/// pushes a point 1.5 texels off the surface along its normal, then PCF reads
/// the 2x2 texels around it (centres up to 1 texel away); the rest is slack
/// for f32 rounding.
pub const COVER_MARGIN_TEXELS: f32 = 4.0;

/// The shadow texels a frame can sample: a convex region of the map, as
/// half-planes in texel coordinates. Every point any method shades lies in
/// the view frustum (near to far) and in the altitude slab [0, 255]; the light
/// carries that convex slice of space onto the map as a convex polygon, and
/// shading only reads texels within [`COVER_MARGIN_TEXELS`] of it. Texels
/// outside are not cast (the GPU pass and the CPU twin store
/// `SHADOW_MISS` there): at the horizon most of the square map lies outside
/// the view's wedge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowCover {
    /// `(nx, ny, d)`: texel centre `c` is covered when `nx cx + ny cy + d <= 0`
    /// for each of the first `count` planes (`n` unit length, outward).
    pub planes: [[f32; 3]; MAX_COVER_EDGES],
    /// How many of `planes` apply; 0 covers every texel.
    pub count: u32,
}

impl ShadowCover {
    /// No culling: every texel is cast.
    pub const EVERY_TEXEL: ShadowCover = ShadowCover {
        planes: [[0.0; 3]; MAX_COVER_EDGES],
        count: 0,
    };

    /// No texel: the view sees nothing in the altitude slab.
    pub const NO_TEXEL: ShadowCover = {
        let mut planes = [[0.0; 3]; MAX_COVER_EDGES];
        planes[0] = [0.0, 0.0, 1.0];
        ShadowCover { planes, count: 1 }
    };

    /// The region of `frame`'s map that `camera`'s visible points can
    /// sample: the light's projection of the frustum (near to far) cut to
    /// the altitude slab [0, 255], widened by [`COVER_MARGIN_TEXELS`].
    pub fn of_view(camera: &Camera, frame: &ShadowFrame) -> ShadowCover {
        let outline: Vec<[f32; 2]> = crate::frustum::slab_points(camera, camera.far, 255.0)
            .into_iter()
            .map(|p| frame.texel_coords(p.as_dvec3()).as_vec2().to_array())
            .collect();
        if outline.is_empty() {
            return ShadowCover::NO_TEXEL;
        }
        let hull: Vec<glam::DVec2> = crate::frustum::convex_hull(outline)
            .into_iter()
            .map(|p| glam::Vec2::from(p).as_dvec2())
            .collect();
        if hull.len() < 3 {
            // A degenerate slice (a line or a point): keep it simple and
            // cast everything rather than reason about a zero-area region.
            return ShadowCover::EVERY_TEXEL;
        }
        let mut cover = ShadowCover::EVERY_TEXEL;
        for (k, a) in hull.iter().enumerate() {
            let b = hull[(k + 1) % hull.len()];
            let e = b - *a;
            // Counter-clockwise hull: the outside is to the right of a -> b.
            let n = glam::DVec2::new(e.y, -e.x).normalize();
            if (cover.count as usize) < MAX_COVER_EDGES {
                let d = -n.dot(*a) - f64::from(COVER_MARGIN_TEXELS);
                cover.planes[cover.count as usize] = [n.x as f32, n.y as f32, d as f32];
                cover.count += 1;
            }
        }
        cover
    }

    /// Whether texel (i, j)'s centre is covered, in f32 as `frame.wgsl`'s
    /// `shadow_texel_cast` computes it.
    pub fn covers(&self, i: u32, j: u32) -> bool {
        let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
        self.planes[..self.count as usize]
            .iter()
            .all(|[nx, ny, d]| nx * x + ny * y + d <= 0.0)
    }

    /// Share of `side` x `side` texels covered (for reports).
    pub fn fraction(&self, side: u32) -> f64 {
        let covered: u64 = (0..side)
            .map(|j| (0..side).filter(|&i| self.covers(i, j)).count() as u64)
            .sum();
        covered as f64 / (f64::from(side) * f64::from(side))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(pitch: f32, eye_z: f32, w: u32, h: u32) -> Camera {
        Camera::new(Vec3::new(1000.0, 8000.0, eye_z), 37.0, pitch, w, h).unwrap()
    }

    /// Points any method can shade: pixel rays at view depths near..far,
    /// inside the altitude slab.
    fn visible_points(camera: &Camera) -> Vec<Vec3> {
        let mut points = Vec::new();
        let (w, h) = (camera.width as f32, camera.height as f32);
        for j in 0..=16 {
            for i in 0..=16 {
                let d = camera.image_direction(w * i as f32 / 16.0, h * j as f32 / 16.0);
                for k in 0..=64 {
                    let depth = camera.near + (camera.far - camera.near) * k as f32 / 64.0;
                    let p = camera.position + d * (depth / camera.focal_px);
                    if (0.0..=255.0).contains(&p.z) {
                        points.push(p);
                    }
                }
            }
        }
        points
    }

    #[test]
    fn every_texel_a_visible_point_samples_is_cast() {
        for (pitch, eye_z) in [
            (0.0, 60.0),
            (-30.0, 200.0),
            (-60.0, 300.0),
            (-90.0, 400.0),
            (20.0, 30.0),
            (-10.0, 300.0),
        ] {
            let camera = camera(pitch, eye_z, 1280, 800);
            let frame = ShadowFrame::fit(&camera, true);
            let points = visible_points(&camera);
            assert!(!points.is_empty());
            for p in points {
                // The 2x2 PCF taps around the point pushed 1.5 texels off
                // the surface (any direction), as `shading.wgsl` reads them.
                for (ox, oy) in [(-1.5f64, -1.5f64), (1.5, -1.5), (-1.5, 1.5), (1.5, 1.5)] {
                    let uv = frame.texel_coords(p.as_dvec3()) + glam::DVec2::new(ox, oy) - 0.5;
                    let base = uv.floor();
                    for (di, dj) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                        let (i, j) = (base.x + di, base.y + dj);
                        if (0.0..f64::from(SHADOW_SIZE)).contains(&i)
                            && (0.0..f64::from(SHADOW_SIZE)).contains(&j)
                        {
                            assert!(
                                frame.casts(i as u32, j as u32),
                                "pitch {pitch}: texel ({i}, {j}) of {p} is not cast"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_horizon_casts_a_fraction_of_the_map() {
        let horizon = ShadowFrame::fit(&camera(0.0, 60.0, 1280, 800), true);
        let fraction = horizon.cover.fraction(SHADOW_SIZE);
        for (pitch, z) in [
            (0.0, 60.0),
            (0.0, 150.0),
            (-30.0, 150.0),
            (-30.0, 250.0),
            (-60.0, 250.0),
            (-60.0, 350.0),
            (-90.0, 350.0),
            (-90.0, 450.0),
        ] {
            let f = ShadowFrame::fit(&camera(pitch, z, 1280, 800), true);
            eprintln!(
                "pitch {pitch} eye {z}: {:.3}",
                f.cover.fraction(SHADOW_SIZE)
            );
        }
        assert!(
            fraction > 0.05 && fraction < 0.9,
            "horizon covers {fraction}"
        );
        let down = ShadowFrame::fit(&camera(-90.0, 400.0, 1280, 800), true);
        assert!(down.cover.count >= 3 && down.cover.fraction(SHADOW_SIZE) < 1.0);
    }

    #[test]
    fn a_view_of_only_sky_casts_nothing() {
        let up = ShadowFrame::fit(&camera(60.0, 400.0, 320, 200), true);
        assert_eq!(up.cover, ShadowCover::NO_TEXEL);
        assert!(!up.casts(512, 512));
    }
}
