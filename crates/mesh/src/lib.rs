//! The mesh method's CPU side (issue 7): a greedy TIN fit of the three
//! altitude fields (`low`, `mid`, `high`) sharing one planar Delaunay
//! triangulation per 128x128 chunk, three LODs per chunk with crack-free
//! shared borders, compact emission for the GPU, and an exact local refit.
//! The outline fit ([`FitOptions::outline`], issue 17) gives the floor and
//! the slab a triangulation each instead, the slab's constrained to the
//! single/double outline. No GPU dependency.
//!
//! # Using it (the drawing side)
//! - [`LevelMesh::fit`]`(level, tolerance_for_quality(q))` gives one
//!   [`ChunkMesh`] per chunk (row-major, [`ChunkLayout`]); chunk `(cx, cy)`
//!   covers samples `[cx*128, cx*128+128]` in x and y, its last row and
//!   column wrapping into the next chunk (the map is a torus).
//! - A chunk is only a `u16` index list ([`ChunkMesh::indices`]); there is
//!   no vertex buffer. An index is `kind * 129² + y * 129 + x`
//!   ([`encode`]/[`decode`]; kind 0 floor `low`, 1 slab top `high`, 2 cave
//!   ceiling `mid`). The vertex shader decodes the terrain column at chunk
//!   origin + (x, y) from the terrain the GPU already holds (wrapping),
//!   exactly as `Level::column` does, and takes the altitude and terrain
//!   type of that kind (floor: lower type; top/ceiling: upper type).
//! - LOD `k` (max error `τ·2^k`, 0 the finest) is the triangle list in up
//!   to two index ranges [`ChunkMesh::lods`]`[k]` (LODs share triangles).
//!   Any LOD may sit next to any LOD: borders are identical, no skirts.
//! - Triangles are counter-clockwise seen from outside the solid in the
//!   (x, y, z-up) grid frame (see [`emit`] for walls and chunk borders).
//!   Normals are flat, from the triangle.
//! - After an edit: [`LevelMesh::refit`]`(level, dirty)` refits the touched
//!   chunks from scratch and returns the indices of those that changed;
//!   their index lists change length, so replace those ranges. Call
//!   [`LevelMesh::release_indices`] after each upload: nothing else needs
//!   the CPU copies (the refit works from the level and per-chunk hashes).
//!
//! Module map: [`predicates`] (exact integer geometry), [`triangulation`]
//! (arena + flips), [`candidate`] (worst-sample scan), [`border`] (1D edge
//! fit), [`lod`] (the LOD count, insertion causes), [`fit`] (one chunk, all
//! LODs), [`emit`] (index data),
//! [`level_mesh`] (whole level, refit, statistics), [`synthetic`] (fixture).
//!
//! # Example: fit a level, read the triangle counts, refit after an edit
//!
//! ```
//! use strata_level::{DirtyRect, Level};
//! use strata_mesh::{LevelMesh, tolerance_for_quality};
//!
//! // Flat ground at 20 with a 16 x 16 block rising to 60.
//! let mut level = Level::flat(64, 64, 20, 1).unwrap();
//! let (heights, _metas) = level.planes_mut();
//! for y in 24..40 {
//!     for x in 24..40 {
//!         heights[y * 64 + x] = 60;
//!     }
//! }
//! let tolerance = tolerance_for_quality(0.5).unwrap(); // 4 height units
//! let mut mesh = LevelMesh::fit(&level, tolerance);
//! assert_eq!(mesh.chunks.len(), 1); // a map under 128 texels is one chunk
//!
//! let stats = mesh.stats();
//! let finest = &stats.lods[0];
//! assert!(finest.planar > 2, "the block needs more than the two corner triangles");
//! assert_eq!(finest.slab, 0); // no dual columns, so no slab or ceiling
//! assert_eq!(finest.emitted, finest.planar + finest.slab + finest.wall);
//! assert_eq!(stats.gpu_bytes, 2 * mesh.chunks[0].indices.len() as u64);
//!
//! // Flatten the block again; the refit reports the chunk as changed and
//! // equals a fresh fit of the edited level.
//! let (heights, _metas) = level.planes_mut();
//! for y in 24..40 {
//!     for x in 24..40 {
//!         heights[y * 64 + x] = 20;
//!     }
//! }
//! let dirty = DirtyRect { x: 24, y: 24, width: 16, height: 16 };
//! assert_eq!(mesh.refit(&level, &[dirty]), vec![0]);
//! assert_eq!(mesh, LevelMesh::fit(&level, tolerance));
//! ```
//!
//! # Stability
//!
//! The stable surface is [`LevelMesh`] (`fit`, `fit_with_options`,
//! `fit_in_steps`, `refit`, `release_indices`, `stats`), [`ChunkMesh`] and its
//! index encoding ([`encode`]/[`decode`]), [`ChunkLayout`], [`CHUNK`], [`LODS`],
//! [`MeshStats`], [`FitOptions`] and [`tolerance_for_quality`]. The fitting
//! machinery ([`triangulation`], [`candidate`], [`predicates`], [`border`],
//! [`samples`], [`fit`]'s [`ChunkFitter`], [`emit::Emitter`]) and the timing
//! helpers ([`cpu_time`], [`timed_fit`], [`fit_on_threads`]) are public for
//! Strata's bench, tests and renderer and may change.

#![warn(missing_docs)]

pub mod border;
pub mod candidate;
pub mod cpu_time;
pub mod emit;
pub mod fit;
pub mod level_mesh;
pub mod lod;
pub mod predicates;
pub mod region;
pub mod samples;
pub mod synthetic;
pub mod triangulation;

pub use emit::{ChunkMesh, ChunkStats, LodStats, decode, encode};
pub use fit::{
    CAUSES, Cause, ChunkFitter, FitOptions, LODS, OutlinePart, OutlinePartFit, join_outline_parts,
};
pub use level_mesh::{
    ChunkRange, FitInSteps, FitTiming, LevelMesh, MeshStats, dirty_chunks, fit_chunks,
    fit_on_threads, fit_on_threads_with, timed_fit, timed_fit_with, tolerance_for_quality,
};
pub use region::Patch;
pub use samples::{CHUNK, ChunkLayout};
