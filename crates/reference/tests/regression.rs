//! The regression tests the paper earned the hard way (issue 3).

mod common;

use common::{fill, set_dual};
use glam::Vec3;
use strata_camera::{Camera, CameraError};
use strata_level::{Level, ViewSpec};
use strata_reference::{HitClass, Reference, render_reference};

fn at(r: &Reference, i: u32, j: u32) -> (f32, HitClass, u8) {
    let k = (i + j * r.width) as usize;
    (r.distance[k], r.class[k], r.terrain[k])
}

/// Columns of row `j` that hit something.
fn hit_columns(r: &Reference, j: u32) -> Vec<u32> {
    (0..r.width)
        .filter(|&i| at(r, i, j).0.is_finite())
        .collect()
}

/// Flat ground at 10, one 4x4 pillar of height 100 whose west edge is 22 and
/// east edge 18 units west of the eye, its front face 200 units ahead (+y).
fn pillar_scene() -> (Level, Vec3) {
    let mut level = Level::flat(512, 512, 10, 1).unwrap();
    let eye = Vec3::new(256.0, 100.0, 30.0);
    fill(&mut level, 234, 238, 300, 304, 100, 5);
    (level, eye)
}

#[test]
fn focal_length_does_not_scale_with_image_size() {
    let (level, eye) = pillar_scene();
    let mut offsets = Vec::new();
    for (w, h) in [(400, 260), (1280, 800)] {
        let cam = Camera::new(eye, 0.0, 0.0, w, h).unwrap();
        let r = render_reference(&level, &cam);
        // Just below the horizon the ground is beyond far: only the pillar hits.
        let cols = hit_columns(&r, h / 2);
        assert!(!cols.is_empty(), "{w}x{h}: pillar not seen");
        // With a 512 px focal length the pillar's front face (22..18 units
        // west, 200 ahead) spans 56.32..46.08 px right of the centre (west is
        // screen-right), and its east face (18 west, 200..204 ahead) reaches
        // in to 512 * 18 / 204 = 45.18 px: pixel centres 45.5 ..= 55.5.
        let off: Vec<i64> = cols
            .iter()
            .map(|&i| i64::from(i) - i64::from(w / 2))
            .collect();
        assert_eq!(off, (45..=55).collect::<Vec<_>>(), "{w}x{h}");
        // The outermost column sees the front face, 200 ahead along the axis.
        let i = *cols.last().unwrap();
        let (d, class, terrain) = at(&r, i, h / 2);
        let expected = 200.0
            * cam
                .image_direction(i as f32 + 0.5, (h / 2) as f32 + 0.5)
                .length()
            / 512.0;
        assert!((d - expected).abs() < 1e-3, "{d} vs {expected}");
        assert_eq!((class, terrain), (HitClass::Wall, 5));
        offsets.push(off);
    }
    assert_eq!(offsets[0], offsets[1]);
}

#[test]
fn sea_level_is_hit_straight_down() {
    // Ground at 40 with a 16x16 pool of height 0 under the eye.
    let mut level = Level::flat(128, 128, 40, 2).unwrap();
    fill(&mut level, 56, 72, 56, 72, 0, 0);
    let cam = Camera::new(Vec3::new(64.0, 64.0, 60.0), 0.0, -90.0, 65, 65).unwrap();
    let r = render_reference(&level, &cam);
    assert_eq!(r.sky_fraction(), 0.0, "a straight-down frame has no sky");
    let (d, class, terrain) = at(&r, 32, 32);
    assert!((d - 60.0).abs() < 1e-4, "{d}");
    assert_eq!((class, terrain), (HitClass::Floor, 0));
    // An all-sea map too.
    let sea = Level::flat(64, 64, 0, 0).unwrap();
    let cam = Camera::new(Vec3::new(3.0, 3.0, 25.0), 10.0, -90.0, 33, 33).unwrap();
    let r = render_reference(&sea, &cam);
    assert!(r.class.iter().all(|&c| c == HitClass::Floor));
    assert!((at(&r, 16, 16).0 - 25.0).abs() < 1e-4);
}

#[test]
fn east_lands_on_the_side_the_camera_model_says() {
    let mut level = Level::flat(512, 512, 10, 1).unwrap();
    // A landmark 40 east (+x) of the eye, 150 ahead along +y.
    fill(&mut level, 294, 298, 250, 254, 120, 3);
    let eye = Vec3::new(256.0, 100.0, 30.0);
    let cam = Camera::new(eye, 0.0, 0.0, 320, 200).unwrap();
    let r = render_reference(&level, &cam);
    let cols = hit_columns(&r, 100);
    assert!(!cols.is_empty());
    // Pinned: the image is mirrored like the original map (DESIGN §2), so
    // east is on the LEFT when looking along +y ...
    assert!(cols.iter().all(|&i| i < 160), "{cols:?}");
    // ... exactly where the camera projects it.
    let p = cam.project(Vec3::new(296.0, 250.0, 30.0)).unwrap();
    assert!(cols.contains(&(p.x as u32)), "{p} vs {cols:?}");
    // Yaw 90 looks along +x: the landmark (40 east, 150 north) is now ahead,
    // 150 units to the left, i.e. north = screen-right? The model says
    // screen-right is -right = -(flat x Z) = +y for yaw 90: so on the right.
    let cam = Camera::new(Vec3::new(150.0, 252.0, 30.0), 90.0, 0.0, 320, 200).unwrap();
    let r = render_reference(&level, &cam);
    let cols = hit_columns(&r, 100);
    // Straight ahead at 144 units, centred within 4 texels' width (~14 px).
    assert!(cols.contains(&159) && cols.contains(&160), "{cols:?}");
    let (d, class, _) = at(&r, 160, 100);
    assert!((d - 144.0).abs() < 0.01, "{d}");
    assert_eq!(class, HitClass::Wall);
    let north = cam.project(Vec3::new(200.0, 262.0, 30.0)).unwrap();
    assert!(north.x > 160.0, "yaw 90: +y is screen-right: {north}");
}

/// Floor 10 everywhere; a slab over x in [40, 88), y in [60, 100) with
/// floor 10, top 80, gap code 7 (mid = 10 + 8 * 8 = 74); a wall of height
/// 200 across y in [110, 114).
fn cave_scene() -> Level {
    let mut level = Level::flat(128, 128, 10, 1).unwrap();
    for y in 60..100 {
        for x in (40..88).step_by(2) {
            set_dual(&mut level, x, y, 10, 80, 7, 2, 6);
        }
    }
    fill(&mut level, 0, 128, 110, 114, 200, 4);
    assert_eq!(level.column(64, 70).mid, 74);
    level
}

#[test]
fn a_ray_under_a_slab_reaches_the_far_wall() {
    let level = cave_scene();
    // From outside, at z 30, looking along +y into the cave mouth.
    let cam = Camera::new(Vec3::new(64.5, 40.5, 30.0), 0.0, 0.0, 33, 33).unwrap();
    let r = render_reference(&level, &cam);
    let (d, class, terrain) = at(&r, 16, 16);
    assert!((d - 69.5).abs() < 1e-4, "{d}");
    assert_eq!((class, terrain), (HitClass::Wall, 4));
    // Looking up 40 degrees, the ray enters the cave mouth at z 46.4 and
    // meets the underside (mid 74) at y 92.9, inside the slab's extent.
    let cam = Camera::new(Vec3::new(64.5, 40.5, 30.0), 0.0, 40.0, 33, 33).unwrap();
    let (d, class, terrain) = at(&render_reference(&level, &cam), 16, 16);
    assert_eq!((class, terrain), (HitClass::CaveCeiling, 6));
    let expected = 44.0 / 40f32.to_radians().sin();
    assert!((d - expected).abs() < 1e-3, "{d} vs {expected}");
    // From inside the cave (eye measured above the floor).
    let view = ViewSpec::parse("cave", "64.5,70.5:0:20:under", 0.0).unwrap();
    let cam = Camera::from_view(&level, &view, 33, 33).unwrap();
    assert_eq!(cam.position.z, 30.0);
    let r = render_reference(&level, &cam);
    let (d, class, _) = at(&r, 16, 16);
    assert!((d - 39.5).abs() < 1e-4, "{d}");
    assert_eq!(class, HitClass::Wall);
}

#[test]
fn a_ray_up_inside_the_cave_hits_the_ceiling_at_mid() {
    let level = cave_scene();
    let view = ViewSpec::parse("up", "64.5,80.5:0:20:under", 90.0).unwrap();
    let cam = Camera::from_view(&level, &view, 33, 33).unwrap();
    let r = render_reference(&level, &cam);
    let (d, class, terrain) = at(&r, 16, 16);
    assert_eq!((class, terrain), (HitClass::CaveCeiling, 6));
    assert!((d - 44.0).abs() < 1e-5, "74 - 30 = 44, got {d}");
    // And straight down from above the slab: its top at 80.
    let view = ViewSpec::parse("down", "64.5,80.5:0:20", -90.0).unwrap();
    let cam = Camera::from_view(&level, &view, 33, 33).unwrap();
    let (d, class, terrain) = at(&render_reference(&level, &cam), 16, 16);
    assert_eq!((class, terrain), (HitClass::SlabTop, 6));
    assert!((d - 20.0).abs() < 1e-5, "{d}");
}

#[test]
fn views_wrap_and_bad_cameras_are_errors() {
    let level = cave_scene();
    let inside = ViewSpec::parse("v", "64.5,80.5:0:20:under", -10.0).unwrap();
    let wrapped = ViewSpec::parse("v", "-63.5,336.5:0:20:under", -10.0).unwrap();
    let a = Camera::from_view(&level, &inside, 40, 30).unwrap();
    let b = Camera::from_view(&level, &wrapped, 40, 30).unwrap();
    assert_eq!(render_reference(&level, &a), render_reference(&level, &b));
    let buried = ViewSpec::parse("v", "64.5,80.5:0:65:under", 0.0).unwrap();
    assert!(matches!(
        Camera::from_view(&level, &buried, 40, 30),
        Err(CameraError::EyeInSolid { .. })
    ));
    assert!(matches!(
        Camera::new(Vec3::ZERO, 0.0, 0.0, 0, 30),
        Err(CameraError::Size(0, 30))
    ));
    assert!(Camera::new(Vec3::ZERO, 0.0, -91.0, 10, 10).is_err());
}

#[test]
fn rays_wrap_around_the_map() {
    // A 64x64 map: the wall at y in [110,114) of a 128 map is replaced by one
    // at y 8..12; looking +y from y 40, the ray wraps past 64 and hits it at
    // y 72 = 64 + 8, distance 32.
    let mut level = Level::flat(64, 64, 10, 1).unwrap();
    fill(&mut level, 0, 64, 8, 12, 200, 3);
    let cam = Camera::new(Vec3::new(20.5, 40.0, 30.0), 0.0, 0.0, 33, 33).unwrap();
    let (d, class, terrain) = at(&render_reference(&level, &cam), 16, 16);
    assert!((d - 32.0).abs() < 1e-4, "{d}");
    assert_eq!((class, terrain), (HitClass::Wall, 3));
}
