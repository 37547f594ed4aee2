//! The whole level's colliders: build, refit after edits, statistics.

use crate::chunk::ChunkCollider;
use rayon::prelude::*;
use strata_level::{DirtyRect, Level};
use strata_mesh::{ChunkFitter, ChunkLayout, ChunkMesh, LevelMesh, dirty_chunks};

/// One triangle-mesh collider per chunk of a level, following its edits.
pub struct TerrainCollider {
    pub(crate) layout: ChunkLayout,
    /// Highest vertex over all chunks (rays rising above it stop).
    pub(crate) top: f32,
    tolerance: f64,
    pub(crate) chunks: Vec<ChunkCollider>,
}

/// Size of a [`TerrainCollider`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ColliderStats {
    /// Chunks (one collider each).
    pub chunks: usize,
    /// Triangles over all chunks.
    pub triangles: usize,
    /// Approximate memory of all chunk colliders (vertices, indices, BVH).
    pub memory_bytes: usize,
}

impl TerrainCollider {
    /// Fit the level's mesh at `tolerance` (see
    /// [`strata_mesh::tolerance_for_quality`]) and build every chunk.
    pub fn fit(level: &Level, tolerance: f64) -> Self {
        let mesh = LevelMesh::fit(level, tolerance);
        Self::from_mesh(level, &mesh)
    }

    /// Build every chunk from an existing fit of `level` (its index lists
    /// must not have been released).
    pub fn from_mesh(level: &Level, mesh: &LevelMesh) -> Self {
        let layout = mesh.layout;
        let chunks = mesh
            .chunks
            .par_iter()
            .enumerate()
            .map(|(i, m)| ChunkCollider::build(level, &layout, i, m))
            .collect();
        TerrainCollider {
            layout,
            top: 0.0,
            tolerance: mesh.tolerance(),
            chunks,
        }
        .with_top()
    }

    fn with_top(mut self) -> Self {
        self.update_top();
        self
    }

    fn update_top(&mut self) {
        self.top = self.chunks.iter().map(|c| c.z_range.1).fold(0.0, f32::max);
    }

    /// The fit tolerance (the mesh's max vertical error at LOD 0).
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The chunk grid.
    pub fn layout(&self) -> &ChunkLayout {
        &self.layout
    }

    /// Chunk `index`'s collider (row-major, see [`ChunkLayout`]).
    pub fn chunk(&self, index: usize) -> &ChunkCollider {
        &self.chunks[index]
    }

    /// After an edit of `level`: refit and rebuild exactly the chunks the
    /// dirty rectangles touch (as the renderer's mesh refit does). Returns
    /// their indices. A level of another size is rebuilt whole.
    pub fn apply_edit(&mut self, level: &Level, dirty: &[DirtyRect]) -> Vec<usize> {
        if ChunkLayout::of(level) != self.layout {
            *self = Self::fit(level, self.tolerance);
            return (0..self.chunks.len()).collect();
        }
        let ids = dirty_chunks(&self.layout, level.width(), level.height(), dirty);
        let (layout, tol) = (self.layout, self.tolerance);
        let fresh: Vec<ChunkCollider> = ids
            .par_iter()
            .map_init(ChunkFitter::default, |f, &i| {
                let (cx, cy) = layout.coords(i);
                let m = f.fit(level, &layout, cx, cy, tol);
                ChunkCollider::build(level, &layout, i, &m)
            })
            .collect();
        for (&i, c) in ids.iter().zip(fresh) {
            self.chunks[i] = c;
        }
        self.update_top();
        ids
    }

    /// Replace chunks from meshes someone else already refit (the renderer's
    /// mesh method, in the call that uploads them): `(chunk index, mesh)`.
    ///
    /// ```
    /// use strata_collide::TerrainCollider;
    /// use strata_mesh::{ChunkFitter, ChunkLayout};
    /// let mut level = strata_level::Level::flat(256, 128, 40, 1).unwrap();
    /// let mut collider = TerrainCollider::fit(&level, 1.0);
    /// let mut site = strata_level::EditSite::fostral();
    /// (site.centre_x, site.centre_y, site.radius, site.depth) = (60, 60, 20, 30.0);
    /// strata_level::edit::crater(&mut level, &site);
    /// // Chunk 0 refit elsewhere (as the renderer does), handed over.
    /// let layout = ChunkLayout::of(&level);
    /// let mesh = ChunkFitter::default().fit(&level, &layout, 0, 0, 1.0);
    /// collider.replace_chunks(&level, &[(0, &mesh)]);
    /// let hit = collider.cast_ray([60.5, 60.5, 100.0], [0.0, 0.0, -1.0], 200.0).unwrap();
    /// assert!(hit.point[2] < 15.0, "the crater floor: {:?}", hit.point);
    /// ```
    pub fn replace_chunks(&mut self, level: &Level, refit: &[(usize, &ChunkMesh)]) {
        let layout = self.layout;
        let fresh: Vec<(usize, ChunkCollider)> = refit
            .par_iter()
            .map(|&(i, m)| (i, ChunkCollider::build(level, &layout, i, m)))
            .collect();
        for (i, c) in fresh {
            self.chunks[i] = c;
        }
        self.update_top();
    }

    /// Chunk count, triangles and memory.
    ///
    /// ```
    /// let level = strata_level::Level::flat(256, 256, 40, 1).unwrap();
    /// let stats = strata_collide::TerrainCollider::fit(&level, 1.0).stats();
    /// assert_eq!(stats.chunks, 4);
    /// assert!(stats.triangles >= 8 && stats.memory_bytes > 0);
    /// ```
    pub fn stats(&self) -> ColliderStats {
        ColliderStats {
            chunks: self.chunks.len(),
            triangles: self.chunks.iter().map(ChunkCollider::triangles).sum(),
            memory_bytes: self.chunks.iter().map(ChunkCollider::memory_bytes).sum(),
        }
    }
}
