//! A big world looks like a big world, not the default one repeated: its
//! 2048x2048 windows all differ (also those a whole number of road,
//! district and map-width periods apart) and each has about the default
//! world's dual fraction and roughness. Checked on a 65536x65536 world
//! through the chunked generator, a few windows of it (the whole of it is
//! the store benchmark's: `crates/store/examples/store_windows.rs`).

use rayon::prelude::*;
use strata_level::generate::{Chunked, GenerateParams, Knobs};
use strata_level::stats::LevelStats;

/// The default world's (2048x16384, seed 1997) whole-map figures, as
/// `strata generate` prints them; its own eight 2048² windows spread
/// 11.97 .. 13.46 % dual and 3.55 .. 3.81 floor roughness.
const DEFAULT_DUAL_PERCENT: f64 = 12.74;
const DEFAULT_FLOOR_ROUGHNESS: f64 = 3.66;

#[test]
fn big_world_windows_differ_and_match_the_default_world() {
    let params = GenerateParams {
        seed: 1997,
        width: 1 << 16,
        height: 1 << 16,
    };
    let world = Chunked::new(&params, &Knobs::default()).unwrap();
    // Windows 2048 and 4096 apart each way (multiples of every period the
    // generator has below the map size), and a few far apart.
    let spots: [(i64, i64); 6] = [
        (20480, 8192),
        (22528, 8192),
        (20480, 10240),
        (24576, 12288),
        (61440, 50176),
        (3072, 40960),
    ];
    let windows: Vec<(String, LevelStats)> = spots
        .par_iter()
        .map(|&(x, y)| {
            let level = world.patch(x, y, 2048, 2048).unwrap();
            (level.content_hash(), LevelStats::compute(&level))
        })
        .collect();
    for (i, (hash, s)) in windows.iter().enumerate() {
        for (j, (other, _)) in windows.iter().enumerate().skip(i + 1) {
            assert_ne!(
                hash, other,
                "windows {:?} and {:?} are equal",
                spots[i], spots[j]
            );
        }
        let dual = (s.dual_percent - DEFAULT_DUAL_PERCENT) / DEFAULT_DUAL_PERCENT;
        let rough = (s.roughness_floor - DEFAULT_FLOOR_ROUGHNESS) / DEFAULT_FLOOR_ROUGHNESS;
        // Wider than the default world's own spread: most of a big world's
        // windows have no river valley, which every 2048² window of the
        // default world crosses (bench/store-gen has the measured spread).
        assert!(
            dual.abs() < 0.20 && rough.abs() < 0.10,
            "window {:?}: dual {:.2} % ({:+.1} %), floor roughness {:.3} ({:+.1} %)",
            spots[i],
            s.dual_percent,
            dual * 100.0,
            s.roughness_floor,
            rough * 100.0
        );
        assert_eq!(s.pair_disagreements, 0);
    }
}

#[test]
fn big_world_views_and_edit_site_spread_over_it() {
    let params = GenerateParams {
        seed: 1997,
        width: 1 << 16,
        height: 1 << 16,
    };
    let world = Chunked::new(&params, &Knobs::default())
        .unwrap()
        .world_without_planes();
    assert_eq!(world.views.len(), 12);
    let (w, h) = (params.width as f32, params.height as f32);
    for v in &world.views {
        assert!(
            (0.0..w).contains(&v.x) && (0.0..h).contains(&v.y),
            "view {v} off the map"
        );
    }
    // The landmarks (and so the views) are spread along the whole length.
    let ys: Vec<f32> = world.views.iter().map(|v| v.y).collect();
    let (lo, hi) = ys
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &y| (a.min(y), b.max(y)));
    assert!(hi - lo > 0.8 * h, "views span only {lo} .. {hi}");
    let edit = world.edit.unwrap();
    assert!((0..params.width as i64).contains(&edit.centre_x));
    assert!((0..params.height as i64).contains(&edit.centre_y));
}
