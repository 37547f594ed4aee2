//! The reference is converged: halving (and quartering) its step changes no
//! pixel's class and moves no distance measurably, the pyramid skips only
//! what it may, and an independent fine fixed-step march with bisection
//! agrees with it.

mod common;

use glam::{DVec3, Vec3};
use strata_camera::Camera;
use strata_level::Level;
use strata_reference::{HitClass, Reference, ReferenceSettings, Tracer, render_reference_with};

/// Cameras over the rough level: several pitches, eyes low over the terrain
/// (where grazing rays are), plus one inside a cave.
fn cameras(level: &Level) -> Vec<Camera> {
    let mut rng = common::Rng::new(7);
    let mut out = Vec::new();
    for pitch in [0.0, -30.0, -60.0, -90.0, 25.0] {
        for _ in 0..2 {
            let (x, y) = (rng.below(256) as f32 + 0.37, rng.below(256) as f32 + 0.61);
            let top = level.column_at(x, y).top();
            let eye = f32::from(top) + 3.0 + rng.below(60) as f32;
            let yaw = rng.below(360) as f32 + 0.3;
            out.push(Camera::new(Vec3::new(x, y, eye), yaw, pitch, 160, 100).unwrap());
        }
    }
    // Inside the roomiest cave.
    let (mut best, mut at) = (0u32, (0i64, 0i64));
    for y in 0..256 {
        for x in 0..256 {
            let c = level.column(x, y);
            if c.dual && u32::from(c.mid - c.low) > best {
                (best, at) = (u32::from(c.mid - c.low), (x, y));
            }
        }
    }
    assert!(best >= 16, "the rough level has a cave");
    let c = level.column(at.0, at.1);
    let z = f32::from(c.low) + f32::from(c.mid - c.low) * 0.5;
    let pos = Vec3::new(at.0 as f32 + 0.5, at.1 as f32 + 0.5, z);
    for (yaw, pitch) in [(33.0, 0.0), (200.0, 20.0)] {
        out.push(Camera::new(pos, yaw, pitch, 160, 100).unwrap());
    }
    out
}

fn render(level: &Level, cam: &Camera, subdivision: u32, accelerate: bool) -> Reference {
    render_reference_with(
        level,
        cam,
        &ReferenceSettings {
            subdivision,
            accelerate,
        },
    )
}

#[test]
fn halving_the_step_changes_no_class_and_no_distance() {
    let level = common::rough_level(1);
    let mut seen = std::collections::HashSet::new();
    for cam in cameras(&level) {
        let base = render(&level, &cam, 1, true);
        seen.extend(base.class.iter().copied());
        if cam.pitch_deg <= 0.0 {
            assert!(base.sky_fraction() < 100.0, "{cam:?} sees nothing");
        }
        for sub in [2, 4] {
            let fine = render(&level, &cam, sub, true);
            let mut worst = 0f32;
            for k in 0..base.pixel_count() {
                assert_eq!(
                    base.class[k], fine.class[k],
                    "pixel {k} at 1/{sub} step, {cam:?}"
                );
                assert_eq!(base.terrain[k], fine.terrain[k], "pixel {k}, {cam:?}");
                let (a, b) = (base.distance[k], fine.distance[k]);
                if a.is_finite() || b.is_finite() {
                    worst = worst.max((a - b).abs());
                }
            }
            assert!(
                worst < 1e-3,
                "1/{sub} step moved a distance by {worst}, {cam:?}"
            );
        }
        // The pyramid only skips what no ray can touch: bit-identical.
        let plain = render(&level, &cam, 1, false);
        let differ = (0..base.pixel_count())
            .filter(|&k| {
                plain.class[k] != base.class[k]
                    || plain.distance[k].to_bits() != base.distance[k].to_bits()
            })
            .count();
        assert_eq!(differ, 0, "pyramid changed {differ} pixels, {cam:?}");
        // Nor does a tracer that never built one (the viewer's pick).
        let bare = Tracer::unaccelerated(&level).render(&cam, &ReferenceSettings::default());
        assert!(bare == base, "the unaccelerated tracer differs, {cam:?}");
    }
    for class in HitClass::ALL {
        assert!(
            seen.contains(&class),
            "no {class:?} pixel: the test would not cover it"
        );
    }
}

/// An independent, slow reference: fixed step along the ray, then 20
/// bisections of the bracketing step.
fn march(level: &Level, cam: &Camera, step: f64) -> Vec<f32> {
    let o = cam.position.as_dvec3();
    let solid = |p: DVec3| {
        level
            .column(p.x.floor() as i64, p.y.floor() as i64)
            .is_solid(p.z as f32)
    };
    let mut out = Vec::new();
    for j in 0..cam.height {
        for i in 0..cam.width {
            let d = cam
                .image_direction(i as f32 + 0.5, j as f32 + 0.5)
                .as_dvec3();
            let t_max = f64::from(cam.far) * d.length() / f64::from(cam.focal_px);
            let d = d.normalize();
            let mut hit = f32::INFINITY;
            let mut t = 0.0;
            while t < t_max && (o + d * t).z <= 256.0 {
                let next = (t + step).min(t_max);
                if solid(o + d * next) {
                    let (mut lo, mut hi) = (t, next);
                    for _ in 0..20 {
                        let mid = 0.5 * (lo + hi);
                        if solid(o + d * mid) {
                            hi = mid
                        } else {
                            lo = mid
                        }
                    }
                    hit = hi as f32;
                    break;
                }
                t = next;
            }
            out.push(hit);
        }
    }
    out
}

#[test]
fn a_fine_fixed_step_march_agrees() {
    let level = common::rough_level(2);
    let mut total = 0usize;
    let mut mask_differs = 0usize;
    let mut errors = Vec::new();
    for cam in cameras(&level).into_iter().step_by(3) {
        let cam = Camera {
            width: 80,
            height: 50,
            ..cam
        };
        let exact = render(&level, &cam, 1, true);
        let marched = march(&level, &cam, 1.0 / 16.0);
        for (a, b) in exact.distance.iter().zip(&marched) {
            total += 1;
            match (a.is_finite(), b.is_finite()) {
                (true, true) => errors.push((a - b).abs()),
                (false, false) => {}
                _ => mask_differs += 1,
            }
            // A sampled march can only miss thin features, never invent them,
            // so it is never nearer than the exact hit.
            if a.is_finite() && b.is_finite() {
                assert!(*b >= a - 1e-3, "march {b} nearer than exact {a}");
            }
        }
    }
    errors.sort_by(f32::total_cmp);
    let p50 = errors[errors.len() / 2];
    let p99 = errors[errors.len() * 99 / 100];
    let differs = 100.0 * mask_differs as f64 / total as f64;
    println!(
        "march vs exact: {total} px, sky mask differs {differs:.3}%, |dd| p50 {p50} p99 {p99}"
    );
    assert!(differs < 0.5, "{differs}% of pixels disagree on sky");
    assert!(p50 < 1e-3 && p99 < 0.1, "p50 {p50} p99 {p99}");
}
