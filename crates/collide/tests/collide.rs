//! The collider against the CPU reference's exact ray cast (random, grazing
//! and cave rays; after edits too), its box queries, its memory, and bad
//! input.

use glam::DVec3;
use strata_collide::{BoxShape, Face, TerrainCollider};
use strata_level::edit::{EditRect, crater, edit_columns};
use strata_level::lcg::Lcg;
use strata_level::{Column, DirtyRect, EditSite, Level};
use strata_mesh::{ChunkLayout, dirty_chunks, synthetic::synthetic_level};
use strata_reference::{ReferenceSettings, Tracer};

const T_MAX: f64 = 4000.0;

fn level() -> Level {
    synthetic_level(256, 256, 3)
}

/// Do the collider and the reference agree on this ray: both miss, or both
/// hit the same column (wrapped) at the same distance?
fn agree(c: &TerrainCollider, tracer: &Tracer, level: &Level, o: DVec3, d: DVec3) -> bool {
    let r = tracer.trace(o, d, T_MAX, &ReferenceSettings::default());
    let m = c.cast_ray(o.into(), d.into(), T_MAX);
    match (r, m) {
        (None, None) => true,
        (Some(r), Some(m)) => {
            let wrap = |p: [i64; 2]| level.wrap(p[0], p[1]);
            (r.distance - m.distance).abs() <= 1e-9 * r.distance.max(1.0)
                && wrap(r.column) == wrap(m.column)
                && r.terrain == m.terrain
        }
        _ => false,
    }
}

/// Random rays of four kinds: down from above at any slope, steeply up out
/// of caves into slab undersides, grazing (within 3 degrees of horizontal,
/// some exactly horizontal, starting a hair above a column's top or on a
/// texel line), and horizontal through caves.
fn rays(level: &Level, n: usize, seed: u64) -> Vec<(&'static str, DVec3, DVec3)> {
    let mut rng = Lcg(seed);
    let (w, h) = (f64::from(level.width()), f64::from(level.height()));
    // The cave kinds need a dual column with room under its slab; a level
    // without one (every slab dug away) gets rays from above instead, or the
    // search for one would never end.
    let caves = (0..level.height()).any(|y| {
        (0..level.width()).any(|x| {
            let c = level.column(i64::from(x), i64::from(y));
            c.dual && c.mid > c.low + 2
        })
    });
    let mut out = Vec::new();
    while out.len() < n {
        let x = rng.next_f64() * w;
        let y = rng.next_f64() * h;
        let c = level.column(x.floor() as i64, y.floor() as i64);
        let az = rng.next_f64() * std::f64::consts::TAU;
        let dir = |el: f64| DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        match out.len() % 4 {
            1 | 3 if !caves => {
                let el = -(0.05 + rng.next_f64() * 1.5);
                out.push(("down", DVec3::new(x, y, 260.0), dir(el)));
            }
            0 => {
                let el = -(0.05 + rng.next_f64() * 1.5);
                out.push(("down", DVec3::new(x, y, 260.0), dir(el)));
            }
            1 if c.dual && c.mid > c.low + 2 => {
                let el = 0.5 + rng.next_f64() * 1.0;
                let z = (f64::from(c.low) + f64::from(c.mid)) * 0.5;
                out.push(("up into a ceiling", DVec3::new(x, y, z), dir(el)));
            }
            1 => {}
            2 => {
                // Grazing: a hair above the top, or exactly at it, or on a
                // texel line; nearly or exactly horizontal.
                let top = f64::from(c.top());
                let z = match rng.next_u32() % 3 {
                    0 => top + 1e-6,
                    1 => top + 0.5,
                    _ => top + 1.0,
                };
                let (x, y) = if rng.next_u32().is_multiple_of(2) {
                    (x.floor(), y)
                } else {
                    (x, y)
                };
                let el = match rng.next_u32() % 3 {
                    0 => 0.0,
                    1 => -(rng.next_f64() * 0.05),
                    _ => rng.next_f64() * 0.05,
                };
                out.push(("grazing", DVec3::new(x, y, z), dir(el)));
            }
            _ if c.dual && c.mid > c.low + 2 => {
                let z = f64::from(c.low) + 1.0 + rng.next_f64() * f64::from(c.mid - c.low - 2);
                out.push(("through a cave", DVec3::new(x, y, z), dir(0.0)));
            }
            _ => {}
        }
    }
    out
}

fn agreement(c: &TerrainCollider, level: &Level, n: usize, seed: u64) -> (usize, usize) {
    let tracer = Tracer::new(level);
    let rays = rays(level, n, seed);
    let mut ok = 0;
    for (kind, o, d) in &rays {
        if agree(c, &tracer, level, *o, *d) {
            ok += 1;
        } else {
            let r = tracer.trace(*o, *d, T_MAX, &ReferenceSettings::default());
            let m = c.cast_ray((*o).into(), (*d).into(), T_MAX);
            eprintln!("{kind} ray {o} {d}: reference {r:?}, collider {m:?}");
        }
    }
    (ok, rays.len())
}

#[test]
fn random_and_grazing_rays_agree_with_the_reference() {
    let level = level();
    let collider = TerrainCollider::new(&level);
    let (ok, n) = agreement(&collider, &level, 8000, 11);
    let share = ok as f64 / n as f64;
    println!(
        "{ok}/{n} rays agree with the CPU reference ({:.2} %)",
        share * 100.0
    );
    assert!(share >= 0.99, "{share}");
    assert_eq!(ok, n, "the traversal is the reference's: every ray agrees");
}

#[test]
fn faces_and_normals_follow_the_column_model() {
    let level = level();
    let collider = TerrainCollider::new(&level);
    let (mut floors, mut ceilings, mut walls) = (0, 0, 0);
    for y in (0..256).step_by(5) {
        for x in (0..256).step_by(5) {
            let c = level.column(x, y);
            let o = [x as f64 + 0.5, y as f64 + 0.5, 300.0];
            let hit = collider.cast_ray(o, [0.0, 0.0, -1.0], 1000.0).unwrap();
            assert_eq!(hit.point[2], f64::from(c.top()));
            assert_eq!(hit.normal, [0.0, 0.0, 1.0]);
            assert_eq!(hit.face, if c.dual { Face::SlabTop } else { Face::Floor });
            floors += 1;
            if c.dual && c.mid > c.low {
                let o = [o[0], o[1], f64::from(c.low) + 0.5];
                let up = collider.cast_ray(o, [0.0, 0.0, 1.0], 1000.0).unwrap();
                assert_eq!((up.point[2], up.face), (f64::from(c.mid), Face::Ceiling));
                assert_eq!(up.normal, [0.0, 0.0, -1.0]);
                ceilings += 1;
            }
            // Horizontally into the column from its west neighbour, under its top.
            let west = level.column(x - 1, y);
            if u16::from(c.low) > u16::from(west.top()) + 1 {
                let z = f64::from(west.top()) + 0.5;
                let hit = collider
                    .cast_ray([x as f64 - 0.5, y as f64 + 0.5, z], [1.0, 0.0, 0.0], 1.0)
                    .unwrap();
                assert_eq!(hit.face, Face::Wall { across_x: true });
                assert_eq!((hit.distance, hit.normal), (0.5, [-1.0, 0.0, 0.0]));
                walls += 1;
            }
        }
    }
    println!("{floors} tops, {ceilings} ceilings, {walls} walls");
    assert!(ceilings > 20 && walls > 20);
}

/// Edits (a crater, small tracks, a slab carved, across the map's edge):
/// the collider follows them and still agrees with the reference on the
/// edited level; it reports the dirty chunks.
#[test]
fn after_edits_rays_agree_and_the_dirty_chunks_are_reported() {
    let mut level = level();
    let mut collider = TerrainCollider::new(&level);
    let mut site = EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) = (127, 60, 24, 40.0);
    let dirty = crater(&mut level, &site);
    let chunks = collider.apply_edit(&level, &dirty);
    assert_eq!(
        chunks,
        dirty_chunks(&ChunkLayout::of(&level), 256, 256, &dirty)
    );
    let mut rng = Lcg(5);
    for k in 0..64 {
        let (cx, cy) = (
            rng.next_u32() as i64 % 300 - 20,
            rng.next_u32() as i64 % 300 - 20,
        );
        (site.centre_x, site.centre_y) = (cx, cy);
        site.radius = 2 + k % 5;
        site.depth = 6.0;
        let dirty = crater(&mut level, &site);
        collider.apply_edit(&level, &dirty);
    }
    // A slab carved across the map's corner.
    let rect = EditRect {
        x: 250,
        y: 250,
        width: 12,
        height: 12,
    };
    let dirty = edit_columns(&mut level, rect, |_, _, c| Column {
        mid: c.low.saturating_add(20),
        high: c.low.saturating_add(40),
        dual: true,
        ..c
    });
    collider.apply_edit(&level, &dirty);
    let o = [1.5, 1.5, f64::from(level.column(1, 1).low) + 1.0];
    let up = collider.cast_ray(o, [0.0, 0.0, 1.0], 100.0).unwrap();
    assert_eq!(up.face, Face::Ceiling);
    let (ok, n) = agreement(&collider, &level, 3000, 23);
    println!("after edits: {ok}/{n} rays agree");
    assert_eq!(ok, n);
    let fresh = TerrainCollider::new(&level);
    assert_eq!(collider.stats(), fresh.stats());
}

#[test]
fn memory_is_four_bytes_a_texel_and_a_pyramid() {
    let level = synthetic_level(512, 1024, 1);
    let stats = TerrainCollider::new(&level).stats();
    let per_texel = stats.memory_bytes as f64 / (512.0 * 1024.0);
    println!("{per_texel:.3} bytes a texel");
    assert!((4.0..4.1).contains(&per_texel), "{per_texel}");
    assert_eq!(stats.columns, 512 * 1024);
}

/// A box on a flat pad: contact distance and a downward box cast.
#[test]
fn box_contact_and_cast_match_the_ground() {
    let mut level = level();
    let pad = EditRect {
        x: 30,
        y: 190,
        width: 24,
        height: 24,
    };
    strata_level::edit::fill_single(&mut level, pad, 100, 1);
    let collider = TerrainCollider::new(&level);
    let (x, y) = (42.0, 202.0);
    let ground = 100.0;
    let half = [0.5f32, 0.5, 0.5];
    let b = BoxShape::axis_aligned([x, y, ground + 50.0], half);
    let hit = collider
        .cast_box(&b, [0.0, 0.0, -1.0], 200.0)
        .expect("lands");
    let rest = ground + 50.0 - hit.distance;
    assert!((rest - (ground + 0.5)).abs() < 1e-2, "{rest}");
    let sunk = BoxShape::axis_aligned([x, y, rest - 0.3], half);
    let c = collider.contact_box(&sunk, 0.0).expect("penetrates");
    assert!(c.distance < -0.2 && c.distance > -0.4, "{}", c.distance);
    assert!(
        collider
            .contact_box(&BoxShape::axis_aligned([x, y, rest + 5.0], half), 1.0)
            .is_none()
    );
    let near = BoxShape::axis_aligned([x, y, rest + 0.5], half);
    let c = collider.contact_box(&near, 1.0).expect("within the margin");
    assert!(
        (c.distance - 0.5).abs() < 1e-3 && c.normal[2] > 0.99,
        "{c:?}"
    );
    // Far from the origin (another copy of the map), the same answer.
    let far = BoxShape::axis_aligned([x + 256.0 * 40.0, y - 256.0 * 7.0, rest - 0.3], half);
    let c2 = collider.contact_box(&far, 0.0).unwrap();
    assert!((c2.distance - c.distance + 0.8).abs() < 1e-3, "{c2:?}");
}

/// A box in a cave touches the floor under it, not the slab over it; one
/// over the slab lands on its top.
#[test]
fn boxes_see_floor_slab_top_and_ceiling() {
    let mut level = Level::flat(256, 256, 40, 1).unwrap();
    let rect = EditRect {
        x: 100,
        y: 100,
        width: 40,
        height: 40,
    };
    edit_columns(&mut level, rect, |_, _, c| Column {
        mid: 70,
        high: 80,
        dual: true,
        ..c
    });
    let collider = TerrainCollider::new(&level);
    let half = [1.0f32, 1.0, 1.0];
    let down = [0.0, 0.0, -1.0];
    let above = BoxShape::axis_aligned([120.5, 120.5, 100.0], half);
    let hit = collider.cast_box(&above, down, 200.0).unwrap();
    assert!(
        (hit.distance - 19.0).abs() < 1e-3,
        "onto the slab top: {hit:?}"
    );
    let cave = BoxShape::axis_aligned([120.5, 120.5, 55.0], half);
    let hit = collider.cast_box(&cave, down, 200.0).unwrap();
    assert!(
        (hit.distance - 14.0).abs() < 1e-3,
        "onto the cave floor: {hit:?}"
    );
    let hit = collider.cast_box(&cave, [0.0, 0.0, 1.0], 200.0).unwrap();
    let ceiling = f64::from(level.column(120, 120).mid);
    assert!(
        (hit.distance - (ceiling - 56.0)).abs() < 1e-3,
        "up to the ceiling: {hit:?}"
    );
    assert!(collider.contact_box(&cave, 0.5).is_none());
}

#[test]
fn bad_input_gives_defined_results() {
    let mut level = level();
    let mut collider = TerrainCollider::new(&level);
    let nan = f64::NAN;
    for (o, d, t) in [
        ([nan, 1.0, 300.0], [0.0, 0.0, -1.0], 100.0),
        ([1.0, 1.0, 300.0], [0.0, nan, -1.0], 100.0),
        ([1.0, 1.0, 300.0], [0.0, 0.0, 0.0], 100.0),
        ([1.0, 1.0, 300.0], [0.0, 0.0, -1.0], nan),
        ([1.0, 1.0, 300.0], [0.0, 0.0, -1.0], -5.0),
        ([1e300, 1.0, 300.0], [0.0, 0.0, -1.0], 1000.0),
        ([1.0, f64::INFINITY, 300.0], [0.0, 0.0, -1.0], 1000.0),
    ] {
        assert_eq!(collider.cast_ray(o, d, t), None, "{o:?} {d:?} {t}");
    }
    // An endless ray is searched up to 10^7 units, then gives up.
    let mut pillar = Level::flat(64, 64, 10, 1).unwrap();
    pillar.planes_mut().0[5 * 64 + 5] = 50;
    let pillar = TerrainCollider::new(&pillar);
    assert_eq!(
        pillar.cast_ray([0.5, 0.5, 20.0], [1.0, 0.0, 0.0], f64::INFINITY),
        None
    );
    // Far from the origin: the same hit as in the map.
    let a = collider
        .cast_ray([30.5, 40.5, 300.0], [0.0, 0.0, -1.0], 400.0)
        .unwrap();
    let b = collider
        .cast_ray(
            [30.5 + 256.0 * 1e6, 40.5 - 256.0 * 3e5, 300.0],
            [0.0, 0.0, -1.0],
            400.0,
        )
        .unwrap();
    assert_eq!(a.distance, b.distance);
    // Inside solid terrain: a hit at distance 0.
    let inside = collider
        .cast_ray([30.5, 40.5, 0.5], [1.0, 0.0, 0.0], 10.0)
        .unwrap();
    assert_eq!(inside.distance, 0.0);
    // Boxes with bad sizes or positions: no contact.
    let bad = BoxShape::axis_aligned([nan, 1.0, 1.0], [1.0; 3]);
    assert!(collider.contact_box(&bad, 0.0).is_none());
    assert!(collider.cast_box(&bad, [0.0, 0.0, -1.0], 10.0).is_none());
    let flat_box = BoxShape::axis_aligned([1.0, 1.0, 1.0], [0.0, 1.0, 1.0]);
    assert!(collider.contact_box(&flat_box, 0.0).is_none());
    // Edits outside the map (wrapped), of radius 0, larger than the map.
    let mut site = EditSite::fostral();
    for (cx, cy, r) in [
        (-1000, 5000, 6),
        (7, 9, 0),
        (100, 100, 1000),
        (i64::MAX, i64::MIN, 3),
    ] {
        (site.centre_x, site.centre_y, site.radius, site.depth) = (cx, cy, r, 10.0);
        let dirty = crater(&mut level, &site);
        collider.apply_edit(&level, &dirty);
    }
    // Rectangles reaching past the map, or empty, from a careless caller.
    let odd = [
        DirtyRect {
            x: 250,
            y: 250,
            width: 300,
            height: 20,
        },
        DirtyRect {
            x: 5000,
            y: 3,
            width: 4,
            height: 4,
        },
        DirtyRect {
            x: 3,
            y: 3,
            width: 0,
            height: 4,
        },
        DirtyRect {
            x: u32::MAX,
            y: u32::MAX,
            width: u32::MAX,
            height: u32::MAX,
        },
    ];
    collider.apply_edit(&level, &odd);
    let (ok, n) = agreement(&collider, &level, 1000, 3);
    assert_eq!(ok, n);
    // A level of another size: rebuilt whole.
    let small = Level::flat(128, 64, 20, 2).unwrap();
    let chunks = collider.apply_edit(&small, &[]);
    assert_eq!(chunks.len(), 1);
    let hit = collider
        .cast_ray([5.5, 5.5, 50.0], [0.0, 0.0, -1.0], 100.0)
        .unwrap();
    assert_eq!(hit.distance, 30.0);
}
