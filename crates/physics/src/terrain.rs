//! The terrain's contact surfaces as fixed colliders of the rapier world,
//! built lazily around the bodies.
//!
//! A whole world's surfaces would not fit a game's memory (a 2048 x 16384
//! map has 2048 chunks of up to three 129 x 129 height fields), so only the
//! chunk cells near a body are in the world: before each step, every cell
//! within reach of a body (its bounding radius, two steps of its motion and
//! a pad) is inserted, and cells out of a wider reach are removed. The map
//! is a torus: a cell `(gx, gy)` of the unwrapped chunk grid is chunk
//! `(gx mod nx, gy mod ny)` placed at `(gx * 128, gy * 128)`, so a body near
//! an edge touches the chunk across it. Copies of a chunk share its shapes.

use rapier3d::parry::shape::SharedShape;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, PhysicsWorld, RigidBodyHandle};
use std::collections::BTreeMap;
use std::sync::Arc;
use strata_collide::TerrainCollider;

use crate::body::BodyShape;

/// Ground friction: enough for a box to stop on a gentle slope, little
/// enough for balls to roll into craters.
const FRICTION: f32 = 0.7;
/// Added to a body's reach when deciding which cells it needs.
const PAD: f32 = 4.0;
/// Cells stay while within this much more than the reach (no churn for a
/// body moving along a chunk's edge).
const KEEP: f32 = 32.0;

/// The cells in the world and the shapes of their chunks.
pub(crate) struct ChunkColliders {
    /// Per chunk in use: its surfaces (floor, slab top, slab underside).
    shapes: BTreeMap<usize, Vec<SharedShape>>,
    /// Per inserted cell: its chunk and collider handles.
    cells: BTreeMap<(i64, i64), (usize, Vec<ColliderHandle>)>,
    /// Bytes of the shapes held.
    bytes: usize,
    /// Sample spacing of the surfaces (1: every texel centre, exact).
    pub(crate) surface_step: u32,
}

/// Cells a body at `p` with `reach` touches: chunk squares of `size`
/// starting at 0.5 (the first sample of a chunk is its first texel's centre).
fn cell_range(p: f32, reach: f32, size: u32) -> std::ops::RangeInclusive<i64> {
    let s = size as f32;
    ((p - reach - 0.5) / s).floor() as i64..=((p + reach - 0.5) / s).floor() as i64
}

impl ChunkColliders {
    /// No cells yet; surfaces through every `surface_step`-th sample.
    pub(crate) fn new(surface_step: u32) -> Self {
        ChunkColliders {
            shapes: BTreeMap::new(),
            cells: BTreeMap::new(),
            bytes: 0,
            surface_step,
        }
    }

    /// Make the world hold the cells within reach of `bodies` (and drop the
    /// ones out of the wider reach).
    pub(crate) fn sync(
        &mut self,
        world: &mut PhysicsWorld,
        terrain: &TerrainCollider,
        bodies: &[(RigidBodyHandle, BodyShape)],
        dt: f32,
    ) {
        let layout = *terrain.layout();
        let mut need = Vec::new();
        let mut keep = Vec::new();
        for &(h, shape) in bodies {
            let Some(b) = world.bodies.get(h) else {
                continue;
            };
            let (t, v) = (b.translation(), b.linvel());
            let reach = shape.bounding_radius() + v.length() * dt * 2.0 + PAD;
            if !(reach.is_finite() && t.is_finite()) {
                continue;
            }
            for (list, r) in [(&mut need, reach), (&mut keep, reach + KEEP)] {
                for gy in cell_range(t.y, r, layout.size_y) {
                    for gx in cell_range(t.x, r, layout.size_x) {
                        list.push((gx, gy));
                    }
                }
            }
        }
        need.sort_unstable();
        need.dedup();
        keep.sort_unstable();
        keep.dedup();
        let gone: Vec<(i64, i64)> = self
            .cells
            .keys()
            .filter(|c| keep.binary_search(c).is_err())
            .copied()
            .collect();
        for cell in gone {
            if let Some((_, handles)) = self.cells.remove(&cell) {
                for h in handles {
                    world.remove_collider(h);
                }
            }
        }
        for cell in need {
            if !self.cells.contains_key(&cell) {
                let inserted = self.insert(world, terrain, cell);
                self.cells.insert(cell, inserted);
            }
        }
        // Shapes no cell uses any more.
        let used: std::collections::BTreeSet<usize> = self.cells.values().map(|c| c.0).collect();
        let unused: Vec<usize> = self
            .shapes
            .keys()
            .filter(|i| !used.contains(i))
            .copied()
            .collect();
        for i in unused {
            self.drop_shapes(i);
        }
    }

    fn drop_shapes(&mut self, chunk: usize) {
        if let Some(shapes) = self.shapes.remove(&chunk) {
            self.bytes -= shapes_bytes(&shapes);
        }
    }

    /// Insert cell `(gx, gy)`'s colliders: its chunk's shapes, built if new.
    fn insert(
        &mut self,
        world: &mut PhysicsWorld,
        terrain: &TerrainCollider,
        (gx, gy): (i64, i64),
    ) -> (usize, Vec<ColliderHandle>) {
        let layout = terrain.layout();
        let (nx, ny) = (i64::from(layout.chunks_x), i64::from(layout.chunks_y));
        let (cx, cy) = (gx.rem_euclid(nx), gy.rem_euclid(ny));
        let chunk = layout.index(cx as u32, cy as u32);
        if !self.shapes.contains_key(&chunk) {
            let Some(s) = terrain.chunk_surfaces_every(chunk, self.surface_step) else {
                return (chunk, Vec::new());
            };
            let shapes: Vec<SharedShape> = [Some(s.floor), s.slab_top, s.ceiling]
                .into_iter()
                .flatten()
                .map(|f| SharedShape(Arc::new(f)))
                .collect();
            self.bytes += shapes_bytes(&shapes);
            self.shapes.insert(chunk, shapes);
        }
        // The chunk's pose in its own cell, moved to cell (gx, gy).
        let s = terrain.chunk_pose(
            chunk,
            [
                ((cx - gx) * i64::from(layout.size_x)) as f64,
                ((cy - gy) * i64::from(layout.size_y)) as f64,
                0.0,
            ],
        );
        let handles = self.shapes[&chunk]
            .iter()
            .map(|shape| {
                let collider = ColliderBuilder::new(shape.clone())
                    .position(s)
                    .friction(FRICTION);
                world.insert_collider(collider, None)
            })
            .collect();
        (chunk, handles)
    }

    /// After an edit: chunks `ids` changed. Their shapes are rebuilt and
    /// their cells in the world replaced (bodies touching them wake).
    /// Returns how many colliders were replaced.
    pub(crate) fn replace(
        &mut self,
        world: &mut PhysicsWorld,
        terrain: &TerrainCollider,
        ids: &[usize],
    ) -> usize {
        let mut replaced = 0;
        for &i in ids {
            if !self.shapes.contains_key(&i) {
                continue;
            }
            self.drop_shapes(i);
            let cells: Vec<(i64, i64)> = self
                .cells
                .iter()
                .filter(|(_, c)| c.0 == i)
                .map(|(k, _)| *k)
                .collect();
            for cell in cells {
                if let Some((_, handles)) = self.cells.remove(&cell) {
                    for h in handles {
                        // Removing a collider wakes the bodies touching it.
                        world.remove_collider(h);
                        replaced += 1;
                    }
                }
                let inserted = self.insert(world, terrain, cell);
                self.cells.insert(cell, inserted);
            }
        }
        replaced
    }

    /// Chunk `i`'s collider handles in the world (all its cells, in cell order).
    pub(crate) fn of(&self, i: usize) -> Vec<ColliderHandle> {
        self.cells
            .values()
            .filter(|c| c.0 == i)
            .flat_map(|c| c.1.iter().copied())
            .collect()
    }

    /// Cells in the world.
    pub(crate) fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Bytes of the height fields held.
    pub(crate) fn memory_bytes(&self) -> usize {
        self.bytes
    }
}

fn shapes_bytes(shapes: &[SharedShape]) -> usize {
    shapes
        .iter()
        .filter_map(|s| s.as_heightfield())
        .map(|f| f.heights().data().len() * 4 + f.cells_statuses().data().len())
        .sum()
}

#[cfg(test)]
mod tests {
    #[test]
    fn cells_around_a_point_cross_the_map_edge() {
        let cells = |p, r| super::cell_range(p, r, 128).collect::<Vec<_>>();
        assert_eq!(cells(60.0, 5.0), [0]);
        assert_eq!(cells(2.0, 5.0), [-1, 0]);
        assert_eq!(cells(126.0, 5.0), [0, 1]);
        assert_eq!(cells(300.0, 200.0), [0, 1, 2, 3]);
    }
}
