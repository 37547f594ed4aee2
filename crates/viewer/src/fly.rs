//! The fly camera: a free eye with yaw and pitch, moved by keys and turned by
//! the mouse, that becomes a [`Camera`] each frame and a `views.txt` line on
//! request. Pure CPU state, so its conventions are unit-tested here.

use glam::Vec3;
use strata_camera::Camera;
use strata_level::{Column, ViewSpec};

/// Base flying speed, world units (texels) per second; Shift multiplies it.
pub const DEFAULT_SPEED: f32 = 80.0;
/// The Shift multiplier.
pub const FAST: f32 = 4.0;
/// Degrees of turn per pixel of mouse motion.
pub const LOOK_DEG_PER_PX: f32 = 0.15;
/// Pitch stays a little inside ±90° so yaw keeps its meaning.
const MAX_PITCH: f32 = 89.5;

/// Which movement keys are held: each axis in -1..=1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Along the view direction (W / S).
    pub forward: f32,
    /// Towards the screen's right (D / A).
    pub right: f32,
    /// Along world z (Space, E / C, Q).
    pub up: f32,
    /// Shift.
    pub fast: bool,
}

impl Motion {
    pub fn is_still(&self) -> bool {
        self.forward == 0.0 && self.right == 0.0 && self.up == 0.0
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub position: Vec3,
    pub yaw_deg: f32,
    pub pitch_deg: f32,
    /// Units per second without Shift.
    pub speed: f32,
}

impl FlyCamera {
    pub fn from_camera(camera: &Camera) -> Self {
        FlyCamera {
            position: camera.position,
            yaw_deg: camera.yaw_deg,
            pitch_deg: camera.pitch_deg.clamp(-MAX_PITCH, MAX_PITCH),
            speed: DEFAULT_SPEED,
        }
    }

    /// The camera for one frame of `width` x `height`.
    pub fn camera(&self, width: u32, height: u32) -> anyhow::Result<Camera> {
        Ok(Camera::new(
            self.position,
            self.yaw_deg,
            self.pitch_deg,
            width,
            height,
        )?)
    }

    /// Move for `dt` seconds, then wrap onto the map (a torus in x and y)
    /// and keep the eye within the altitude range the renderers march.
    /// `world` is the map's width and height, texels.
    pub fn fly(&mut self, motion: &Motion, dt: f32, world: (u32, u32)) {
        let basis = self.basis();
        let speed = self.speed * if motion.fast { FAST } else { 1.0 };
        // The image's x axis runs along -right (the camera's mirrored screen).
        let dir = basis.forward * motion.forward - basis.right * motion.right + Vec3::Z * motion.up;
        self.position += dir * speed * dt;
        self.wrap(world);
    }

    /// Move by `offset` in camera terms: along the view, the screen's right,
    /// world up (the script's `fly`).
    pub fn translate(&mut self, offset: Vec3, world: (u32, u32)) {
        let b = self.basis();
        self.position += b.forward * offset.x - b.right * offset.y + Vec3::Z * offset.z;
        self.wrap(world);
    }

    /// Turn by a mouse motion in pixels: right turns right, down looks down.
    pub fn look(&mut self, dx_px: f32, dy_px: f32) {
        self.turn(dx_px * LOOK_DEG_PER_PX, -dy_px * LOOK_DEG_PER_PX);
    }

    /// Turn right by `right_deg` and up by `up_deg`.
    pub fn turn(&mut self, right_deg: f32, up_deg: f32) {
        // Yaw 0 looks along +y and 90 along +x, and the screen's right is
        // -right = -(flat x Z): turning right is a decreasing yaw.
        self.yaw_deg = (self.yaw_deg - right_deg).rem_euclid(360.0);
        self.pitch_deg = (self.pitch_deg + up_deg).clamp(-MAX_PITCH, MAX_PITCH);
    }

    fn basis(&self) -> strata_camera::Basis {
        // The basis depends only on yaw and pitch.
        Camera {
            position: self.position,
            yaw_deg: self.yaw_deg,
            pitch_deg: self.pitch_deg,
            focal_px: strata_camera::DEFAULT_FOCAL_PX,
            near: strata_camera::DEFAULT_NEAR,
            far: strata_camera::DEFAULT_FAR,
            width: 1,
            height: 1,
        }
        .basis()
    }

    fn wrap(&mut self, (width, height): (u32, u32)) {
        self.position.x = self.position.x.rem_euclid(width as f32);
        self.position.y = self.position.y.rem_euclid(height as f32);
        // Heights are 0..255; a little room above for looking down on it all.
        self.position.z = self.position.z.clamp(0.5, 400.0);
    }

    /// The current eye as a `views.txt` entry: the eye height is measured
    /// above the column's top surface, or above its floor (`under`) when the
    /// eye is below the top (inside a cave), so [`Camera::from_view`] gives
    /// this camera back. `column` is the one under the eye.
    pub fn view_spec(&self, column: Column, name: &str) -> ViewSpec {
        let z = self.position.z;
        let top = f32::from(column.top());
        let (eye, under) = if z >= top {
            (z - top, false)
        } else {
            (z - f32::from(column.low), true)
        };
        let round = |v: f32, k: f32| (v * k).round() / k;
        ViewSpec {
            name: name.to_string(),
            x: round(self.position.x, 10.0),
            y: round(self.position.y, 10.0),
            yaw: round(self.yaw_deg, 10.0),
            eye: round(eye, 100.0),
            under,
            pitch: round(self.pitch_deg, 10.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use strata_level::Level;

    fn level() -> Level {
        Level::flat(256, 512, 100, 1).unwrap()
    }

    fn fly_cam(yaw: f32, pitch: f32) -> FlyCamera {
        FlyCamera {
            position: Vec3::new(100.0, 100.0, 150.0),
            yaw_deg: yaw,
            pitch_deg: pitch,
            speed: DEFAULT_SPEED,
        }
    }

    /// Where a world point lands on screen, for the convention checks.
    fn screen_x(cam: &FlyCamera, p: Vec3) -> f32 {
        cam.camera(320, 200).unwrap().project(p).unwrap().x
    }

    #[test]
    fn strafing_right_moves_the_eye_to_the_screen_right() {
        let size = (256, 512);
        for yaw in [0.0, 37.0, 90.0, 200.0] {
            let mut cam = fly_cam(yaw, -20.0);
            let ahead = cam.position + cam.basis().forward * 50.0;
            let before = screen_x(&cam, ahead);
            let motion = Motion {
                right: 1.0,
                ..Default::default()
            };
            cam.fly(&motion, 0.1, size);
            // The eye went right, so a fixed point ahead appears further left.
            assert!(screen_x(&cam, ahead) < before - 1.0, "yaw {yaw}");
        }
    }

    #[test]
    fn turning_right_brings_the_screen_right_to_the_centre() {
        for yaw in [0.0, 90.0, 311.0] {
            let mut cam = fly_cam(yaw, 0.0);
            let c = cam.camera(320, 200).unwrap();
            // A point ahead that the camera shows right of the centre.
            let p = c.position + c.image_direction(260.0, 100.0);
            assert!(screen_x(&cam, p) > 160.0);
            cam.look(40.0, 0.0);
            let after = screen_x(&cam, p);
            assert!(after < 260.0 - 10.0, "yaw {yaw}: {after}");
        }
        let mut cam = fly_cam(0.0, 0.0);
        cam.look(0.0, 100.0);
        assert!(cam.pitch_deg < 0.0, "moving the mouse down looks down");
        cam.turn(0.0, -500.0);
        assert_eq!(cam.pitch_deg, -MAX_PITCH);
    }

    #[test]
    fn flying_wraps_around_the_map_and_shift_is_faster() {
        let size = (256, 512);
        let mut slow = fly_cam(0.0, 0.0);
        slow.position.y = 510.0;
        let forward = Motion {
            forward: 1.0,
            ..Default::default()
        };
        slow.fly(&forward, 0.1, size);
        assert!((slow.position.y - (510.0 + 8.0 - 512.0)).abs() < 1e-3);
        let mut fast = fly_cam(0.0, 0.0);
        fast.fly(
            &Motion {
                fast: true,
                ..forward
            },
            0.1,
            size,
        );
        assert!((fast.position.y - (100.0 + 8.0 * FAST)).abs() < 1e-3);
    }

    #[test]
    fn a_copied_view_resolves_back_to_the_same_camera() {
        let mut level = level();
        // A slab over a cave: floor 40, ceiling 120, top 160 around (50, 60).
        strata_level::edit::edit_columns(
            &mut level,
            strata_level::edit::EditRect {
                x: 40,
                y: 50,
                width: 20,
                height: 20,
            },
            |_, _, c| strata_level::Column {
                low: 40,
                mid: 120,
                high: 160,
                dual: true,
                ..c
            },
        );
        for (z, under) in [(200.0, false), (60.0, true)] {
            let cam = FlyCamera {
                position: Vec3::new(50.0, 60.0, z),
                yaw_deg: 33.3,
                pitch_deg: -12.5,
                speed: DEFAULT_SPEED,
            };
            let spec = cam.view_spec(level.column_at(50.0, 60.0), "copied");
            assert_eq!(spec.under, under);
            let line = spec.to_string();
            let parsed = strata_level::views::parse_views(&line).unwrap();
            let back = Camera::from_view(&level, &parsed[0], 320, 200).unwrap();
            assert!((back.position - cam.position).length() < 0.1, "{line}");
            assert!((back.yaw_deg - 33.3).abs() < 0.06 && back.pitch_deg == -12.5);
        }
    }
}
