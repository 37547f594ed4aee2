//! The terrain collider (issues 18 and 35): exact to the texel model, small
//! enough for a game, following edits.
//!
//! The collider keeps every texel's decoded column (`[0, low]` and, for a
//! dual pair, `[mid, high]`) packed in 4 bytes, and a max-height pyramid of
//! column tops over tiles of 4..256 texels (under 0.07 bytes a texel): 128
//! MiB for a 2048 x 16384 world, against 2.4 GB for the former triangle
//! mesh. Ray casts walk the pyramid as the CPU reference does and intersect
//! each crossed column's intervals, so their hits are the reference's (same
//! column, same distance), grazing rays included. Contacts (box queries, the
//! physics crate's bodies) use parry3d height fields over texel-centre
//! samples, one per surface (floor, slab top, slab underside, cells removed
//! where a surface does not exist), built on demand for the area asked
//! about ([`surface`]). An edit re-decodes the dirty texels and refreshes
//! the pyramid tiles over them: microseconds for a small edit.
//!
//! The frame is the renderer's: x, y in texels, z up, texel `(x, y)` the
//! unit square `[x, x + 1) x [y, y + 1)`, contact samples at texel centres.
//!
//! # Using it
//! ```
//! use strata_collide::TerrainCollider;
//! let level = strata_mesh::synthetic::synthetic_level(256, 256, 1);
//! let mut collider = TerrainCollider::new(&level);
//! // Straight down onto the ground: the column's top, exactly.
//! let hit = collider
//!     .cast_ray([100.5, 100.5, 300.0], [0.0, 0.0, -1.0], 1000.0)
//!     .expect("the ground is below");
//! assert_eq!(hit.point[2], f64::from(level.column(100, 100).top()));
//! // After an edit, the dirty texels are re-read.
//! let mut site = strata_level::EditSite::fostral();
//! (site.centre_x, site.centre_y, site.radius, site.depth) = (100, 100, 20, 30.0);
//! let mut level = level;
//! let dirty = strata_level::edit::crater(&mut level, &site);
//! let chunks = collider.apply_edit(&level, &dirty);
//! assert!(!chunks.is_empty());
//! let hit = collider.cast_ray([100.5, 100.5, 300.0], [0.0, 0.0, -1.0], 1000.0).unwrap();
//! assert_eq!(hit.point[2], f64::from(level.column(100, 100).top()));
//! ```
//!
//! The map is a torus: queries take unwrapped world coordinates and see the
//! map repeated around them.
//!
//! Stability: [`TerrainCollider`], [`RayHit`], [`Face`], [`BoxContact`],
//! [`BoxCastHit`], [`BoxShape`], [`ColliderStats`] and [`surface::Surfaces`]
//! are the stable surface.

#![warn(missing_docs)]

mod columns;
pub mod query;
mod ray;
pub mod surface;
pub mod terrain;

pub use parry3d;
pub use query::{BoxCastHit, BoxContact, BoxShape, RayHit};
pub use ray::Face;
pub use terrain::{ColliderStats, TerrainCollider};
