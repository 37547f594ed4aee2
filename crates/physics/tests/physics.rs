//! The physics world on small hand-built levels (CPU, a few seconds): bodies
//! rest on the ground, on a slab's top, on a cave's floor under a slab, fall
//! into a crater dug under them, and an edit replaces exactly the dirty
//! chunks' colliders.

use strata_level::edit::{EditRect, crater, edit_columns};
use strata_level::{Column, EditSite, Level};
use strata_physics::{BodyId, BodyShape, PhysicsSettings, TerrainPhysics};

const GROUND: f32 = 40.0;
/// The cave's ceiling (a dual column's `mid` is stored in steps of 8).
const CAVE_TOP: f32 = 64.0;
const SLAB_TOP: f32 = 80.0;
const RADIUS: f32 = 5.0;
/// The fit's max vertical error on these flat pieces is well under this;
/// the rest is rapier's contact slop.
const TOLERANCE: f32 = 0.3;

/// Flat ground at 40, 256x256 (2x2 chunks), with a slab (cave 40..64, top
/// 80) over x 150..200, y 20..100 (inside chunk 1).
fn level() -> Level {
    let mut level = Level::flat(256, 256, GROUND as u8, 1).unwrap();
    let slab = EditRect {
        x: 150,
        y: 20,
        width: 50,
        height: 80,
    };
    edit_columns(&mut level, slab, |_, _, c| Column {
        mid: 70,
        high: SLAB_TOP as u8,
        dual: true,
        upper_type: 5,
        ..c
    });
    assert_eq!(f32::from(level.column(175, 60).mid), CAVE_TOP);
    level
}

fn world(level: &Level) -> TerrainPhysics {
    TerrainPhysics::fit(level, 0.5, PhysicsSettings::default())
}

/// Step until `id` sleeps (at most `max` steps); its centre then.
fn settle(physics: &mut TerrainPhysics, id: BodyId, max: u32) -> [f32; 3] {
    for _ in 0..max {
        physics.step();
        if physics.body(id).unwrap().sleeping {
            break;
        }
    }
    let pose = physics.body(id).unwrap();
    assert!(
        pose.velocity.iter().all(|v| v.abs() < 0.5),
        "still moving: {pose:?}"
    );
    pose.position
}

fn ball() -> BodyShape {
    BodyShape::Sphere { radius: RADIUS }
}

#[test]
fn a_ball_dropped_on_flat_ground_rests_at_ground_height() {
    let level = level();
    let mut physics = world(&level);
    let id = physics.drop_body(ball(), [60.5, 180.5, 120.0]).unwrap();
    let p = settle(&mut physics, id, 600);
    assert!(
        (p[2] - (GROUND + RADIUS)).abs() < TOLERANCE,
        "centre at {p:?}, ground + radius = {}",
        GROUND + RADIUS
    );
    // Straight down: it did not wander.
    assert!(
        (p[0] - 60.5).abs() < 1.0 && (p[1] - 180.5).abs() < 1.0,
        "{p:?}"
    );
}

#[test]
fn a_ball_dropped_over_a_slab_rests_on_its_top_and_one_in_the_cave_on_the_floor() {
    let level = level();
    let mut physics = world(&level);
    let over = physics.drop_body(ball(), [175.5, 60.5, 110.0]).unwrap();
    // Spawned inside the cave, between the floor (40) and ceiling (64).
    let under = physics.drop_body(ball(), [175.5, 60.5, 55.0]).unwrap();
    let on_top = settle(&mut physics, over, 600);
    let in_cave = settle(&mut physics, under, 600);
    assert!(
        (on_top[2] - (SLAB_TOP + RADIUS)).abs() < TOLERANCE,
        "over the slab: {on_top:?}"
    );
    assert!(
        (in_cave[2] - (GROUND + RADIUS)).abs() < TOLERANCE,
        "in the cave, on its floor not the slab: {in_cave:?}"
    );
}

#[test]
fn a_box_settles_flat_on_the_ground() {
    let level = level();
    let mut physics = world(&level);
    let id = physics
        .drop_body(BodyShape::VEHICLE_BOX, [60.5, 60.5, 100.0])
        .unwrap();
    let p = settle(&mut physics, id, 600);
    assert!(
        (p[2] - (GROUND + 3.0)).abs() < TOLERANCE,
        "box centre {p:?}"
    );
}

#[test]
fn a_crater_dug_under_a_resting_ball_swallows_it_and_only_dirty_chunks_change() {
    let mut level = level();
    let mut physics = world(&level);
    let id = physics.drop_body(ball(), [60.5, 180.5, 60.0]).unwrap();
    let before = settle(&mut physics, id, 600);
    assert!(physics.body(id).unwrap().sleeping, "at rest before the dig");
    let handles: Vec<Vec<_>> = (0..4)
        .map(|i| physics.chunk_colliders(i).to_vec())
        .collect();

    // Crater inside chunk 2 (x < 128, y >= 128): depth 30 at its centre.
    let mut site = EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) = (60, 180, 30, 30.0);
    let dirty = crater(&mut level, &site);
    let report = physics.apply_edit(&level, &dirty);
    assert_eq!(report.chunks, [2], "only the crater's chunk is refit");
    // Chunk 2 (cx 0, cy 1) sits in place and across the map's left edge.
    assert_eq!(report.colliders_replaced, handles[2].len());
    for (i, old) in handles.iter().enumerate() {
        let now = physics.chunk_colliders(i);
        if i == 2 {
            assert!(now.iter().all(|h| !old.contains(h)), "chunk 2 replaced");
        } else {
            assert_eq!(now, &old[..], "chunk {i} untouched");
        }
    }

    let after = settle(&mut physics, id, 1200);
    let floor = f32::from(level.column(60, 180).low);
    assert!(floor < GROUND - 25.0, "the crater is dug: floor {floor}");
    assert!(
        after[2] < before[2] - 20.0,
        "fell into the crater: {before:?} -> {after:?}"
    );
    // It rests on the crater's floor: the terrain right under it is one
    // radius down (the bowl is gentle at its bottom).
    let down = physics
        .terrain()
        .cast_ray(after.map(f64::from), [0.0, 0.0, -1.0], 100.0)
        .unwrap();
    assert!(
        (down.distance as f32 - RADIUS).abs() < 0.6,
        "ground {} under the centre {after:?}",
        down.distance
    );
    assert!(
        after[2] < floor + RADIUS + 2.0,
        "near the floor {floor}: {after:?}"
    );
}

#[test]
fn bodies_crossing_the_map_edge_come_back_on_the_other_side() {
    let level = level();
    let mut physics = world(&level);
    let id = physics.drop_body(ball(), [-3.0, 300.0, 60.0]).unwrap();
    let p = physics.body(id).unwrap().position;
    assert_eq!([p[0], p[1]], [253.0, 44.0]);
    // Resting across the edge: it stands on the chunk copies there too.
    let id = physics.drop_body(ball(), [1.0, 60.5, 60.0]).unwrap();
    let p = settle(&mut physics, id, 600);
    assert!((p[2] - (GROUND + RADIUS)).abs() < TOLERANCE, "{p:?}");
}

#[test]
fn bad_sizes_and_positions_are_refused_with_the_value() {
    let level = Level::flat(128, 128, 10, 1).unwrap();
    let mut physics = world(&level);
    let e = physics
        .drop_body(BodyShape::Sphere { radius: -1.0 }, [1.0, 1.0, 20.0])
        .unwrap_err();
    assert!(e.to_string().contains("-1"), "{e}");
    let e = physics
        .drop_body(ball(), [f32::NAN, 1.0, 20.0])
        .unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    assert_eq!(physics.body_count(), 0);
}

#[test]
fn a_click_drops_the_body_above_the_ground_it_sees_or_under_the_ceiling() {
    let level = level();
    let mut physics = world(&level);
    // Looking straight down onto the slab.
    let id = physics
        .drop_on_ray(ball(), [175.5, 60.5, 200.0], [0.0, 0.0, -1.0], 500.0, 20.0)
        .unwrap()
        .unwrap();
    let p = physics.body(id).unwrap().position;
    assert!((p[2] - (SLAB_TOP + RADIUS + 20.0)).abs() < 0.6, "{p:?}");
    // From inside the cave, down onto its floor: under the ceiling.
    let id = physics
        .drop_on_ray(ball(), [175.5, 60.5, 60.0], [0.0, 0.0, -1.0], 500.0, 20.0)
        .unwrap()
        .unwrap();
    let p = physics.body(id).unwrap().position;
    assert!(
        p[2] + RADIUS < CAVE_TOP && p[2] - RADIUS >= GROUND - 0.6,
        "{p:?}"
    );
    // The sky: nothing dropped.
    let none = physics
        .drop_on_ray(ball(), [60.5, 60.5, 200.0], [0.0, 0.0, 1.0], 500.0, 20.0)
        .unwrap();
    assert_eq!(none, None);
    physics.clear_bodies();
    assert_eq!(physics.body_count(), 0);
    assert_eq!(physics.bodies().count(), 0);
}

/// Only the chunks around bodies are in the world: a few cells per body,
/// none once the bodies are gone (the whole map's surfaces never are).
#[test]
fn only_chunks_near_bodies_are_in_the_world() {
    let level = Level::flat(1024, 1024, 30, 1).unwrap();
    let mut physics = world(&level);
    for k in 0..8 {
        let at = [100.5 + 120.0 * k as f32, 60.5 + 117.0 * k as f32, 50.0];
        physics.drop_body(ball(), at).unwrap();
    }
    for _ in 0..60 {
        physics.step();
    }
    let (cells, bytes) = physics.terrain_cells();
    println!("{cells} cells, {bytes} bytes of height fields for 8 bodies");
    assert!((8..=8 * 4).contains(&cells), "{cells}");
    // A flat map has no slabs: one 129 x 129 field per chunk.
    assert!(bytes <= cells * (129 * 129 * 4 + 128 * 128), "{bytes}");
    assert!(
        physics
            .bodies()
            .all(|b| (b.position[2] - 35.0).abs() < TOLERANCE)
    );
    physics.clear_bodies();
    physics.step();
    assert_eq!(physics.terrain_cells(), (0, 0));
}

/// Surfaces through every 4th sample: fewer triangles, the same rest
/// heights on flat ground and on a slab.
#[test]
fn sparser_surfaces_hold_bodies_at_the_same_heights() {
    let level = level();
    let settings = PhysicsSettings {
        surface_step: 4,
        ..Default::default()
    };
    let mut physics = TerrainPhysics::fit(&level, 0.5, settings);
    let ground = physics.drop_body(ball(), [60.5, 180.5, 120.0]).unwrap();
    let slab = physics.drop_body(ball(), [175.5, 60.5, 110.0]).unwrap();
    let g = settle(&mut physics, ground, 600);
    let s = settle(&mut physics, slab, 600);
    assert!((g[2] - (GROUND + RADIUS)).abs() < TOLERANCE, "{g:?}");
    assert!((s[2] - (SLAB_TOP + RADIUS)).abs() < TOLERANCE, "{s:?}");
    let (_, sparse) = physics.terrain_cells();
    let mut exact = world(&level);
    exact.drop_body(ball(), [60.5, 180.5, 120.0]).unwrap();
    exact.drop_body(ball(), [175.5, 60.5, 110.0]).unwrap();
    exact.step();
    let (_, full) = exact.terrain_cells();
    println!("height fields: {sparse} bytes every 4th sample, {full} bytes every sample");
    assert!(sparse * 8 < full, "{sparse} vs {full}");
}
