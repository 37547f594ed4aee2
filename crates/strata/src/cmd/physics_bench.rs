//! `strata collide --physics-bench`: rigid bodies (strata-physics, rapier3d)
//! on the whole world's terrain collider. Step time with N bodies falling
//! onto and resting around the world's crater site (the chunk surfaces
//! around them built as they come), then the crater dug under them: the
//! collider's update and the swap of the dirty chunks' surfaces inside the
//! physics world.

use serde::Serialize;
use strata_collide::TerrainCollider;
use strata_level::{EditSite, Level};
use strata_physics::{BodyShape, PhysicsSettings, TerrainPhysics};
use web_time::Instant;

/// Steps measured per body count: 4 simulated seconds (falling, landing,
/// rolling, most asleep by the end).
const STEPS: u32 = 240;

#[derive(Serialize)]
pub struct Run {
    bodies: usize,
    steps: u32,
    mean_step_ms: f64,
    /// The first simulated second (falling and landing) and the last (resting).
    first_second_step_ms: f64,
    last_second_step_ms: f64,
    asleep_at_end: usize,
    /// Chunk cells in the world at the end, and their height fields' bytes.
    terrain_cells: usize,
    terrain_cell_bytes: usize,
}

#[derive(Serialize)]
pub struct Report {
    /// Spacing of the terrain surface's samples (1: exact).
    surface_step: u32,
    world_build_ms: f64,
    runs: Vec<Run>,
    crater_chunks: usize,
    crater_colliders_replaced: usize,
    crater_refit_ms: f64,
    crater_replace_ms: f64,
    /// Bodies over the crater that fell at least 10 units after the dig.
    bodies_fell_into_crater: usize,
}

/// Grid spacing of the dropped bodies: more than a box's diameter (its
/// bounding sphere's radius is 9.4), so none start overlapping.
const SPACING: f64 = 20.0;

/// N bodies (spheres and boxes alternating) on a square grid `SPACING`
/// apart centred on the crater site, each dropped 10 units above the ground
/// it is over.
fn drop_grid(physics: &mut TerrainPhysics, site: &EditSite, n: usize) -> anyhow::Result<()> {
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let (i, j) = ((k % side) as f64, (k / side) as f64);
        let x = site.centre_x as f64 + (i - side as f64 / 2.0) * SPACING + 0.5;
        let y = site.centre_y as f64 + (j - side as f64 / 2.0) * SPACING + 0.5;
        let shape = if k % 2 == 0 {
            BodyShape::VEHICLE_SPHERE
        } else {
            BodyShape::VEHICLE_BOX
        };
        physics.drop_on_ray(shape, [x, y, 400.0], [0.0, 0.0, -1.0], 1000.0, 10.0)?;
    }
    Ok(())
}

pub fn run(
    level: &mut Level,
    collider: TerrainCollider,
    site: &EditSite,
    counts: &[usize],
    surface_step: u32,
) -> anyhow::Result<Report> {
    let t = Instant::now();
    let settings = PhysicsSettings {
        surface_step,
        ..Default::default()
    };
    let mut physics = TerrainPhysics::new(collider, settings);
    let world_build_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut runs = Vec::new();
    for &n in counts {
        physics.clear_bodies();
        drop_grid(&mut physics, site, n)?;
        let mut times = Vec::with_capacity(STEPS as usize);
        for _ in 0..STEPS {
            let t = Instant::now();
            physics.step();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
        runs.push(Run {
            bodies: physics.body_count(),
            steps: STEPS,
            mean_step_ms: mean(&times),
            first_second_step_ms: mean(&times[..60]),
            last_second_step_ms: mean(&times[times.len() - 60..]),
            asleep_at_end: physics.bodies().filter(|b| b.sleeping).count(),
            terrain_cells: physics.terrain_cells().0,
            terrain_cell_bytes: physics.terrain_cells().1,
        });
    }

    // The crater under the last run's resting bodies.
    let before: Vec<_> = physics.bodies().collect();
    let dirty = strata_level::edit::crater(level, site);
    let edit = physics.apply_edit(level, &dirty);
    for _ in 0..STEPS {
        physics.step();
    }
    let r2 = f64::from(site.radius).powi(2) * 0.5;
    let fell = before
        .iter()
        .filter(|b| {
            let dx = f64::from(b.position[0]) - site.centre_x as f64 - 0.5;
            let dy = f64::from(b.position[1]) - site.centre_y as f64 - 0.5;
            dx * dx + dy * dy < r2
                && physics
                    .body(b.id)
                    .is_some_and(|now| now.position[2] < b.position[2] - 10.0)
        })
        .count();
    Ok(Report {
        surface_step,
        world_build_ms,
        runs,
        crater_chunks: edit.chunks.len(),
        crater_colliders_replaced: edit.colliders_replaced,
        crater_refit_ms: edit.refit_ms,
        crater_replace_ms: edit.replace_ms,
        bodies_fell_into_crater: fell,
    })
}

pub fn print(r: &Report) {
    println!(
        "physics world (rapier3d) on the collider: {:.3} ms to create (chunk surfaces, every {} texel(s), come with the bodies)",
        r.world_build_ms, r.surface_step
    );
    for run in &r.runs {
        println!(
            "  {:>5} bodies: {:.3} ms per {:.4} s step over {} steps (first second {:.3} ms, last {:.3} ms; {} asleep at the end; {} chunk cells, {:.1} MiB of height fields)",
            run.bodies,
            run.mean_step_ms,
            PhysicsSettings::default().step,
            run.steps,
            run.first_second_step_ms,
            run.last_second_step_ms,
            run.asleep_at_end,
            run.terrain_cells,
            run.terrain_cell_bytes as f64 / f64::from(1 << 20)
        );
    }
    println!(
        "crater under them: collider updated in {1:.3} ms ({0} chunks), {2} rapier colliders replaced in {3:.3} ms; {4} bodies over it fell in",
        r.crater_chunks,
        r.crater_refit_ms,
        r.crater_colliders_replaced,
        r.crater_replace_ms,
        r.bodies_fell_into_crater
    );
}
