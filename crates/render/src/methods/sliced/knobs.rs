//! `sliced:N` and `sliced:N/refine`: the slice count, and the refining pass;
//! `/fragwalk` and `/forward` put back earlier ways of the plain slicer for A/B.

use super::super::contract::MethodSettings;
use super::super::knobs::{Flag, Knobs, Slider, Sweep, count, plain};
use super::super::march_beam::{NO_BEAM_FLAG, nobeam_tag, split_nobeam};
use anyhow::bail;

pub static KNOBS: Knobs = Knobs {
    grammar: "N or N/refine, then optionally /fragwalk (or, for N, /forward), then optionally /nobeam",
    default: Some("512"),
    parse,
    describe: |s| {
        let refined = if s.sliced_refine { " refined" } else { "" };
        let walk = if s.sliced_fragment_walk {
            " fragment-walk"
        } else {
            ""
        };
        let forward = if s.sliced_forward_shading {
            " forward-shading"
        } else {
            ""
        };
        format!(
            "slices={}{refined}{walk}{forward}{}",
            s.slices,
            nobeam_tag(s)
        )
    },
    keep: |from, to| {
        to.slices = from.slices;
        to.sliced_refine = from.sliced_refine;
        to.sliced_fragment_walk = from.sliced_fragment_walk;
        to.sliced_forward_shading = from.sliced_forward_shading;
        to.march_beam = from.march_beam;
    },
    sliders: &[Slider::count(
        "slices",
        "slices",
        (16, 2048),
        |s| s.slices as f32,
        |s, v| s.slices = v as u32,
    )],
    flags: &[
        Flag {
            long: "slices",
            value: Some("N"),
            help: "`sliced`: horizontal slices.",
            default: |s| s.slices.to_string(),
            apply: |text, s| {
                s.slices = count(text)?;
                Ok(())
            },
        },
        Flag {
            long: "sliced-refine",
            value: None,
            help: "`sliced`: per pixel, the exact surface crossing on the ray up to the nearest kept slice (a full-screen pass after the slices).",
            default: |_| String::new(),
            apply: |_, s| {
                s.sliced_refine = true;
                Ok(())
            },
        },
        Flag {
            long: "sliced-fragment-walk",
            value: None,
            help: "`sliced`: each slice fragment walks its own gap on grazing rays, in place of one walk per pixel after the slices (for A/B; `sliced:N/fragwalk`).",
            default: |_| String::new(),
            apply: |_, s| {
                s.sliced_fragment_walk = true;
                Ok(())
            },
        },
        Flag {
            long: "sliced-forward",
            value: None,
            help: "`sliced`: shade every kept slice fragment in the slice pass, in place of marks and one shading a pixel after them (for A/B; `sliced:N/forward`).",
            default: |_| String::new(),
            apply: |_, s| {
                s.sliced_forward_shading = true;
                Ok(())
            },
        },
        NO_BEAM_FLAG,
    ],
};

/// `N` (the paper's plain slicer) or `N/refine`, then optionally
/// `/fragwalk` (or, plain, `/forward`), then optionally `/nobeam` (the
/// per-pixel walks from the near plane).
fn parse(text: &str, s: &mut MethodSettings) -> anyhow::Result<()> {
    let (text, beam) = split_nobeam(text);
    s.march_beam = beam;
    let (text, fragment_walk) = match text.strip_suffix("/fragwalk") {
        Some(rest) => (rest, true),
        None => (text, false),
    };
    let (text, forward) = match text.strip_suffix("/forward") {
        Some(rest) if !fragment_walk => (rest, true),
        _ => (text, false),
    };
    let (n, refine) = match text.split_once('/') {
        Some((n, "refine")) if !forward => (n, true),
        Some((_, "refine")) => bail!("`/forward` is the plain slicer's (not with `refine`)"),
        Some((_, other)) => bail!("`{other}` is not `refine`, `fragwalk` or `forward`"),
        None => (text, false),
    };
    s.slices = plain(count(n))?;
    s.sliced_refine = refine;
    s.sliced_fragment_walk = fragment_walk;
    s.sliced_forward_shading = forward;
    Ok(())
}

/// `strata tune`'s sweep. The refined slicer is a setting of the same
/// method (its slices still decide coverage), so the rule weighs it against
/// the paper's plain slicer at equal tuning.
pub static SWEEP: Sweep = Sweep {
    order: 2,
    knob: "slices [/refine]",
    full: &[
        "32",
        "64",
        "128",
        "256",
        "512",
        "1024",
        "32/refine",
        "64/refine",
        "128/refine",
        "256/refine",
        "512/refine",
        "1024/refine",
    ],
    quick: &["32", "512", "1024", "32/refine", "512/refine"],
    at_paper_size: false,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_refine_and_fragment_walk() {
        let mut s = MethodSettings::default();
        parse("256/refine/fragwalk", &mut s).unwrap();
        assert_eq!(
            (s.slices, s.sliced_refine, s.sliced_fragment_walk),
            (256, true, true)
        );
        parse("512/fragwalk", &mut s).unwrap();
        assert_eq!(
            (s.slices, s.sliced_refine, s.sliced_fragment_walk),
            (512, false, true)
        );
        parse("64", &mut s).unwrap();
        assert_eq!(
            (s.slices, s.sliced_refine, s.sliced_fragment_walk),
            (64, false, false)
        );
        assert!(parse("512/fragwalk/refine", &mut s).is_err());
        parse("512/refine/nobeam", &mut s).unwrap();
        assert!(s.sliced_refine && !s.march_beam);
        parse("512", &mut s).unwrap();
        assert!(s.march_beam);
        assert!(parse("512/fast", &mut s).is_err());
        parse("512/forward/nobeam", &mut s).unwrap();
        assert!(s.sliced_forward_shading && !s.sliced_refine && !s.march_beam);
        parse("512", &mut s).unwrap();
        assert!(!s.sliced_forward_shading);
        assert!(parse("512/refine/forward", &mut s).is_err());
        assert!(parse("512/forward/fragwalk", &mut s).is_err());
    }
}
