//! Rigid bodies on Strata's terrain (issues 18 and 35): a [rapier3d] world
//! whose ground is the exact [`TerrainCollider`](strata_collide::TerrainCollider)'s
//! contact surfaces (parry3d height fields of the floor, slab tops and slab
//! undersides, per 128x128 chunk, built lazily for the chunks around the
//! bodies so memory stays small), and whose ground follows edits:
//! [`TerrainPhysics::apply_edit`] updates the collider and replaces exactly
//! the dirty chunks' colliders, so bodies resting on dug ground fall into
//! the new crater. No GPU: the viewer draws the bodies; tests and
//! `strata collide --physics-bench` run it headless.
//!
//! rapier3d 0.36 is built on parry3d 0.31, the geometry library
//! `strata-collide` builds its height fields with, so they go into the
//! world as they are (shared between a chunk's copies, never converted).
//!
//! ```
//! use strata_physics::{BodyShape, PhysicsSettings, TerrainPhysics};
//! let mut level = strata_level::Level::flat(256, 256, 40, 1).unwrap();
//! let mut physics = TerrainPhysics::fit(&level, 1.0, PhysicsSettings::default());
//! let ball = physics.drop_body(BodyShape::Sphere { radius: 5.0 }, [100.5, 100.5, 80.0]).unwrap();
//! for _ in 0..240 {
//!     physics.step();
//! }
//! let z = physics.body(ball).unwrap().position[2];
//! assert!((z - 45.0).abs() < 0.5, "resting on the ground at 40: {z}");
//! // Dig under it: the chunk's colliders are replaced and the ball falls.
//! let mut site = strata_level::EditSite::fostral();
//! (site.centre_x, site.centre_y, site.radius, site.depth) = (100, 100, 20, 30.0);
//! let dirty = strata_level::edit::crater(&mut level, &site);
//! let report = physics.apply_edit(&level, &dirty);
//! assert_eq!(report.chunks, [0]);
//! ```
//!
//! Stability: [`TerrainPhysics`] (`new`, `fit`, `drop_body`, `drop_on_ray`,
//! `step`, `advance`, `apply_edit`, `bodies`, `clear_bodies`),
//! [`BodyShape`], [`BodyPose`] and [`PhysicsSettings`] are the stable
//! surface; [`TerrainPhysics::world`] hands out rapier's own types, which
//! follow rapier's versions.

#![warn(missing_docs)]

mod body;
mod clock;
mod terrain;
mod world;

pub use body::{BodyId, BodyPose, BodyShape};
pub use clock::FixedStep;
pub use rapier3d;
pub use world::{EditReport, PhysicsSettings, TerrainPhysics};

/// Bad input to the physics world.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    /// A body size that is not positive and finite.
    #[error("body {0:?}: size {1} must be positive and finite")]
    BadSize(BodyShape, f32),
    /// A drop position that is not finite.
    #[error("drop position {0:?} is not finite")]
    BadPosition([f32; 3]),
}
