//! The generated world: determinism, size handling, and the figures issue 2
//! asks for, measured on a 1024x4096 world (a
//! quarter of the default's width and length, so the landmarks and the river
//! take about the share of it they take of the default world).

use std::sync::OnceLock;
use strata_level::World;
use strata_level::generate::{GenerateError, GenerateParams, generate};

fn small() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    WORLD.get_or_init(|| {
        generate(&GenerateParams {
            seed: 1997,
            width: 1024,
            height: 4096,
        })
        .expect("1024x4096 generates")
    })
}

#[test]
fn same_bytes_at_any_thread_count() {
    let params = GenerateParams {
        seed: 42,
        width: 256,
        height: 512,
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| generate(&params).unwrap());
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    let b = four.install(|| generate(&params).unwrap());
    assert_eq!(a.level.content_hash(), b.level.content_hash());
    assert_eq!(a.views, b.views);
    let other = generate(&GenerateParams { seed: 43, ..params }).unwrap();
    assert_ne!(
        a.level.content_hash(),
        other.level.content_hash(),
        "the seed matters"
    );
}

#[test]
fn bad_sizes_are_errors_not_panics() {
    for (width, height) in [
        (300, 512),
        (128, 512),
        (512, 0),
        (1 << 16, 256),
        (1 << 15, 1 << 15),
    ] {
        let err = generate(&GenerateParams {
            seed: 1,
            width,
            height,
        })
        .unwrap_err();
        assert!(
            matches!(err, GenerateError::Size { .. }),
            "{width}x{height}: {err}"
        );
    }
    for size in [(256, 256), (256, 4096), (4096, 256)] {
        let w = generate(&GenerateParams {
            seed: 5,
            width: size.0,
            height: size.1,
        })
        .unwrap();
        assert_eq!(w.views.len(), 12, "{size:?}");
        assert!(w.edit.is_some());
    }
}

#[test]
fn dual_pairs_are_valid_and_caves_tall_enough() {
    let level = &small().level;
    let (w, h) = (level.width(), level.height());
    let dual = level.dual_texel_count() as f64 / (f64::from(w) * f64::from(h));
    assert!((0.08..=0.14).contains(&dual), "dual fraction {dual}");
    assert_eq!(level.pair_disagreement_count(), 0);
    for y in 0..h as i64 {
        for x in (0..w as i64).step_by(2) {
            let c = level.column(x, y);
            if c.dual {
                assert!(c.mid >= c.low + 8, "cave under 8 at ({x},{y}): {c:?}");
                assert!(c.high >= c.mid + 2, "slab under 2 at ({x},{y}): {c:?}");
            }
        }
    }
}

#[test]
fn roughness_is_in_fostral_range() {
    let stats = strata_level::stats::LevelStats::compute(&small().level);
    let (low, comp) = (stats.roughness_floor, stats.roughness_surface);
    assert!((2.0..=6.0).contains(&low), "lap low {low}");
    let ratio = comp / low;
    assert!(
        (1.5..=2.5).contains(&ratio),
        "composite {comp}, ratio {ratio}"
    );
}

#[test]
fn terraced_not_smooth() {
    let level = &small().level;
    let (w, h) = (level.width() as i64, level.height() as i64);
    let (mut cliffs, mut flat, mut water, mut land, mut types) =
        (0u64, 0u64, 0u64, 0u64, [0u64; 8]);
    let mut heights = [0u64; 256];
    for y in 0..h {
        for x in 0..w {
            let (c, e) = (level.column(x, y), level.column(x + 1, y));
            let step = (i32::from(c.low) - i32::from(e.low)).abs();
            cliffs += (step >= 20) as u64;
            flat += (step <= 3) as u64;
            heights[usize::from(c.low)] += 1;
            types[usize::from(c.lower_type)] += 1;
            if c.lower_type == 0 {
                water += 1;
                assert!(c.low < 80, "water above sea level at ({x},{y})");
            } else {
                land += (c.low > 80) as u64;
            }
        }
    }
    let n = (w * h) as f64;
    // Vertical cliffs are common, most ground is flat, land is above the sea.
    assert!(
        cliffs as f64 / n > 0.01,
        "cliff steps {}",
        cliffs as f64 / n
    );
    assert!(flat as f64 / n > 0.6, "flat steps {}", flat as f64 / n);
    assert!(
        (0.02..0.25).contains(&(water as f64 / n)),
        "water {}",
        water as f64 / n
    );
    assert!(land as f64 / n > 0.7);
    // Every terrain type covers a real share of the map.
    for (t, &count) in types.iter().enumerate() {
        assert!(count as f64 / n > 0.01, "type {t}: {}", count as f64 / n);
    }
    // Plateaus: a few heights (with their small noise) hold much of the map.
    heights.sort_unstable();
    let top8: u64 = heights.iter().rev().take(24).sum();
    assert!(
        top8 as f64 / n > 0.4,
        "24 most common heights hold {}",
        top8 as f64 / n
    );
}

#[test]
fn twelve_views_and_an_edit_site() {
    let world = small();
    assert_eq!(world.views.len(), 12);
    for pitch in [0.0, -30.0, -60.0, -90.0] {
        assert_eq!(
            world.views.iter().filter(|v| v.pitch == pitch).count(),
            3,
            "pitch {pitch}"
        );
    }
    let level = &world.level;
    for v in &world.views {
        let c = level.column_at(v.x, v.y);
        assert!(
            !c.is_solid(f32::from(c.top()) + v.eye),
            "{}: eye in solid",
            v.name
        );
    }
    // The hangar view: the centre ray, level, meets a slab within 60 units.
    let hangar = world
        .views
        .iter()
        .find(|v| v.name == "hangar")
        .expect("a hangar view");
    let top = level.column_at(hangar.x, hangar.y).top();
    let z = f32::from(top) + hangar.eye;
    let (s, c) = hangar.yaw.to_radians().sin_cos();
    let hit = (1..600)
        .map(|i| i as f32 * 0.1)
        .find(|d| level.is_solid(hangar.x + s * d, hangar.y + c * d, z))
        .expect("the hangar view hits something within 60");
    let col = level.column_at(hangar.x + s * hit, hangar.y + c * hit);
    assert!(
        col.dual && z >= f32::from(col.mid),
        "hit the floor or a wall, not a slab: {col:?} at z {z}"
    );
    // The edit site: the crater has a slab within its radius, the camera 158 south.
    let edit = world.edit.as_ref().unwrap();
    assert_eq!((edit.radius, edit.depth), (48, 90.0));
    assert_eq!(edit.camera.y as i64 - edit.centre_y, 158);
    let r = edit.radius as i64;
    let slabs = (-r..=r)
        .flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)))
        .filter(|(dx, dy)| dx * dx + dy * dy <= r * r)
        .filter(|(dx, dy)| level.column(edit.centre_x + dx, edit.centre_y + dy).dual)
        .count();
    assert!(slabs > 500, "only {slabs} slab texels inside the crater");
    // ... and the edit camera sees the crater centre: nothing solid on the way.
    let cam = &edit.camera;
    let eye = f32::from(level.column_at(cam.x, cam.y).top()) + cam.eye;
    let centre = (edit.centre_x as f32 + 0.5, edit.centre_y as f32 + 0.5);
    let ground = f32::from(level.column_at(centre.0, centre.1).top()) + 4.0;
    for i in 1..1000 {
        let t = i as f32 / 1000.0;
        let (x, y) = (
            cam.x + (centre.0 - cam.x) * t,
            cam.y + (centre.1 - cam.y) * t,
        );
        let z = eye + (ground - eye) * t;
        assert!(
            !level.is_solid(x, y, z),
            "edit camera's view of the crater blocked at ({x}, {y}, {z})"
        );
    }
    // Within the picture: the crater is less than the half field of view
    // (400 px of an 800-px-high image at 512 px focal) above the view axis.
    let down = ((eye - ground) / (cam.y - centre.1).abs())
        .atan()
        .to_degrees();
    assert!(
        (cam.pitch + down).abs() < (400f32 / 512.0).atan().to_degrees(),
        "crater {down} deg down"
    );
}
