//! The collider against the CPU reference's exact ray cast, after edits too.

use glam::DVec3;
use strata_collide::{BoxShape, TerrainCollider};
use strata_level::lcg::Lcg;
use strata_level::{EditSite, Level};
use strata_mesh::{ChunkLayout, dirty_chunks, synthetic::synthetic_level};
use strata_reference::{ReferenceSettings, Tracer};

const TOL: f64 = 1.0;

fn level() -> Level {
    synthetic_level(256, 256, 3)
}

fn reference_hit(level: &Level, o: DVec3, d: DVec3) -> Option<f64> {
    Tracer::new(level)
        .trace(o, d, 4000.0, &ReferenceSettings::default())
        .map(|h| h.distance)
}

fn collider_hit(c: &TerrainCollider, o: DVec3, d: DVec3) -> Option<f64> {
    c.cast_ray(o.into(), d.into(), 4000.0).map(|h| h.distance)
}

/// Straight down through texel centres (where the fit's error bound holds):
/// the collider's altitude is within the fit tolerance of the exact one.
#[test]
fn vertical_rays_agree_with_reference_within_tolerance() {
    let level = level();
    let collider = TerrainCollider::fit(&level, TOL);
    let mut rng = Lcg(7);
    let (mut worst, n) = (0.0f64, 2000);
    let mut over = 0;
    for _ in 0..n {
        let x = (rng.next_f64() * 256.0).floor() + 0.5;
        let y = (rng.next_f64() * 256.0).floor() + 0.5;
        let o = DVec3::new(x, y, 300.0);
        let d = DVec3::NEG_Z;
        let r = reference_hit(&level, o, d).expect("reference sees the ground");
        let m = collider_hit(&collider, o, d).expect("collider sees the ground");
        let e = (r - m).abs();
        worst = worst.max(e);
        if e > TOL + 1e-3 {
            over += 1;
        }
    }
    println!("vertical down: worst |Δz| {worst:.3} (tolerance {TOL}), {over}/{n} over");
    assert_eq!(over, 0, "worst {worst}");
}

/// Straight up from inside caves at dual texel centres: the cave ceiling.
#[test]
fn upward_rays_hit_the_slab_ceiling() {
    let level = level();
    let collider = TerrainCollider::fit(&level, TOL);
    let (mut n, mut over, mut worst) = (0, 0, 0.0f64);
    for y in (0..256).step_by(3) {
        for x in (0..256).step_by(3) {
            let c = level.column(x, y);
            if !c.dual || c.mid <= c.low + 2 {
                continue;
            }
            let o = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, f64::from(c.low) + 1.0);
            let r = reference_hit(&level, o, DVec3::Z).expect("the ceiling is above");
            let Some(m) = collider_hit(&collider, o, DVec3::Z) else {
                over += 1;
                continue;
            };
            n += 1;
            let e = (r - m).abs();
            worst = worst.max(e);
            if e > TOL + 1e-3 {
                over += 1;
            }
        }
    }
    println!("vertical up into ceilings: {n} rays, worst |Δz| {worst:.3}, {over} over");
    assert!(n > 100, "the fixture has caves ({n} rays)");
    assert_eq!(over, 0, "worst {worst}");
}

/// Is `p` within the fit tolerance of the terrain's sampled surfaces around
/// it? Samples stand at texel centres and the TIN interpolates between them,
/// so a point is on the terrain when its altitude lies in the range one of
/// the three surfaces (floor, slab top, ceiling) spans over the 4x4 samples
/// around it, widened by the tolerance.
fn on_sampled_surface(level: &Level, p: DVec3, tol: f64) -> bool {
    let (bx, by) = ((p.x - 0.5).floor() as i64, (p.y - 0.5).floor() as i64);
    let mut range = [(f64::MAX, f64::MIN); 3];
    for y in by - 1..=by + 2 {
        for x in bx - 1..=bx + 2 {
            let c = level.column(x, y);
            for (k, z) in [c.low, c.mid, c.high].into_iter().enumerate() {
                let z = f64::from(z);
                range[k] = (range[k].0.min(z), range[k].1.max(z));
            }
        }
    }
    range
        .iter()
        .any(|&(lo, hi)| p.z >= lo - tol && p.z <= hi + tol)
}

/// Random oblique rays (down from above, and steeply up out of caves into
/// the slab's ceiling). Every collider hit lies on the terrain within the
/// fit tolerance; the hit distances agree with the exact cast within the
/// tolerance (in altitude) for most rays, the rest being rays that graze a
/// cliff, where the TIN's ramp between two texel centres and the
/// reference's vertical column side legitimately part.
#[test]
fn random_rays_agree_with_reference() {
    let level = level();
    let collider = TerrainCollider::fit(&level, TOL);
    let tracer = Tracer::new(&level);
    let mut rng = Lcg(11);
    let (mut n, mut close, mut up, mut misses) = (0, 0, 0, 0);
    let mut errors = Vec::new();
    while n < 3000 {
        let x = rng.next_f64() * 256.0;
        let y = rng.next_f64() * 256.0;
        let c = level.column(x.floor() as i64, y.floor() as i64);
        let az = rng.next_f64() * std::f64::consts::TAU;
        let into_ceiling = c.dual && c.mid > c.low + 4 && rng.next_f64() < 0.5;
        let (o, d) = if into_ceiling {
            let el = 0.8 + rng.next_f64() * 0.19;
            let h = (1.0 - el * el).sqrt();
            // From the middle of the cave, well clear of the floor's ramps.
            let z = (f64::from(c.low) + f64::from(c.mid)) * 0.5;
            (
                DVec3::new(x.floor() + 0.5, y.floor() + 0.5, z),
                DVec3::new(h * az.cos(), h * az.sin(), el),
            )
        } else {
            let el = 0.3 + rng.next_f64() * 0.69;
            let h = (1.0 - el * el).sqrt();
            (
                DVec3::new(x, y, 260.0),
                DVec3::new(h * az.cos(), h * az.sin(), -el),
            )
        };
        let Some(r) = tracer.trace(o, d, 4000.0, &ReferenceSettings::default()) else {
            continue;
        };
        n += 1;
        up += usize::from(into_ceiling);
        let Some(m) = collider.cast_ray(o.into(), d.into(), 4000.0) else {
            // A ray grazing a column's side may slip past the ramp; a slab
            // narrower than a triangle has no ceiling in the TIN.
            eprintln!(
                "missed {o} {d}: reference {:?} at {:.1}",
                r.class, r.distance
            );
            misses += 1;
            continue;
        };
        let p = DVec3::from(m.point);
        assert!(
            on_sampled_surface(&level, p, TOL + 1e-3),
            "collider hit {p} off the terrain (ray {o} {d})"
        );
        let e = ((r.distance - m.distance) * d.z).abs();
        errors.push(e);
        if e <= TOL + 1e-3 {
            close += 1;
        }
    }
    errors.sort_by(f64::total_cmp);
    let p = |q: f64| errors[((errors.len() - 1) as f64 * q) as usize];
    let share = close as f64 / n as f64;
    println!(
        "random rays: {n} ({up} up into ceilings, {misses} grazing misses), {:.1} % within τ in altitude; |Δz| median {:.3} p90 {:.3} p99 {:.3}",
        share * 100.0,
        p(0.5),
        p(0.9),
        p(0.99)
    );
    assert!(up > 50, "{up} rays into ceilings");
    assert!(misses * 100 < n, "{misses} misses");
    assert!(share > 0.8, "{share}");
    assert!(p(0.5) <= TOL * 0.5, "median {}", p(0.5));
}

/// A crater replaces exactly the dirty chunks, and casts through it see the
/// new floor.
#[test]
fn crater_refit_sees_the_new_floor() {
    let mut level = level();
    let mut collider = TerrainCollider::fit(&level, TOL);
    let mut site = EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) = (127, 60, 24, 40.0);
    let o = DVec3::new(127.5, 60.5, 300.0);
    let before = collider_hit(&collider, o, DVec3::NEG_Z).unwrap();
    let untouched = collider.chunk(3).triangles();
    let dirty = strata_level::edit::crater(&mut level, &site);
    let rebuilt = collider.apply_edit(&level, &dirty);
    let expected = dirty_chunks(&ChunkLayout::of(&level), 256, 256, &dirty);
    assert_eq!(rebuilt, expected);
    assert!(!rebuilt.contains(&3) && collider.chunk(3).triangles() == untouched);
    let after = collider_hit(&collider, o, DVec3::NEG_Z).unwrap();
    let exact = reference_hit(&level, o, DVec3::NEG_Z).unwrap();
    println!("crater centre: before {before:.2} after {after:.2} reference {exact:.2}");
    assert!(
        after - before > 20.0,
        "the floor went down: {before} -> {after}"
    );
    assert!((after - exact).abs() <= TOL + 1e-3);
    // And an oblique ray into the crater's rim side.
    let o2 = DVec3::new(100.5, 60.5, 200.0);
    let d2 = (DVec3::new(127.5, 60.5, 0.0) - o2).normalize();
    let _ = collider_hit(&collider, o2, d2).expect("hits the crater region");
}

/// A box: contact distance and a downward box cast agree with the ray.
#[test]
fn box_contact_and_cast_match_the_ground() {
    let level = level();
    // A flat pad (filled by an edit) so the box's clearance is plain.
    let mut level = level;
    let pad = strata_level::edit::EditRect {
        x: 30,
        y: 190,
        width: 24,
        height: 24,
    };
    strata_level::edit::fill_single(&mut level, pad, 100, 1);
    let collider = TerrainCollider::fit(&level, TOL);
    let (x, y) = (42.0, 202.0);
    let ground = 300.0 - collider_hit(&collider, DVec3::new(x, y, 300.0), DVec3::NEG_Z).unwrap();
    let half = [0.5f32, 0.5, 0.5];
    // Cast a small box down: it stops about half a unit above the ground
    // under its centre (higher if a slope under a corner comes first).
    let b = BoxShape::axis_aligned([x, y, ground + 50.0], half);
    let hit = collider
        .cast_box(&b, [0.0, 0.0, -1.0], 200.0)
        .expect("lands");
    let rest = ground + 50.0 - hit.distance;
    println!("ground {ground:.2}, box rests at {rest:.2}");
    assert!((rest - (ground + 0.5)).abs() < 1e-2, "{rest}");
    // Sunk 0.3 into the ground: a contact with negative distance.
    let sunk = BoxShape::axis_aligned([x, y, rest - 0.3], half);
    let c = collider.contact_box(&sunk, 0.0).expect("penetrates");
    assert!(c.distance < -0.2 && c.distance > -0.4, "{}", c.distance);
    // Well above: no contact within a margin of 1.
    let above = BoxShape::axis_aligned([x, y, rest + 5.0], half);
    assert!(collider.contact_box(&above, 1.0).is_none());
    // Half a unit above: reported within a margin of 1, at that distance.
    let near = BoxShape::axis_aligned([x, y, rest + 0.5], half);
    let c = collider.contact_box(&near, 1.0).expect("within the margin");
    assert!(
        (c.distance - 0.5).abs() < 1e-3 && c.normal[2] > 0.99,
        "{c:?}"
    );
}
