//! The physics toy (`--physics`, key O): rigid bodies (strata-physics,
//! rapier3d) dropped where the user clicks, on the terrain collider that
//! follows the viewer's digs. The collider is built on a thread when the
//! toy is first switched on; digs made meanwhile are applied when it lands.
//! Natively only: in a browser the toy says so and stays off.

use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};

#[cfg(not(target_arch = "wasm32"))]
pub use native::PhysicsToy;
#[cfg(target_arch = "wasm32")]
pub use stub::PhysicsToy;

/// Which body a click drops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drop {
    Sphere,
    Box,
}

/// Height above the clicked ground a body is dropped from.
pub const DROP_HEIGHT: f32 = 25.0;

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use super::*;
    use crate::bodies::BodyPainter;
    use std::sync::mpsc;
    use strata_physics::{BodyPose, BodyShape, PhysicsSettings, TerrainPhysics};
    use web_time::Instant;

    enum State {
        Off,
        /// The collider is being fitted; edits made meanwhile wait here.
        Building {
            done: mpsc::Receiver<TerrainPhysics>,
            edits: Vec<DirtyRect>,
            started: Instant,
        },
        Ready(Box<TerrainPhysics>),
    }

    pub struct PhysicsToy {
        state: State,
        /// Stepping and drawing (a built world is kept while off).
        pub on: bool,
        painter: Option<BodyPainter>,
        /// The map's size, for drawing bodies at their copy nearest the eye.
        size: [f32; 2],
    }

    impl PhysicsToy {
        pub fn new(level: &Level) -> Self {
            PhysicsToy {
                state: State::Off,
                on: false,
                painter: None,
                size: [level.width() as f32, level.height() as f32],
            }
        }

        /// Switch on or off; the first switch on starts fitting the
        /// collider (at the mesh method's `quality`) on a thread.
        pub fn toggle(&mut self, level: &Arc<Level>, quality: f64) -> String {
            self.on = !self.on;
            if !self.on {
                return "physics off (bodies kept, paused)".into();
            }
            if let State::Off = self.state {
                let tolerance = strata_mesh::tolerance_for_quality(quality).unwrap_or(4.0);
                let (send, done) = mpsc::channel();
                let level = Arc::clone(level);
                std::thread::spawn(move || {
                    let world = TerrainPhysics::fit(&level, tolerance, PhysicsSettings::default());
                    let _ = send.send(world);
                });
                self.state = State::Building {
                    done,
                    edits: Vec::new(),
                    started: Instant::now(),
                };
                return format!(
                    "physics on: fitting the terrain collider (max error {tolerance}) ..."
                );
            }
            "physics on: left click drops a ball, Shift+click a box, middle click digs, X clears"
                .into()
        }

        /// Whether the world is built (and so clicks drop bodies).
        pub fn is_ready(&self) -> bool {
            matches!(self.state, State::Ready(_))
        }

        /// Take a finished collider build (applying the edits made
        /// meanwhile); a line to say when one landed.
        pub fn poll(&mut self, level: &Level) -> Option<String> {
            let State::Building {
                done,
                edits,
                started,
            } = &mut self.state
            else {
                return None;
            };
            let mut world = done.try_recv().ok()?;
            let seconds = started.elapsed().as_secs_f64();
            let pending = std::mem::take(edits);
            if !pending.is_empty() {
                world.apply_edit(level, &pending);
            }
            let stats = world.terrain().stats();
            self.state = State::Ready(Box::new(world));
            Some(format!(
                "physics ready in {seconds:.2} s: {} chunk colliders, {} triangles; \
                 left click drops a ball, Shift+click a box, middle click digs, X clears",
                stats.chunks, stats.triangles
            ))
        }

        /// Run the fixed steps a frame of `dt` seconds makes.
        pub fn advance(&mut self, dt: f64) {
            if let (true, State::Ready(world)) = (self.on, &mut self.state) {
                world.advance(dt);
            }
        }

        /// Drop a body onto the terrain the picture point shows.
        pub fn drop_at(&mut self, camera: &Camera, at: (f32, f32), what: Drop) -> String {
            let State::Ready(world) = &mut self.state else {
                return "physics: the collider is still being fitted".into();
            };
            let dir = camera.image_direction(at.0, at.1).as_dvec3();
            let t_max = f64::from(camera.far) * dir.length() / f64::from(camera.focal_px);
            let shape = match what {
                Drop::Sphere => BodyShape::VEHICLE_SPHERE,
                Drop::Box => BodyShape::VEHICLE_BOX,
            };
            let origin = camera.position.as_dvec3().to_array();
            match world.drop_on_ray(shape, origin, dir.to_array(), t_max, DROP_HEIGHT) {
                Ok(Some(id)) => {
                    let p = world.body(id).map_or([0.0; 3], |b| b.position);
                    format!(
                        "dropped a {} at {:.0}, {:.0}, {:.0} ({} bodies)",
                        if what == Drop::Sphere { "ball" } else { "box" },
                        p[0],
                        p[1],
                        p[2],
                        world.body_count()
                    )
                }
                Ok(None) => "nothing to drop onto there: sky".into(),
                Err(e) => format!("not dropped: {e}"),
            }
        }

        pub fn clear(&mut self) -> String {
            match &mut self.state {
                State::Ready(world) => {
                    let n = world.body_count();
                    world.clear_bodies();
                    format!("cleared {n} bodies")
                }
                _ => "no bodies to clear".into(),
            }
        }

        /// The level was edited: replace the dirty chunks' colliders now
        /// (or after the build). A line when colliders were replaced.
        pub fn edited(&mut self, level: &Level, dirty: &[DirtyRect]) -> Option<String> {
            match &mut self.state {
                State::Off => None,
                State::Building { edits, .. } => {
                    edits.extend_from_slice(dirty);
                    None
                }
                State::Ready(world) => {
                    let r = world.apply_edit(level, dirty);
                    Some(format!(
                        "physics: {} chunk(s) refit in {:.1} ms, {} collider(s) replaced in {:.2} ms",
                        r.chunks.len(),
                        r.refit_ms,
                        r.colliders_replaced,
                        r.replace_ms
                    ))
                }
            }
        }

        pub fn body_count(&self) -> usize {
            match &self.state {
                State::Ready(world) => world.body_count(),
                _ => 0,
            }
        }

        /// Draw the bodies into the renderer's picture (after a method's
        /// frame, so they compose with it by depth).
        pub fn draw(&mut self, shared: &strata_render::Shared, camera: &Camera) {
            let (true, State::Ready(world)) = (self.on, &self.state) else {
                return;
            };
            let bodies: Vec<BodyPose> = world.bodies().collect();
            if bodies.is_empty() {
                return;
            }
            let painter = self
                .painter
                .get_or_insert_with(|| BodyPainter::new(&shared.device));
            painter.draw(
                shared,
                camera.view_proj(),
                camera.position,
                self.size,
                &bodies,
            );
        }
    }
}

#[cfg(target_arch = "wasm32")]
mod stub {
    use super::*;

    /// In a browser: rapier's world and the collider fit stay native-only
    /// (the fit of a whole map would block the page's only thread).
    pub struct PhysicsToy {
        pub on: bool,
    }

    const NATIVE_ONLY: &str = "physics is native-only (run `strata view --physics`)";

    impl PhysicsToy {
        pub fn new(_: &Level) -> Self {
            PhysicsToy { on: false }
        }
        pub fn toggle(&mut self, _: &Arc<Level>, _: f64) -> String {
            NATIVE_ONLY.into()
        }
        pub fn is_ready(&self) -> bool {
            false
        }
        pub fn poll(&mut self, _: &Level) -> Option<String> {
            None
        }
        pub fn advance(&mut self, _: f64) {}
        pub fn drop_at(&mut self, _: &Camera, _: (f32, f32), _: Drop) -> String {
            NATIVE_ONLY.into()
        }
        pub fn clear(&mut self) -> String {
            NATIVE_ONLY.into()
        }
        pub fn edited(&mut self, _: &Level, _: &[DirtyRect]) -> Option<String> {
            None
        }
        pub fn body_count(&self) -> usize {
            0
        }
        pub fn draw(&mut self, _: &strata_render::Shared, _: &Camera) {}
    }
}
