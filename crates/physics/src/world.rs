//! [`TerrainPhysics`]: a rapier world on the terrain collider, stepped at a
//! fixed rate, whose terrain follows edits chunk by chunk.

use crate::PhysicsError;
use crate::body::{BodyId, BodyPose, BodyShape};
use crate::clock::FixedStep;
use crate::terrain::ChunkColliders;
use rapier3d::prelude::{PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, Vector};
use strata_collide::TerrainCollider;
use strata_level::{DirtyRect, Level};
use web_time::Instant;

/// How the world moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsSettings {
    /// Downward acceleration, units per second² (a texel is a few
    /// decimetres, so this is stronger than 9.81 to look like Earth's).
    pub gravity: f32,
    /// Seconds per step.
    pub step: f64,
    /// Most steps one [`TerrainPhysics::advance`] runs (see [`FixedStep`]).
    pub max_steps_per_advance: u32,
    /// Continuous collision detection on dropped bodies: fast bodies do
    /// not tunnel through the terrain's thin surfaces.
    pub ccd: bool,
    /// Spacing, in texels, of the terrain surface's samples in the world:
    /// 1 (the default) puts every texel centre in, the surface exact to the
    /// texel model's heights; 2 or 4 keep every 2nd or 4th (4 or 16 times
    /// fewer triangles under each body, so cheaper steps, on a surface
    /// exact at those samples only). Rounded down to a power of two,
    /// clamped to a chunk's side.
    pub surface_step: u32,
}

impl Default for PhysicsSettings {
    fn default() -> Self {
        PhysicsSettings {
            gravity: 40.0,
            step: 1.0 / 60.0,
            max_steps_per_advance: 15,
            ccd: true,
            surface_step: 1,
        }
    }
}

/// What an edit did to the physics world.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EditReport {
    /// The chunks whose surfaces changed (row-major indices).
    pub chunks: Vec<usize>,
    /// Rapier colliders replaced: the changed chunks' surfaces in the world
    /// (in place and across the map's edges).
    pub colliders_replaced: usize,
    /// Updating the collider (columns and pyramid).
    pub refit_ms: f64,
    /// Rebuilding the changed surfaces in the world and swapping them in.
    pub replace_ms: f64,
}

/// Rigid bodies on the terrain. The terrain is a [`TerrainCollider`]; the
/// chunks around the bodies are in the world as fixed height-field
/// colliders (floor, slab top, slab underside; built when a body comes
/// near, dropped when it leaves), and an edit replaces exactly the dirty
/// chunks' colliders in the same call.
pub struct TerrainPhysics {
    world: PhysicsWorld,
    terrain: TerrainCollider,
    chunks: ChunkColliders,
    bodies: Vec<(RigidBodyHandle, BodyShape)>,
    clock: FixedStep,
    settings: PhysicsSettings,
    /// Map size in texels (bodies wrap around it).
    size: [f32; 2],
}

impl TerrainPhysics {
    /// A world on `terrain` (see [`TerrainCollider::fit`]).
    pub fn new(terrain: TerrainCollider, settings: PhysicsSettings) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -settings.gravity);
        world.integration_parameters.dt = settings.step as f32;
        let chunks = ChunkColliders::new(settings.surface_step);
        let layout = terrain.layout();
        let size = [
            (layout.size_x * layout.chunks_x) as f32,
            (layout.size_y * layout.chunks_y) as f32,
        ];
        TerrainPhysics {
            world,
            terrain,
            chunks,
            bodies: Vec::new(),
            clock: FixedStep::new(settings.step, settings.max_steps_per_advance),
            settings,
            size,
        }
    }

    /// Build `level`'s collider and the world on it; `tolerance` is ignored
    /// (the collider is exact, see [`TerrainCollider::fit`]).
    pub fn fit(level: &Level, tolerance: f64, settings: PhysicsSettings) -> Self {
        Self::new(TerrainCollider::fit(level, tolerance), settings)
    }

    /// The terrain collider (ray casts, box queries).
    pub fn terrain(&self) -> &TerrainCollider {
        &self.terrain
    }

    /// The rapier world itself, for anything this type does not wrap.
    pub fn world(&self) -> &PhysicsWorld {
        &self.world
    }

    /// The settings the world was made with.
    pub fn settings(&self) -> &PhysicsSettings {
        &self.settings
    }

    /// Drop a body with its centre at `at` (world coordinates; x and y
    /// wrap into the map), at rest. Errors on a bad size or a non-finite
    /// position.
    pub fn drop_body(&mut self, shape: BodyShape, at: [f32; 3]) -> Result<BodyId, PhysicsError> {
        shape.validate()?;
        if at.iter().any(|v| !v.is_finite()) {
            return Err(PhysicsError::BadPosition(at));
        }
        let [x, y] = self.wrapped([at[0], at[1]]);
        let body = RigidBodyBuilder::dynamic()
            .translation(Vector::new(x, y, at[2]))
            .ccd_enabled(self.settings.ccd);
        let (handle, _) = self.world.insert(body, shape.collider().friction(0.7));
        self.bodies.push((handle, shape));
        Ok(BodyId(handle))
    }

    /// Drop a body `height` units above where the ray from `origin` along
    /// `dir` first meets the terrain (a click on the picture); `None` when
    /// it meets none (sky).
    pub fn drop_on_ray(
        &mut self,
        shape: BodyShape,
        origin: [f64; 3],
        dir: [f64; 3],
        t_max: f64,
        height: f32,
    ) -> Result<Option<BodyId>, PhysicsError> {
        let Some(hit) = self.terrain.cast_ray(origin, dir, t_max) else {
            return Ok(None);
        };
        let (p, n) = (hit.point, hit.normal.map(f64::from));
        // Along the hit normal, so a click on a cave's ceiling drops the
        // body below it; no higher than the terrain above the point allows
        // (a click on a cave floor drops it inside the cave).
        let r = f64::from(shape.bounding_radius());
        let mut above = r + f64::from(height.max(0.0));
        let start = [p[0] + n[0] * 0.01, p[1] + n[1] * 0.01, p[2] + n[2] * 0.01];
        if let Some(roof) = self.terrain.cast_ray(start, n, above + r) {
            above = (roof.distance - r - 0.5)
                .max(roof.distance * 0.5)
                .min(above);
        }
        let at = [
            p[0] + n[0] * above,
            p[1] + n[1] * above,
            p[2] + n[2] * above,
        ];
        self.drop_body(shape, at.map(|v| v as f32)).map(Some)
    }

    /// Remove every dropped body.
    pub fn clear_bodies(&mut self) {
        for (h, _) in self.bodies.drain(..) {
            self.world.remove_body(h);
        }
    }

    /// How many bodies there are.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Every body's pose.
    pub fn bodies(&self) -> impl Iterator<Item = BodyPose> + '_ {
        self.bodies
            .iter()
            .filter_map(|&(h, shape)| self.pose(h, shape))
    }

    /// One body's pose (`None` once cleared).
    pub fn body(&self, id: BodyId) -> Option<BodyPose> {
        let &(h, shape) = self.bodies.iter().find(|(h, _)| *h == id.0)?;
        self.pose(h, shape)
    }

    fn pose(&self, h: RigidBodyHandle, shape: BodyShape) -> Option<BodyPose> {
        let b = self.world.bodies.get(h)?;
        let (t, r, v) = (b.translation(), b.rotation(), b.linvel());
        Some(BodyPose {
            id: BodyId(h),
            shape,
            position: [t.x, t.y, t.z],
            rotation: [r.x, r.y, r.z, r.w],
            velocity: [v.x, v.y, v.z],
            sleeping: b.is_sleeping(),
        })
    }

    /// Run one fixed step (first bringing the terrain cells around the
    /// bodies into the world).
    pub fn step(&mut self) {
        self.chunks.sync(
            &mut self.world,
            &self.terrain,
            &self.bodies,
            self.settings.step as f32,
        );
        self.world.step();
        self.wrap_bodies();
    }

    /// A frame of `dt` seconds passed: run the whole steps it makes (see
    /// [`FixedStep`]); returns how many ran.
    pub fn advance(&mut self, dt: f64) -> u32 {
        let steps = self.clock.advance(dt);
        for _ in 0..steps {
            self.step();
        }
        steps
    }

    /// After an edit of `level`: the collider re-reads the dirty texels,
    /// and the chunks they touch that are in the world get new surfaces
    /// (bodies resting on them wake and fall onto the new ground).
    pub fn apply_edit(&mut self, level: &Level, dirty: &[DirtyRect]) -> EditReport {
        let t = Instant::now();
        let chunks = self.terrain.apply_edit(level, dirty);
        let refit_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let colliders_replaced = self.chunks.replace(&mut self.world, &self.terrain, &chunks);
        EditReport {
            chunks,
            colliders_replaced,
            refit_ms,
            replace_ms: t.elapsed().as_secs_f64() * 1e3,
        }
    }

    /// Chunk `index`'s rapier collider handles (its cells in the world, in
    /// place and across the map's edges); empty while no body is near it.
    pub fn chunk_colliders(&self, index: usize) -> Vec<rapier3d::prelude::ColliderHandle> {
        self.chunks.of(index)
    }

    /// Chunk cells in the world now, and the bytes of their height fields.
    pub fn terrain_cells(&self) -> (usize, usize) {
        (self.chunks.cell_count(), self.chunks.memory_bytes())
    }

    fn wrapped(&self, [x, y]: [f32; 2]) -> [f32; 2] {
        let wrap = |v: f32, n: f32| (v - 0.5).rem_euclid(n) + 0.5;
        [wrap(x, self.size[0]), wrap(y, self.size[1])]
    }

    /// Bodies that left the map come back across the opposite edge, with
    /// their velocity (the terrain there is the same).
    fn wrap_bodies(&mut self) {
        for &(h, _) in &self.bodies {
            let Some(b) = self.world.bodies.get_mut(h) else {
                continue;
            };
            let t = b.translation();
            let [x, y] = {
                let wrap = |v: f32, n: f32| (v - 0.5).rem_euclid(n) + 0.5;
                [wrap(t.x, self.size[0]), wrap(t.y, self.size[1])]
            };
            if x != t.x || y != t.y {
                b.set_translation(Vector::new(x, y, t.z), true);
            }
        }
    }
}
