//! One chunk's collider: its finest LOD as a parry3d triangle mesh.

use parry3d::math::Vector;
use parry3d::shape::TriMesh;
use std::sync::Arc;
use strata_level::Level;
use strata_mesh::{ChunkLayout, ChunkMesh, decode};

/// A chunk's triangle mesh in chunk-local coordinates: the chunk's sample
/// `(0, 0)` (texel `(cx * 128, cy * 128)`) sits at local `(0.5, 0.5)`, so
/// local coordinates stay small and exact in f32 wherever the map is.
pub struct ChunkCollider {
    /// `None` for a chunk without triangles (never for a fitted chunk).
    /// Shared so a rigid-body world (rapier3d, on the same parry3d) can hold
    /// the same mesh as a collider shape without copying it.
    pub mesh: Option<Arc<TriMesh>>,
    /// Lowest and highest altitude of its vertices.
    pub z_range: (f32, f32),
}

impl ChunkCollider {
    /// Build chunk `index` of `layout` from its fitted mesh (LOD 0), reading
    /// vertex altitudes from `level` exactly as the mesh vertex shader does.
    pub fn build(level: &Level, layout: &ChunkLayout, index: usize, mesh: &ChunkMesh) -> Self {
        let (cx, cy) = layout.coords(index);
        let stride = layout.size_x + 1;
        let positions = stride * (layout.size_y + 1);
        // Index value -> vertex number (the index list names each grid
        // sample and kind many times).
        let mut slot = vec![u32::MAX; (positions * 3) as usize];
        let mut vertices: Vec<Vector> = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        let (mut zlo, mut zhi) = (f32::MAX, f32::MIN);
        for tri in mesh.lod_triangles(0) {
            let mut t = [0u32; 3];
            for (k, &i) in tri.iter().enumerate() {
                let s = &mut slot[usize::from(i)];
                if *s == u32::MAX {
                    let (x, y, kind) = decode(i, stride, positions);
                    let c = level.column(
                        i64::from(cx * layout.size_x + x),
                        i64::from(cy * layout.size_y + y),
                    );
                    let z = f32::from([c.low, c.high, c.mid][usize::from(kind.min(2))]);
                    zlo = zlo.min(z);
                    zhi = zhi.max(z);
                    *s = vertices.len() as u32;
                    vertices.push(Vector::new(x as f32 + 0.5, y as f32 + 0.5, z));
                }
                t[k] = *s;
            }
            triangles.push(t);
        }
        // TriMesh::new fails only on an empty index list.
        let mesh = TriMesh::new(vertices, triangles).ok().map(Arc::new);
        let z_range = if mesh.is_some() {
            (zlo, zhi)
        } else {
            (0.0, 0.0)
        };
        ChunkCollider { mesh, z_range }
    }

    /// Where the chunk's local frame sits in the world: the translation
    /// `(cx * size_x, cy * size_y, 0)` that places its mesh.
    pub fn origin(layout: &ChunkLayout, index: usize) -> [f64; 3] {
        let (cx, cy) = layout.coords(index);
        [
            f64::from(cx * layout.size_x),
            f64::from(cy * layout.size_y),
            0.0,
        ]
    }

    /// Approximate heap + inline bytes (parry's own estimate for the mesh).
    pub fn memory_bytes(&self) -> usize {
        size_of::<Self>() + self.mesh.as_ref().map_or(0, |m| m.heap_memory_size())
    }

    /// Triangles in the collider.
    pub fn triangles(&self) -> usize {
        self.mesh.as_ref().map_or(0, |m| m.num_triangles())
    }
}
