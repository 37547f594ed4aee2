//! The scene's light, shared by the CPU colour reference and every GPU
//! method: the sun's direction, the sky colour and the frame of the 1024²
//! shadow map (fitted to the camera). The GPU fills the map in
//! `strata-render`'s `shadow.wgsl`; `strata-reference` casts its CPU twin.

use crate::Camera;
use glam::Vec3;

/// Side of the shared shadow map, texels.
pub const SHADOW_SIZE: u32 = 1024;
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
    /// Corner of the map's square (texel (0, 0)'s outer corner).
    pub origin: Vec3,
    /// Unit vector along the map's texel x axis, perpendicular to the light.
    pub u: Vec3,
    /// Unit vector along the map's texel y axis, perpendicular to `u` and the light.
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
