//! Terrain colliders that follow edits (issue 18).
//!
//! The mesh method's fitted TIN ([`strata_mesh`]) doubles as a conventional
//! triangle collider: one [`parry3d`] [`TriMesh`](parry3d::shape::TriMesh)
//! per 128x128 chunk from its finest LOD (floor, slab top, cave ceiling and
//! walls), in the same world frame the renderer draws (x, y texels, z up,
//! samples at texel centres `(x + 0.5, y + 0.5)`).
//!
//! # Using it
//! ```
//! use strata_collide::TerrainCollider;
//! let level = strata_mesh::synthetic::synthetic_level(256, 256, 1);
//! let mut collider = TerrainCollider::fit(&level, 1.0);
//! // Straight down onto the ground.
//! let hit = collider
//!     .cast_ray([100.5, 100.5, 300.0], [0.0, 0.0, -1.0], 1000.0)
//!     .expect("the ground is below");
//! assert!(hit.distance > 0.0);
//! // After an edit, exactly the dirty chunks are rebuilt.
//! let mut site = strata_level::EditSite::fostral();
//! (site.centre_x, site.centre_y, site.radius, site.depth) = (100, 100, 20, 30.0);
//! let mut level = level;
//! let dirty = strata_level::edit::crater(&mut level, &site);
//! let rebuilt = collider.apply_edit(&level, &dirty);
//! assert!(!rebuilt.is_empty());
//! ```
//!
//! The map is a torus: queries take unwrapped world coordinates and see the
//! chunk copies around them ([`query`]). A renderer that already refit the
//! dirty chunks hands them over with [`TerrainCollider::replace_chunks`]
//! (the `mesh` method does, through `strata_render`'s refit listener), so the
//! collider changes on the same consistency boundary as the GPU buffers.
//!
//! Stability: [`TerrainCollider`], [`RayHit`], [`BoxContact`], [`BoxCastHit`]
//! and [`ColliderStats`] are the stable surface; [`chunk`] is an
//! implementation detail exposed for benchmarks.

#![warn(missing_docs)]

pub mod chunk;
pub mod query;
pub mod terrain;

pub use parry3d;
pub use query::{BoxCastHit, BoxContact, BoxShape, RayHit};
pub use terrain::{ColliderStats, TerrainCollider};
