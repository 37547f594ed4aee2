//! The terrain's chunk meshes as fixed colliders of the rapier world.
//!
//! The map is a torus. Bodies are kept inside it (see
//! [`crate::TerrainPhysics`]), and a body near an edge must touch the
//! chunks across it, so each chunk is placed at its own cell and at the
//! cells of the one-chunk ring around the map where it repeats. Every copy
//! shares the chunk's one `Arc<TriMesh>`.

use rapier3d::parry::shape::SharedShape;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, PhysicsWorld, Vector};
use strata_collide::TerrainCollider;
use strata_collide::chunk::ChunkCollider;
use strata_mesh::ChunkLayout;

/// Ground friction: enough for a box to stop on a gentle slope, little
/// enough for balls to roll into craters.
const FRICTION: f32 = 0.7;

/// Per chunk, the handles of its colliders in the world (in place and
/// across the map's edges).
#[derive(Default)]
pub(crate) struct ChunkColliders {
    handles: Vec<Vec<ColliderHandle>>,
}

/// The cells `g` in `-1..=n` (the map and its one-chunk ring) that repeat
/// chunk coordinate `c`.
fn cells(c: u32, n: u32) -> impl Iterator<Item = i64> {
    let n = i64::from(n);
    (-1..=n).filter(move |g| g.rem_euclid(n) == i64::from(c))
}

impl ChunkColliders {
    /// Insert every chunk of `terrain`.
    pub(crate) fn insert_all(world: &mut PhysicsWorld, terrain: &TerrainCollider) -> Self {
        let handles = (0..terrain.layout().count())
            .map(|i| insert_chunk(world, terrain.layout(), i, terrain.chunk(i)))
            .collect();
        ChunkColliders { handles }
    }

    /// Replace chunks `ids` with `terrain`'s current meshes; returns how many
    /// colliders (chunks and their copies) were replaced.
    pub(crate) fn replace(
        &mut self,
        world: &mut PhysicsWorld,
        terrain: &TerrainCollider,
        ids: &[usize],
    ) -> usize {
        let mut replaced = 0;
        for &i in ids {
            // Removing a collider wakes the bodies touching it: bodies
            // resting on the old ground fall onto the new one.
            for h in self.handles[i].drain(..) {
                world.remove_collider(h);
                replaced += 1;
            }
            self.handles[i] = insert_chunk(world, terrain.layout(), i, terrain.chunk(i));
        }
        replaced
    }

    /// Chunk `i`'s collider handles.
    pub(crate) fn of(&self, i: usize) -> &[ColliderHandle] {
        &self.handles[i]
    }
}

fn insert_chunk(
    world: &mut PhysicsWorld,
    layout: &ChunkLayout,
    i: usize,
    chunk: &ChunkCollider,
) -> Vec<ColliderHandle> {
    let Some(mesh) = &chunk.mesh else {
        return Vec::new();
    };
    let (cx, cy) = layout.coords(i);
    let mut out = Vec::new();
    for gy in cells(cy, layout.chunks_y) {
        for gx in cells(cx, layout.chunks_x) {
            // The same mesh, shared: no copy, no conversion.
            let shape = SharedShape(mesh.clone());
            let at = Vector::new(
                (gx * i64::from(layout.size_x)) as f32,
                (gy * i64::from(layout.size_y)) as f32,
                0.0,
            );
            let collider = ColliderBuilder::new(shape)
                .translation(at)
                .friction(FRICTION);
            out.push(world.insert_collider(collider, None));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn each_chunk_repeats_across_the_edge_it_touches() {
        let cells = |c, n| super::cells(c, n).collect::<Vec<_>>();
        assert_eq!(cells(0, 4), [0, 4]);
        assert_eq!(cells(3, 4), [-1, 3]);
        assert_eq!(cells(1, 4), [1]);
        // A map one chunk wide: the chunk on both sides.
        assert_eq!(cells(0, 1), [-1, 0, 1]);
    }
}
