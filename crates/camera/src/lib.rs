//! The one camera model (DESIGN §2), shared by the CPU reference and every GPU
//! method: a focal length fixed in pixels, near 1, far 600 along the view
//! axis, and the paper's yaw/pitch basis.
//!
//! Pixel (i, j) of a W x H image looks along
//! `focal * forward - right * (i - W/2 + 0.5) + up * (H/2 - j - 0.5)`.
//! The minus on `right` mirrors the image relative to a right-handed z-up
//! world: the original map's y axis points down the screen, and keeping that
//! handedness makes our images line up with vange-rs pixel for pixel.
//!
//! Units: positions are world units (one map texel across, one altitude step
//! up; altitudes run 0..=255), angles are degrees, image coordinates are
//! pixels from the top-left corner.
//!
//! # Example: a camera and a pixel ray
//!
//! ```
//! use glam::Vec3;
//! use strata_camera::Camera;
//! use strata_level::{Level, ViewSpec};
//!
//! // Yaw 0 looks along +y; pitch -30 looks down.
//! let camera = Camera::new(Vec3::new(32.0, 10.0, 80.0), 0.0, -30.0, 64, 48).unwrap();
//! let centre = camera.pixel_ray(32, 24); // unit direction through pixel (32, 24)
//! assert!((centre.length() - 1.0).abs() < 1e-6);
//! assert!(centre.y > 0.0 && centre.z < 0.0);
//!
//! // A point along that ray projects back onto the pixel's centre.
//! let p = camera.project(camera.position + centre * 50.0).unwrap();
//! assert!((p.x - 32.5).abs() < 1e-3 && (p.y - 24.5).abs() < 1e-3);
//!
//! // A view resolved against a level: the eye 5 units above the ground.
//! let level = Level::flat(64, 64, 30, 1).unwrap();
//! let view = ViewSpec::parse("v", "10,20:90:5", -20.0).unwrap();
//! let camera = Camera::from_view(&level, &view, 64, 48).unwrap();
//! assert_eq!(camera.position, Vec3::new(10.0, 20.0, 35.0));
//! ```
//!
//! # Stability
//!
//! [`Camera`] (its fields, `new`, `from_view`, `pixel_ray`, `project`,
//! `view_proj` and the depth conversions), [`Basis`], [`CameraError`] and the
//! `DEFAULT_*` constants are the stable surface: every method's images depend
//! on this convention. The [`light`] module (sun, sky, shadow-map frame) is
//! the shading's and may change with it.

#![warn(missing_docs)]

pub mod frustum;
pub mod light;

use glam::{Mat4, Vec3, Vec4};
use serde::{Deserialize, Serialize};
use strata_level::views::{ViewError, check_pitch};
use strata_level::{Level, ViewSpec};

/// Focal length in pixels. Fixed: the field of view depends on the image size
/// (scaling it with the image height was the paper's first reference bug).
pub const DEFAULT_FOCAL_PX: f32 = 512.0;
/// Near plane, world units along the view axis.
pub const DEFAULT_NEAR: f32 = 1.0;
/// Far plane, measured along the view axis.
pub const DEFAULT_FAR: f32 = 600.0;

/// Why a camera could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CameraError {
    /// The image width or height (pixels) is 0.
    #[error("image size {0}x{1} must be positive")]
    Size(u32, u32),
    /// The pitch is outside [-90, 90] degrees.
    #[error(transparent)]
    View(#[from] ViewError),
    /// [`Camera::from_view`] put the eye inside solid terrain: an `eye` of 0
    /// or less, or, with `under`, one that reaches into the slab.
    #[error(
        "view `{name}`: the eye at ({x}, {y}, {z}) is inside solid terrain (column floor {low}, slab {mid}..{high})"
    )]
    EyeInSolid {
        /// The view's name.
        name: String,
        /// Eye x, world units, wrapped onto the map.
        x: f32,
        /// Eye y, world units, wrapped onto the map.
        y: f32,
        /// Eye altitude.
        z: f32,
        /// The column's floor altitude.
        low: u8,
        /// The column's slab bottom (cave ceiling); equals `high` without a slab.
        mid: u8,
        /// The column's top altitude.
        high: u8,
    },
}

/// The orthonormal view basis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    /// Horizontal heading: `(sin yaw, cos yaw, 0)`.
    pub flat: Vec3,
    /// `flat x Z`; the image's x axis runs along `-right`.
    pub right: Vec3,
    /// `flat cos(pitch) + Z sin(pitch)`.
    pub forward: Vec3,
    /// `right x forward`.
    pub up: Vec3,
}

/// A pinhole camera and its image size; see the crate docs for the pixel
/// convention. Build it with [`Camera::new`] or [`Camera::from_view`], which
/// check the size and pitch.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Eye position, world units (x, y on the map, z altitude).
    pub position: Vec3,
    /// Heading in degrees: 0 looks along +y, 90 along +x.
    pub yaw_deg: f32,
    /// Degrees in [-90, 90]; negative looks down.
    pub pitch_deg: f32,
    /// Focal length in pixels ([`DEFAULT_FOCAL_PX`]).
    pub focal_px: f32,
    /// Near plane, world units along the view axis.
    pub near: f32,
    /// Far plane, world units along the view axis.
    pub far: f32,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

impl Camera {
    /// A camera with the default focal length, near and far planes.
    /// Errors: [`CameraError::Size`] for a zero side, [`CameraError::View`]
    /// for a pitch outside [-90, 90].
    pub fn new(
        position: Vec3,
        yaw_deg: f32,
        pitch_deg: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        if width == 0 || height == 0 {
            return Err(CameraError::Size(width, height));
        }
        check_pitch(pitch_deg)?;
        Ok(Camera {
            position,
            yaw_deg,
            pitch_deg,
            focal_px: DEFAULT_FOCAL_PX,
            near: DEFAULT_NEAR,
            far: DEFAULT_FAR,
            width,
            height,
        })
    }

    /// Resolve a view against a level: wrap the position onto the map, put the
    /// eye `eye` units above the top surface (or the floor, for `under`), and
    /// refuse an eye inside solid terrain ([`CameraError::EyeInSolid`]).
    pub fn from_view(
        level: &Level,
        view: &ViewSpec,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        Self::from_view_over(
            (level.width(), level.height()),
            |x, y| level.column_at(x, y),
            view,
            width,
            height,
        )
    }

    /// [`Camera::from_view`] over a map of `size` (width, height) whose
    /// columns `column_at` reads, for worlds not held whole in memory (a
    /// store: one chunk is read).
    pub fn from_view_over(
        size: (u32, u32),
        column_at: impl FnOnce(f32, f32) -> strata_level::model::Column,
        view: &ViewSpec,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        let x = view.x.rem_euclid(size.0 as f32);
        let y = view.y.rem_euclid(size.1 as f32);
        let column = column_at(x, y);
        let base = if view.under { column.low } else { column.top() };
        let z = f32::from(base) + view.eye;
        if column.is_solid(z) {
            return Err(CameraError::EyeInSolid {
                name: view.name.clone(),
                x,
                y,
                z,
                low: column.low,
                mid: column.mid,
                high: column.high,
            });
        }
        Self::new(Vec3::new(x, y, z), view.yaw, view.pitch, width, height)
    }

    /// The view basis from yaw and pitch (see [`Basis`]).
    pub fn basis(&self) -> Basis {
        let (sy, cy) = self.yaw_deg.to_radians().sin_cos();
        let (sp, cp) = self.pitch_deg.to_radians().sin_cos();
        let flat = Vec3::new(sy, cy, 0.0);
        let right = flat.cross(Vec3::Z);
        let forward = flat * cp + Vec3::Z * sp;
        let up = right.cross(forward);
        Basis {
            flat,
            right,
            forward,
            up,
        }
    }

    /// Unnormalised direction through the point (px, py) of the image plane,
    /// in pixels from the top-left corner (a pixel's centre is `i + 0.5`).
    /// Its component along `forward` is exactly `focal_px`.
    pub fn image_direction(&self, px: f32, py: f32) -> Vec3 {
        let b = self.basis();
        let sx = px - self.width as f32 * 0.5;
        let sy = self.height as f32 * 0.5 - py;
        b.forward * self.focal_px - b.right * sx + b.up * sy
    }

    /// Unit direction of the ray through the centre of pixel (i, j).
    pub fn pixel_ray(&self, i: u32, j: u32) -> Vec3 {
        self.image_direction(i as f32 + 0.5, j as f32 + 0.5)
            .normalize()
    }

    /// Distance along the ray of pixel (i, j) that reaches view depth `view_z`
    /// (the coordinate along `forward`).
    pub fn view_z_to_distance(&self, i: u32, j: u32, view_z: f32) -> f32 {
        let d = self.image_direction(i as f32 + 0.5, j as f32 + 0.5);
        view_z * d.length() / self.focal_px
    }

    /// Distance along the ray of pixel (i, j) beyond which the far plane clips it.
    pub fn far_distance(&self, i: u32, j: u32) -> f32 {
        self.view_z_to_distance(i, j, self.far)
    }

    /// World to wgpu clip space (x right, y up, depth 0 at near .. 1 at far).
    pub fn view_proj(&self) -> Mat4 {
        let b = self.basis();
        let e = self.position;
        let screen_right = -b.right;
        let kx = 2.0 * self.focal_px / self.width as f32;
        let ky = 2.0 * self.focal_px / self.height as f32;
        let kz = self.far / (self.far - self.near);
        let row = |v: Vec3, w: f32| Vec4::new(v.x, v.y, v.z, w);
        let rows = [
            row(screen_right * kx, -screen_right.dot(e) * kx),
            row(b.up * ky, -b.up.dot(e) * ky),
            row(b.forward * kz, -(b.forward.dot(e) + self.near) * kz),
            row(b.forward, -b.forward.dot(e)),
        ];
        Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose()
    }

    /// Linearise a depth-buffer value (0 near .. 1 far) to view depth.
    pub fn depth_to_view_z(&self, depth: f32) -> f32 {
        let (n, f) = (self.near, self.far);
        n * f / (f - depth * (f - n))
    }

    /// Depth-buffer value of a point at view depth `view_z`.
    pub fn view_z_to_depth(&self, view_z: f32) -> f32 {
        let (n, f) = (self.near, self.far);
        f / (f - n) * (1.0 - n / view_z)
    }

    /// Distance along the ray of pixel (i, j) for a depth-buffer value:
    /// linearise with near/far, then divide by the cosine to the view axis.
    pub fn depth_to_distance(&self, i: u32, j: u32, depth: f32) -> f32 {
        self.view_z_to_distance(i, j, self.depth_to_view_z(depth))
    }

    /// Project a world point to (pixel x, pixel y, depth), or `None` behind the eye.
    pub fn project(&self, p: Vec3) -> Option<Vec3> {
        let clip = self.view_proj() * p.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(Vec3::new(
            (ndc.x + 1.0) * 0.5 * self.width as f32,
            (1.0 - ndc.y) * 0.5 * self.height as f32,
            ndc.z,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(yaw: f32, pitch: f32, w: u32, h: u32) -> Camera {
        Camera::new(Vec3::new(100.0, 200.0, 50.0), yaw, pitch, w, h).unwrap()
    }

    #[test]
    fn yaw_conventions() {
        // Yaw 0 looks along +y, yaw 90 along +x.
        let b = cam(0.0, 0.0, 8, 8).basis();
        assert!(b.forward.abs_diff_eq(Vec3::Y, 1e-6));
        let b = cam(90.0, 0.0, 8, 8).basis();
        assert!(b.forward.abs_diff_eq(Vec3::X, 1e-6));
        // Straight down is well defined.
        let b = cam(30.0, -90.0, 8, 8).basis();
        assert!(b.forward.abs_diff_eq(-Vec3::Z, 1e-6));
        assert!(b.up.abs_diff_eq(b.flat, 1e-6));
    }

    #[test]
    fn image_is_mirrored_like_the_original_map() {
        // Looking along +y, the world's +x is on the image's left
        // (the map's y runs down the screen in the original game).
        let c = cam(0.0, 0.0, 64, 64);
        let east = c.project(c.position + Vec3::new(10.0, 100.0, 0.0)).unwrap();
        assert!(east.x < 32.0, "+x lands on the left: {east}");
        let d = c.pixel_ray(0, 32);
        assert!(d.x > 0.0);
    }

    #[test]
    fn projection_inverts_pixel_rays() {
        for (yaw, pitch) in [
            (0.0, 0.0),
            (299.0, -30.0),
            (158.0, -60.0),
            (10.0, -90.0),
            (45.0, 20.0),
        ] {
            let c = cam(yaw, pitch, 320, 200);
            for (i, j) in [(0, 0), (319, 199), (160, 100), (17, 150)] {
                let dist = 123.0;
                let p = c.position + c.pixel_ray(i, j) * dist;
                let s = c.project(p).unwrap();
                assert!((s.x - (i as f32 + 0.5)).abs() < 1e-2, "{yaw} {pitch} {s}");
                assert!((s.y - (j as f32 + 0.5)).abs() < 1e-2, "{yaw} {pitch} {s}");
                let back = c.depth_to_distance(i, j, s.z);
                assert!((back - dist).abs() < 1e-2 * dist, "{back} vs {dist}");
            }
        }
    }

    #[test]
    fn depth_range_is_near_to_far() {
        let c = cam(0.0, 0.0, 16, 16);
        assert!((c.view_z_to_depth(c.near)).abs() < 1e-6);
        assert!((c.view_z_to_depth(c.far) - 1.0).abs() < 1e-6);
        assert!(
            (c.depth_to_view_z(0.5) - c.depth_to_view_z(c.view_z_to_depth(c.depth_to_view_z(0.5))))
                .abs()
                < 1e-3
        );
    }

    #[test]
    fn focal_length_does_not_scale_with_image_size() {
        let small = cam(0.0, 0.0, 400, 260);
        let large = cam(0.0, 0.0, 1280, 800);
        let p = small.position + Vec3::new(-30.0, 256.0, 20.0);
        let a = small.project(p).unwrap();
        let b = large.project(p).unwrap();
        // 512 px focal: a point 30 units right and 20 up at distance 256 is
        // 60 px right and 40 px up of the centre at every image size.
        assert!(
            (a.x - 200.0 - 60.0).abs() < 1e-3 && (a.y - 130.0 + 40.0).abs() < 1e-3,
            "{a}"
        );
        assert!(
            (b.x - 640.0 - 60.0).abs() < 1e-3 && (b.y - 400.0 + 40.0).abs() < 1e-3,
            "{b}"
        );
    }

    #[test]
    fn views_resolve_against_the_level() {
        let level = Level::flat(64, 64, 30, 1).unwrap();
        let view = ViewSpec::parse("v", "-10,70:0:5", -30.0).unwrap();
        let c = Camera::from_view(&level, &view, 32, 16).unwrap();
        assert_eq!(c.position, Vec3::new(54.0, 6.0, 35.0));
        let inside = ViewSpec::parse("v", "1,1:0:-5", 0.0).unwrap();
        assert!(matches!(
            Camera::from_view(&level, &inside, 32, 16),
            Err(CameraError::EyeInSolid { .. })
        ));
        assert!(matches!(
            Camera::from_view(&level, &view, 0, 16),
            Err(CameraError::Size(0, 16))
        ));
    }
}
