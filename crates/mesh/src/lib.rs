//! The mesh method's CPU side (issue 7): a greedy TIN fit of the three
//! altitude fields (`low`, `mid`, `high`) sharing one planar Delaunay
//! triangulation per 128x128 chunk, three LODs per chunk with crack-free
//! shared borders, compact emission for the GPU, and an exact local refit.
//! No GPU dependency.
//!
//! Module map: [`predicates`] (exact integer geometry), [`triangulation`]
//! (arena + flips), [`candidate`] (worst-sample scan), [`border`] (1D edge
//! fit), [`fit`] (one chunk, all LODs), [`emit`] (vertex/index data),
//! [`level_mesh`] (whole level, refit, statistics), [`synthetic`] (fixture).

pub mod border;
pub mod candidate;
pub mod cpu_time;
pub mod emit;
pub mod fit;
pub mod level_mesh;
pub mod predicates;
pub mod samples;
pub mod synthetic;
pub mod triangulation;

pub use emit::{ChunkMesh, ChunkStats, LodStats, decode, encode};
pub use fit::{CAUSES, Cause, ChunkFitter, LODS};
pub use level_mesh::{
    ChunkRange, FitTiming, LevelMesh, MeshStats, dirty_chunks, fit_on_threads, timed_fit,
    tolerance_for_quality,
};
pub use samples::{CHUNK, ChunkLayout};
