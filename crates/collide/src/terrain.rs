//! The whole level's collider: build, follow edits, statistics.

use crate::columns::Columns;
use strata_level::{DirtyRect, Level};
use strata_mesh::{ChunkLayout, dirty_chunks};

/// The terrain's exact collider: a packed copy of every texel's column and
/// a max-height pyramid (see the crate docs), following the level's edits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TerrainCollider {
    pub(crate) layout: ChunkLayout,
    pub(crate) columns: Columns,
}

/// Size of a [`TerrainCollider`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ColliderStats {
    /// Chunks of the map (the units edits report and contact surfaces are
    /// built in; 128 x 128 texels).
    pub chunks: usize,
    /// Triangles held: none (the collider holds columns; contact surfaces
    /// are built on demand, see [`TerrainCollider::chunk_surfaces`]).
    pub triangles: usize,
    /// Texel columns held (the map's area).
    pub columns: usize,
    /// Memory of the columns and the pyramid, bytes.
    pub memory_bytes: usize,
}

impl TerrainCollider {
    /// The collider of `level`: every column decoded and packed, the
    /// pyramid built (all cores).
    ///
    /// ```
    /// use strata_collide::TerrainCollider;
    /// let level = strata_level::Level::flat(256, 128, 40, 1).unwrap();
    /// let collider = TerrainCollider::new(&level);
    /// let hit = collider.cast_ray([10.5, 10.5, 100.0], [0.0, 0.0, -1.0], 200.0).unwrap();
    /// assert_eq!(hit.distance, 60.0);
    /// assert_eq!(collider.stats().memory_bytes / (256 * 128), 4, "4 bytes a texel");
    /// ```
    pub fn new(level: &Level) -> Self {
        TerrainCollider {
            layout: ChunkLayout::of(level),
            columns: Columns::new(level),
        }
    }

    /// [`TerrainCollider::new`]; `tolerance` is ignored (the collider is
    /// exact to the texel model: there is no fit). Kept for callers of the
    /// former triangle-mesh collider.
    pub fn fit(level: &Level, tolerance: f64) -> Self {
        let _ = tolerance;
        Self::new(level)
    }

    /// Vertical error of the collider against the texel model: 0.
    pub fn tolerance(&self) -> f64 {
        0.0
    }

    /// The chunk grid (128 x 128 texels, fewer on a smaller map).
    pub fn layout(&self) -> &ChunkLayout {
        &self.layout
    }

    /// After an edit of `level`: re-decode the texels of the dirty
    /// rectangles and refresh the pyramid over them. Returns the chunks
    /// whose contact surfaces changed (see [`strata_mesh::dirty_chunks`]).
    /// A level of another size is rebuilt whole; rectangles reaching past
    /// the map wrap onto it.
    pub fn apply_edit(&mut self, level: &Level, dirty: &[DirtyRect]) -> Vec<usize> {
        if (level.width(), level.height()) != (self.columns.width(), self.columns.height())
            || level.mid_rule != self.columns.mid_rule
        {
            *self = Self::new(level);
            return (0..self.layout.count()).collect();
        }
        for r in dirty {
            self.columns.update(level, r);
        }
        dirty_chunks(&self.layout, level.width(), level.height(), dirty)
    }

    /// Chunk count, columns and memory.
    ///
    /// ```
    /// let level = strata_level::Level::flat(256, 256, 40, 1).unwrap();
    /// let stats = strata_collide::TerrainCollider::new(&level).stats();
    /// assert_eq!((stats.chunks, stats.columns), (4, 256 * 256));
    /// ```
    pub fn stats(&self) -> ColliderStats {
        ColliderStats {
            chunks: self.layout.count(),
            triangles: 0,
            columns: self.columns.width() as usize * self.columns.height() as usize,
            memory_bytes: self.columns.memory_bytes(),
        }
    }
}
