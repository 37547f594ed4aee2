//! Issue 17's generator knobs: each moves its own statistic (as `strata
//! info` measures it) and leaves the other within a tolerance; bad values
//! are errors naming the knob; no knobs is the default world byte for byte.

use strata_level::generate::{GenerateError, GenerateParams, Knobs, generate, generate_with};
use strata_level::stats::LevelStats;

const PARAMS: GenerateParams = GenerateParams {
    seed: 1997,
    width: 1024,
    height: 2048,
};

fn stats(knobs: Knobs) -> LevelStats {
    LevelStats::compute(&generate_with(&PARAMS, &knobs).expect("generates").level)
}

#[test]
fn no_knobs_is_the_default_world() {
    let plain = generate(&PARAMS).unwrap();
    let knobs = generate_with(&PARAMS, &Knobs::default()).unwrap();
    assert_eq!(plain.level.content_hash(), knobs.level.content_hash());
    assert_eq!(plain.name, knobs.name);
}

#[test]
fn dual_fraction_moves_dual_share_not_floor_roughness() {
    let base = stats(Knobs::default());
    let mut rf = Vec::new();
    for f in [0.0, 0.1, 0.3, 0.5] {
        let s = stats(Knobs {
            dual_fraction: Some(f),
            ..Knobs::default()
        });
        println!(
            "dual fraction {f}: dual {:.2} %  r_f {:.3}  r_s {:.3}",
            s.dual_percent, s.roughness_floor, s.roughness_surface
        );
        assert!(
            (s.dual_percent - 100.0 * f).abs() < 1.5,
            "dual fraction {f} gave {:.2} % dual",
            s.dual_percent
        );
        rf.push(s.roughness_floor);
    }
    println!("default: r_f {:.3}", base.roughness_floor);
    for r in rf {
        assert!(
            (r / base.roughness_floor - 1.0).abs() < 0.1,
            "floor roughness moved to {r:.3} from {:.3}",
            base.roughness_floor
        );
    }
}

#[test]
fn floor_roughness_moves_floor_roughness_not_dual_share() {
    let base = stats(Knobs::default());
    let mut last = 0.0;
    for r in [0.0, 1.0, 2.0, 4.0] {
        let s = stats(Knobs {
            floor_roughness: Some(r),
            ..Knobs::default()
        });
        println!(
            "floor roughness {r}: dual {:.2} %  r_f {:.3}  r_s {:.3}",
            s.dual_percent, s.roughness_floor, s.roughness_surface
        );
        assert!(
            s.roughness_floor > last,
            "r_f {:.3} at {r} is not above {last:.3}",
            s.roughness_floor
        );
        last = s.roughness_floor;
        assert!(
            (s.dual_percent - base.dual_percent).abs() < 1.0,
            "dual moved to {:.2} % from {:.2} %",
            s.dual_percent,
            base.dual_percent
        );
    }
    assert!(
        last > 1.4 * base.roughness_floor,
        "r_f at 4 is {last:.3}, the default's {:.3}",
        base.roughness_floor
    );
}

#[test]
fn knob_values_out_of_range_are_named_errors() {
    for knobs in [
        Knobs {
            dual_fraction: Some(0.6),
            ..Knobs::default()
        },
        Knobs {
            dual_fraction: Some(-0.1),
            ..Knobs::default()
        },
        Knobs {
            floor_roughness: Some(f64::NAN),
            ..Knobs::default()
        },
        Knobs {
            floor_roughness: Some(9.0),
            ..Knobs::default()
        },
    ] {
        let err = generate_with(&PARAMS, &knobs).unwrap_err();
        assert!(matches!(err, GenerateError::Knob { .. }), "{err:?}");
        let text = err.to_string();
        assert!(text.contains("outside its range"), "{text}");
    }
}
