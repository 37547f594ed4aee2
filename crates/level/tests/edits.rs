//! Edits: wrapping, pair validity, dirty rectangles, the crater.

mod common;

use common::{Rng, synthetic};
use std::collections::HashSet;
use strata_level::edit::{DirtyRect, EditRect, crater, edit_columns, fill_single};
use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT, MidRule};
use strata_level::{Column, EditSite, Level, ViewSpec};

/// Texels whose height or meta differ.
fn changed(a: &Level, b: &Level) -> HashSet<(u32, u32)> {
    let w = a.width();
    let mut out = HashSet::new();
    for i in 0..a.heights().len() {
        if a.heights()[i] != b.heights()[i] || a.metas()[i] != b.metas()[i] {
            out.insert((i as u32 % w, i as u32 / w));
        }
    }
    out
}

fn covered(rects: &[DirtyRect], level: &Level) -> HashSet<(u32, u32)> {
    let mut out = HashSet::new();
    for r in rects {
        assert!(r.x % 2 == 0 && r.width % 2 == 0, "{r:?} is not whole pairs");
        assert!(
            r.x + r.width <= level.width() && r.y + r.height <= level.height(),
            "{r:?}"
        );
        for y in r.y..r.y + r.height {
            for x in r.x..r.x + r.width {
                assert!(out.insert((x, y)), "rects overlap at {x},{y}");
            }
        }
    }
    out
}

/// Every pair agrees on the dual flag and every dual pair has a cave of at least 8.
fn assert_pairs_valid(level: &Level) {
    assert_eq!(level.pair_disagreement_count(), 0);
    for y in 0..level.height() as i64 {
        for x in (0..level.width() as i64).step_by(2) {
            let c = level.column(x, y);
            if c.dual {
                assert!(c.mid >= c.low + 8 && c.mid <= c.high, "{x},{y}: {c:?}");
            }
        }
    }
}

#[test]
fn fill_wraps_across_both_edges() {
    let mut level = Level::flat(64, 32, 50, 1).unwrap();
    let before = level.clone();
    let rect = EditRect {
        x: -3,
        y: -2,
        width: 6,
        height: 4,
    };
    let dirty = fill_single(&mut level, rect, 10, 4);
    // Widened to pairs: x in [-4, 4) -> 60..64 and 0..4; y in {30, 31, 0, 1}.
    let mut got = dirty.clone();
    got.sort_by_key(|r| (r.x, r.y));
    let r = |x, y| DirtyRect {
        x,
        y,
        width: 4,
        height: 2,
    };
    assert_eq!(got, vec![r(0, 0), r(0, 30), r(60, 0), r(60, 30)]);
    let ch = changed(&before, &level);
    assert_eq!(ch.len(), 32);
    assert_eq!(ch, covered(&dirty, &level));
    assert_eq!(level.column(-1, -1).low, 10);
    assert_eq!(level.column(63, 31).lower_type, 4);
    assert_eq!(level.column(4, 0).low, 50);
    assert_eq!(level.column(59, 0).low, 50);
}

#[test]
fn huge_and_far_rects_stay_inside_one_map() {
    let mut level = Level::flat(16, 8, 50, 1).unwrap();
    let rect = EditRect {
        x: i64::MAX - 3,
        y: i64::MIN,
        width: u32::MAX,
        height: u32::MAX,
    };
    let dirty = fill_single(&mut level, rect, 3, 0);
    assert_eq!(covered(&dirty, &level).len(), 16 * 8);
    assert!(level.heights().iter().all(|&h| h == 3));
}

#[test]
fn callback_sees_unwrapped_coordinates() {
    let mut level = Level::flat(16, 8, 50, 1).unwrap();
    let mut seen = Vec::new();
    edit_columns(
        &mut level,
        EditRect {
            x: 15,
            y: 7,
            width: 1,
            height: 2,
        },
        |x, y, c| {
            seen.push((x, y));
            c
        },
    );
    seen.sort();
    assert_eq!(seen, vec![(14, 7), (14, 8), (15, 7), (15, 8)]);
}

fn dual_level() -> Level {
    // One dual pair at (2,1): low 20, high 100, code 6 -> mid 76 (original rule).
    let mut level = Level::flat(8, 4, 30, 1).unwrap();
    let (h, m) = level.planes_mut();
    h[8 + 2] = 20;
    h[8 + 3] = 100;
    m[8 + 2] = META_DOUBLE_LEVEL | (2 << META_TERRAIN_SHIFT) | 0b01;
    m[8 + 3] = META_DOUBLE_LEVEL | (5 << META_TERRAIN_SHIFT) | 0b10;
    level
}

#[test]
fn closing_the_gap_leaves_the_column_single_at_its_top() {
    let mut level = dual_level();
    assert_eq!(level.column(2, 1).mid, 76);
    let rect = EditRect {
        x: 3,
        y: 1,
        width: 1,
        height: 1,
    };
    // Raise the floor into the slab.
    let dirty = edit_columns(&mut level, rect, |_, _, c| Column {
        low: c.low + 60,
        ..c
    });
    assert_eq!(
        dirty,
        vec![DirtyRect {
            x: 2,
            y: 1,
            width: 2,
            height: 1
        }]
    );
    for x in [2, 3] {
        let c = level.column(x, 1);
        assert_eq!((c.dual, c.low, c.upper_type), (false, 100, 5), "{x}: {c:?}");
    }
    assert_pairs_valid(&level);
}

#[test]
fn short_caves_close_and_gaps_round_down() {
    let mut level = dual_level();
    let rect = EditRect {
        x: 2,
        y: 1,
        width: 2,
        height: 1,
    };
    // Cave of 30 -> largest code with gap <= 30 is 2 (gap 24): mid 44.
    edit_columns(&mut level, rect, |_, _, c| Column {
        mid: 50,
        low: 20,
        ..c
    });
    let c = level.column(2, 1);
    assert_eq!((c.dual, c.low, c.mid, c.high), (true, 20, 44, 100));
    // A cave of 5 cannot be expressed: single at the top.
    edit_columns(&mut level, rect, |_, _, c| Column {
        mid: c.low + 5,
        ..c
    });
    let c = level.column(3, 1);
    assert_eq!((c.dual, c.low), (false, 100));
    // And a single pair can become dual.
    edit_columns(
        &mut level,
        EditRect {
            x: 4,
            y: 2,
            width: 1,
            height: 1,
        },
        |_, _, _| Column {
            low: 10,
            mid: 30,
            high: 60,
            dual: true,
            lower_type: 3,
            upper_type: 6,
        },
    );
    let c = level.column(5, 2);
    assert_eq!(
        (c.dual, c.low, c.mid, c.high, c.lower_type, c.upper_type),
        (true, 10, 26, 60, 3, 6)
    );
    assert_pairs_valid(&level);
}

#[test]
fn random_edits_keep_pairs_valid_and_dirty_rects_cover_changes() {
    let mut level = synthetic(64, 32, 21);
    assert_pairs_valid(&level);
    let mut rng = Rng(99);
    for _ in 0..200 {
        let before = level.clone();
        let rect = EditRect {
            x: rng.below(200) as i64 - 100,
            y: rng.below(100) as i64 - 50,
            width: rng.below(40) as u32,
            height: rng.below(20) as u32,
        };
        let (a, b, c) = (
            rng.below(256) as u8,
            rng.below(256) as u8,
            rng.below(256) as u8,
        );
        let kind = rng.below(3);
        let dirty = edit_columns(&mut level, rect, |x, y, col| {
            match (kind as i64 + (x ^ y)).rem_euclid(3) {
                0 => Column {
                    low: a,
                    mid: b,
                    high: c,
                    dual: true,
                    ..col
                },
                1 => Column {
                    low: col.low.wrapping_add(a),
                    ..col
                },
                _ => Column {
                    low: b,
                    mid: b,
                    high: b,
                    dual: false,
                    lower_type: 7,
                    upper_type: 7,
                },
            }
        });
        let ch = changed(&before, &level);
        let cov = covered(&dirty, &level);
        assert!(
            ch.is_subset(&cov),
            "a changed texel lies outside the dirty rects"
        );
        assert_pairs_valid(&level);
    }
}

fn site(x: i64, y: i64) -> EditSite {
    EditSite {
        centre_x: x,
        centre_y: y,
        radius: 6,
        depth: 90.0,
        camera: ViewSpec::parse("e", "0,0:0:10", 0.0).unwrap(),
    }
}

#[test]
fn crater_lowers_the_floor_removes_slabs_and_wraps() {
    let mut level = synthetic(64, 32, 5);
    let before = level.clone();
    let dirty = crater(&mut level, &site(1, 30));
    assert_eq!(dirty.len(), 4, "{dirty:?}");
    let ch = changed(&before, &level);
    assert!(ch.is_subset(&covered(&dirty, &level)));
    assert_pairs_valid(&level);
    // Centre: floor lowered by 90, never below 0; no slab left inside.
    let c0 = before.column(0, 30);
    assert_eq!(level.column(1, 30).low, c0.low.saturating_sub(90));
    for dy in -5i64..=5 {
        for dx in -4i64..=4 {
            if dx * dx + dy * dy < 25 {
                assert!(!level.column(1 + dx, 30 + dy).dual, "{dx},{dy}");
            }
        }
    }
    // Outside the radius nothing changes.
    assert_eq!(level.column(10, 30), before.column(10, 30));
    assert_eq!(level.column(1, 20), before.column(1, 20));
    // Profile: depth (1 - d²/r²) at d = 3 of r = 6 -> 67.5 below a raised
    // floor of 200: 132.5, rounded half away from zero.
    let mut flat = Level::flat(64, 32, 200, 2).unwrap();
    crater(&mut flat, &site(32, 16));
    assert_eq!(flat.column(32, 16).low, 110);
    assert_eq!(flat.column(35, 16).low, 133);
    assert_eq!(flat.column(38, 16).low, 200);
    assert_eq!(flat.mid_rule, MidRule::Original);
}

/// A snapshot taken before a crater undoes it exactly, every bit, also when
/// the crater wraps over a corner of the map; the edit's changes lie inside
/// the snapshot's rectangles.
#[test]
fn snapshot_undoes_a_crater_exactly_across_the_corner() {
    use strata_level::edit::{Snapshot, covered_rects, crater_rect};
    let original = synthetic(64, 32, 11);
    for (cx, cy) in [(30, 16), (1, 0), (63, 31), (-5, 40)] {
        let site = EditSite {
            centre_x: cx,
            centre_y: cy,
            radius: 9,
            depth: 30.0,
            ..EditSite::fostral()
        };
        let mut level = original.clone();
        let snapshot = Snapshot::take(&level, crater_rect(&site));
        let dirty = crater(&mut level, &site);
        assert!(!dirty.is_empty(), "crater at {cx},{cy} changed nothing");
        let inside = covered(&covered_rects(&level, crater_rect(&site)), &level);
        assert!(changed(&original, &level).is_subset(&inside));
        let restored = snapshot.restore(&mut level);
        assert_eq!(restored, covered_rects(&level, crater_rect(&site)));
        assert!(level == original, "undo at {cx},{cy} left differences");
        assert!(snapshot.bytes() <= 2 * 20 * 19);
    }
}

/// Issue 35, bad input: a crater outside the map wraps onto it (the same
/// texels as its copy inside), a radius of 0 digs nothing, a radius larger
/// than the map lowers every texel once (the nearest copy of the centre
/// decides), a depth that is not finite is refused by `try_crater` and
/// changes nothing through `crater`; centres at the ends of i64 do not panic.
#[test]
fn bad_craters_wrap_do_nothing_or_are_refused() {
    use strata_level::edit::{EditError, try_crater};
    let original = synthetic(64, 32, 5);
    let dig = |s: &EditSite| {
        let mut level = original.clone();
        let dirty = crater(&mut level, s);
        (level, dirty)
    };
    // Outside the map, many maps away: the same crater as its copy inside.
    let (inside, _) = dig(&site(10, 12));
    for (x, y) in [(10 + 64 * 1000, 12 - 32 * 7), (10 - 64 * 3, 12 + 32 * 5)] {
        let (outside, dirty) = dig(&site(x, y));
        assert!(!dirty.is_empty());
        assert!(
            outside == inside,
            "crater at {x},{y} is not the one at 10,12"
        );
    }
    // Radius 0: nothing.
    let (level, dirty) = dig(&EditSite {
        radius: 0,
        ..site(10, 12)
    });
    assert!(dirty.is_empty() && level == original);
    // Larger than the map: every texel lowered, once; symmetric about the centre.
    let mut flat = Level::flat(64, 32, 200, 2).unwrap();
    let dirty = crater(
        &mut flat,
        &EditSite {
            radius: 1000,
            depth: 50.0,
            ..site(7, 3)
        },
    );
    assert!(!dirty.is_empty());
    for y in 0..32i64 {
        for x in 0..64i64 {
            let low = flat.column(x, y).low;
            assert!((150..200).contains(&low), "{x},{y}: {low}");
            assert_eq!(low, flat.column(14 - x, 6 - y).low, "{x},{y}");
        }
    }
    assert_eq!(flat.column(7, 3).low, 150);
    let mut huge = Level::flat(64, 32, 200, 2).unwrap();
    crater(
        &mut huge,
        &EditSite {
            radius: u32::MAX,
            depth: 50.0,
            ..site(7, 3)
        },
    );
    assert!((0..64).all(|x| huge.column(x, 9).low == 150));
    // NaN and infinite depths: an error from try_crater, nothing changed.
    for depth in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let s = EditSite {
            depth,
            ..site(10, 12)
        };
        let mut level = original.clone();
        let e = try_crater(&mut level, &s).unwrap_err();
        assert!(matches!(e, EditError::Depth(_)));
        assert!(e.to_string().contains("not a finite number"), "{e}");
        assert!(level == original);
        assert!(dig(&s).1.is_empty());
    }
    assert!(try_crater(&mut original.clone(), &site(10, 12)).is_ok());
    // The ends of i64: wraps, no overflow.
    for (x, y) in [(i64::MAX, i64::MIN), (i64::MIN, i64::MAX)] {
        let (level, _) = dig(&site(x, y));
        assert_pairs_valid(&level);
    }
}
