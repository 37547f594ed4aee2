//! A small survey end to end: generated worlds at two dual fractions and a
//! directory that is not a world. The failed world keeps its row with an
//! error naming it, the others are fitted at every quality, the more-dual
//! world fits worse, and the report holds the table and correlations.

use strata_level::generate::{GenerateParams, Knobs};
use strata_survey::{Plan, WorldSpec, report, run};

fn generated(dual: f64, rough: f64) -> WorldSpec {
    WorldSpec::Generated {
        params: GenerateParams {
            seed: 7,
            width: 512,
            height: 1024,
        },
        knobs: Knobs {
            dual_fraction: Some(dual),
            floor_roughness: Some(rough),
        },
    }
}

#[test]
fn a_failed_world_keeps_the_others_rows() {
    let missing = std::env::temp_dir().join("strata-survey-test-no-such-world");
    let plan = Plan {
        worlds: vec![
            generated(0.0, 1.0),
            WorldSpec::Dir(missing.clone()),
            generated(0.3, 1.0),
            generated(0.15, 1.0),
        ],
        qualities: vec![0.0, 0.5, 1.0],
        table_quality: 0.5,
        outline: false,
    };
    let survey = run(&plan, 2, &());
    assert_eq!(survey.worlds.len(), 4);
    let bad = &survey.worlds[1];
    let err = bad.error.as_deref().expect("the missing world failed");
    assert!(err.contains(&missing.display().to_string()), "{err}");
    assert!(bad.fits.is_empty());
    for w in [&survey.worlds[0], &survey.worlds[2], &survey.worlds[3]] {
        assert!(w.error.is_none(), "{:?}", w.error);
        assert_eq!(w.fits.len(), 3);
        // Finer quality, more triangles.
        assert!(w.fits[0].triangles < w.fits[1].triangles);
        assert!(w.fits[1].triangles < w.fits[2].triangles);
    }
    let (flat, dual) = (&survey.worlds[0], &survey.worlds[2]);
    assert!(flat.dual_percent < 0.01 && (dual.dual_percent - 30.0).abs() < 2.0);
    let (a, b) = (flat.fit_at(0.5).unwrap(), dual.fit_at(0.5).unwrap());
    println!(
        "reduction at q=0.5: dual 0 % {:.1}x, dual 30 % {:.1}x",
        a.reduction, b.reduction
    );
    assert!(a.reduction > 1.25 * b.reduction);
    assert_eq!(a.causes[2], 0, "no slab, no boundary insertions");
    assert!(b.causes[2] > 0 && b.slab_share > a.slab_share);

    let corr = report::correlations(&survey);
    assert_eq!(corr.len(), 3);
    let mid = &corr[1];
    assert_eq!(mid.worlds, 3);
    assert!(mid.dual.expect("varies") < -0.5, "{mid:?}");

    let dir = std::env::temp_dir().join(format!("strata-survey-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let figures = strata_survey::plots::write_all(&dir, &survey).unwrap();
    report::write(&dir, "test", &survey, &figures).unwrap();
    let md = std::fs::read_to_string(dir.join("survey.md")).unwrap();
    assert!(md.contains("| dual 30% rough 1 |"), "{md}");
    assert!(md.contains("failed: loading the world in"), "{md}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("survey.json")).unwrap()).unwrap();
    assert_eq!(json["survey"]["worlds"].as_array().unwrap().len(), 4);
    for (_, file) in figures {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.contains("<svg") && svg.contains("circle"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
