//! The CPU reference every quality claim rests on (DESIGN §3): one ray per
//! pixel through the decoded level, with the shared camera, giving a sky
//! mask, the hit distance, which interval was hit and its terrain type; and
//! the metrics that score a rendered image against it.
//!
//! The ray cast is exact rather than sampled: it visits every texel column
//! the ray crosses (a 2D grid traversal, accelerated by a conservative
//! max-height pyramid) and intersects the ray's segment inside each column
//! with the column's solid intervals analytically. Nothing is skipped, so a
//! finer step cannot change a class; `tests/convergence.rs` proves it.
//! There is no march step to tune and no bisection: each column's entry
//! point is solved exactly (the paper's "march + >= 12 bisections" converges
//! to the same point).
//!
//! For many views of one level, build one [`Tracer`] (it owns the pyramid)
//! and hash the level once: [`ReferenceCache::get_or_compute_traced`].
//! [`ReferenceCache::get_or_compute`] re-hashes the level (64 MiB for a
//! Fostral-sized map) and rebuilds the pyramid on every miss.
//!
//! # Worlds larger than memory
//!
//! [`Tracer::over`] traces any [`strata_level::ColumnSource`]: a [`Level`]
//! takes the in-memory path above; a store's chunk cache
//! (`strata_store::ChunkCache`) is read a chunk at a time, the pyramid's
//! coarsest level coming from the chunk summaries and the finer ones built
//! per chunk when a ray first enters it and cached with the chunk, so no
//! whole-map array is ever built and memory stays within the cache's
//! budget. The pictures are bit-identical (`tests/store.rs`). Read errors
//! stop the rays and come back from [`Tracer::try_render`];
//! [`camera_for_view`] resolves a view against any source.
//!
//! Command line: `strata reference --out DIR [--view SPEC --pitch DEG |
//! --views FILE] [--size WxH] [--json] [--no-cache]`, then `strata metrics
//! --reference DIR/<view> --render RENDER_DIR [--json]`.
//!
//! # Example: trace a small image and read a pixel's hit
//!
//! ```
//! use glam::{DVec3, Vec3};
//! use strata_camera::Camera;
//! use strata_level::Level;
//! use strata_reference::{HitClass, ReferenceSettings, Tracer, compare};
//!
//! // Flat ground at altitude 20; the eye 30 units above it, looking straight down.
//! let level = Level::flat(64, 64, 20, 3).unwrap();
//! let camera = Camera::new(Vec3::new(32.0, 32.0, 50.0), 0.0, -90.0, 16, 16).unwrap();
//! let tracer = Tracer::new(&level); // build once per level, reuse for every view
//! let image = tracer.render(&camera, &ReferenceSettings::default());
//!
//! let centre = 8 * 16 + 8; // pixel (8, 8), row-major
//! assert_eq!(image.class[centre], HitClass::Floor);
//! assert_eq!(image.terrain[centre], 3);
//! assert!((image.distance[centre] - 30.0).abs() < 0.1);
//! assert_eq!(image.sky_fraction(), 0.0);
//!
//! // One ray on its own: from (10, 10, 50) along +x and down.
//! let dir = DVec3::new(1.0, 0.0, -1.0).normalize();
//! let hit = tracer
//!     .trace(DVec3::new(10.0, 10.0, 50.0), dir, 600.0, &ReferenceSettings::default())
//!     .unwrap();
//! assert_eq!(hit.class, HitClass::Floor);
//! assert_eq!(hit.column, [40, 10]); // 30 across for 30 down
//!
//! // A renderer's distances scored against the reference: identical, so no errors.
//! let metrics = compare(&image, &image.distance);
//! assert_eq!(metrics.see_through, 0.0);
//! assert_eq!(metrics.depth_p95, 0.0);
//! ```
//!
//! # Stability
//!
//! The stable surface is [`Tracer`] (`new`, `unaccelerated`, `over`,
//! `render`, `try_render`, `trace`), [`RayHit`], [`Reference`], [`HitClass`] (and its stored codes),
//! [`ReferenceSettings`], [`render_reference`], [`Metrics`] with [`compare`] /
//! [`metrics::try_compare`], and the on-disk view format of [`output`]
//! (`reference.json` plus the raw files). The colour reference ([`shading`],
//! [`shadow_map`]) follows the GPU shading and may change with it, as may the
//! cache's key scheme and directory layout ([`cache`]); the version constants
//! say when outputs change.

#![warn(missing_docs)]

pub mod cache;
pub mod metrics;
pub mod output;
mod pyramid;
mod raycast;
pub mod shading;
pub mod shadow_map;
mod tiled;

use serde::{Deserialize, Serialize};
use strata_camera::Camera;
use strata_level::source::{ColumnSource, SourceError};
use strata_level::{Level, ViewSpec};

pub use cache::{ReferenceCache, default_cache_dir};
pub use metrics::{Metrics, compare, distance_from_depth};
pub use raycast::{RayHit, Tracer};
pub use shading::{ColorImage, TerrainRamps, render_color, render_color_checked};
pub use shadow_map::ShadowMap;

/// Bumped whenever the reference's output for the same level and camera can
/// change; part of every cache key.
pub const REFERENCE_VERSION: u32 = 1;

/// Bumped whenever the colour reference (`shading`, `shadow_map`) can change
/// for the same level, camera and colours; part of every colour cache key.
/// 2: the shadow map's texels on the light's lattice, in steps of size.
pub const COLOR_VERSION: u32 = 2;

/// What a pixel's ray hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum HitClass {
    /// Nothing before the far plane (or above the highest column).
    #[default]
    Sky = 0,
    /// The floor interval `[0, low]`, entered from above.
    Floor = 1,
    /// The slab `[mid, high]` of a dual column, entered from above.
    SlabTop = 2,
    /// The slab's underside at `mid`, entered from below (inside a cave).
    CaveCeiling = 3,
    /// A column entered through one of its vertical sides.
    Wall = 4,
}

impl HitClass {
    /// Every class, in code order.
    pub const ALL: [HitClass; 5] = [
        HitClass::Sky,
        HitClass::Floor,
        HitClass::SlabTop,
        HitClass::CaveCeiling,
        HitClass::Wall,
    ];

    /// The class stored as `code` by [`HitClass::code`], if any.
    pub fn from_code(code: u8) -> Option<HitClass> {
        Self::ALL.get(usize::from(code)).copied()
    }

    /// The byte stored in `class.u8` (0 sky .. 4 wall).
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// One reference image, row-major, `width * height` entries per field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Distance from the eye along the pixel's ray; `f32::INFINITY` is sky.
    pub distance: Vec<f32>,
    /// Which interval each pixel's ray hit ([`HitClass::Sky`] for none).
    pub class: Vec<HitClass>,
    /// Terrain type (0..7) of the interval hit; 0 for sky.
    pub terrain: Vec<u8>,
}

impl Reference {
    /// `width * height`.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Percent of pixels that are sky.
    pub fn sky_fraction(&self) -> f64 {
        let sky = self.distance.iter().filter(|d| !d.is_finite()).count();
        100.0 * sky as f64 / self.pixel_count().max(1) as f64
    }

    /// Smallest, median and largest hit distance, or `None` when all sky.
    /// The median is the lower middle value of the sorted hits.
    pub fn distance_summary(&self) -> Option<(f32, f32, f32)> {
        let mut hits: Vec<f32> = self
            .distance
            .iter()
            .copied()
            .filter(|d| d.is_finite())
            .collect();
        if hits.is_empty() {
            return None;
        }
        hits.sort_unstable_by(f32::total_cmp);
        Some((hits[0], hits[(hits.len() - 1) / 2], hits[hits.len() - 1]))
    }
}

/// Knobs of the reference, for the convergence test; the default is the
/// reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ReferenceSettings {
    /// Traversal cells per texel side (a power of two, 1..=64). 2 halves the
    /// step: each column's ray segment is cut at every half-texel line and
    /// each piece intersected separately. The result must not change.
    pub subdivision: u32,
    /// Skip tiles the ray passes above using the max-height pyramid. Exact
    /// either way; off only to check that.
    pub accelerate: bool,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            subdivision: 1,
            accelerate: true,
        }
    }
}

/// A view could not be resolved against a column source.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// The column under the view could not be read.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// The view itself is bad (eye in solid terrain, bad pitch or size).
    #[error(transparent)]
    Camera(#[from] strata_camera::CameraError),
}

/// [`Camera::from_view`] against any column source (one column is read):
/// the same wrap, eye height and checks, for a map that is not in memory.
pub fn camera_for_view(
    source: &dyn ColumnSource,
    view: &ViewSpec,
    width: u32,
    height: u32,
) -> Result<Camera, ViewError> {
    if let Some(level) = source.as_level() {
        return Ok(Camera::from_view(level, view, width, height)?);
    }
    let (w, h) = source.size();
    let x = view.x.rem_euclid(w as f32);
    let y = view.y.rem_euclid(h as f32);
    let column = source.column(x.floor() as i64, y.floor() as i64)?;
    let base = if view.under { column.low } else { column.top() };
    let z = f32::from(base) + view.eye;
    if column.is_solid(z) {
        return Err(strata_camera::CameraError::EyeInSolid {
            name: view.name.clone(),
            x,
            y,
            z,
            low: column.low,
            mid: column.mid,
            high: column.high,
        }
        .into());
    }
    Ok(Camera::new(
        glam::Vec3::new(x, y, z),
        view.yaw,
        view.pitch,
        width,
        height,
    )?)
}

/// The reference image of `level` seen through `camera`.
pub fn render_reference(level: &Level, camera: &Camera) -> Reference {
    Tracer::new(level).render(camera, &ReferenceSettings::default())
}

/// [`render_reference`] with explicit settings.
pub fn render_reference_with(
    level: &Level,
    camera: &Camera,
    settings: &ReferenceSettings,
) -> Reference {
    Tracer::new(level).render(camera, settings)
}
