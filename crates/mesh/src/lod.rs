//! The shapes of a chunk's counters, shared by the fit ([`crate::fit`]),
//! which fills them, and the emitter ([`crate::emit`]), which carries them:
//! the LOD count and the causes of a vertex insertion.

/// Number of LODs per chunk; LOD `k` has max error `τ · 2^k`.
pub const LODS: usize = 3;

/// Why a vertex was inserted (issue 7 accounting).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Cause {
    /// `low` had the largest error (ties go to `low`).
    Floor = 0,
    /// `mid` or `high` had the largest error, the triangle's three vertices
    /// are dual and so are the sample and its eight neighbours in the chunk:
    /// the slab's own relief.
    SlabInterior = 1,
    /// `mid` or `high` had the largest error otherwise: the sample is single
    /// or on the edge of a dual region, or the triangle straddles a
    /// single↔dual transition (some vertices single). These are the
    /// insertions the transition forces: a single sample has
    /// `mid = high = low`, so both step by the slab thickness across it.
    Boundary = 2,
    /// A vertex of the 1D fit of a chunk edge.
    Border = 3,
}

/// Number of [`Cause`] variants (the length of the per-cause counters).
pub const CAUSES: usize = 4;
