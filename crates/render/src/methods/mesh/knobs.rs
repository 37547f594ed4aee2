//! `mesh:Q[o][/PX][/gradient][/fragment][/centres]`: the fit quality, the
//! outline-constrained fit, the LOD tolerance in pixels, the gradient-normal
//! diagnostic, and for A/B the fragment path's colour (against the deferred
//! frame) and samples at texel centres (against samples moved to walls).

use super::super::contract::MethodSettings;
use super::super::knobs::{Flag, Knobs, Slider, SliderKind, Sweep, plain, positive};
use anyhow::{Context, bail};

pub static KNOBS: Knobs = Knobs {
    grammar: "Q, q=Q or Qo, then /PX, /gradient, /fragment and /centres",
    default: Some("0.5"),
    parse,
    describe: |s| {
        format!(
            "q={}{} lod={}px{}{}{}",
            s.mesh_quality,
            if s.mesh_outline { " outline" } else { "" },
            s.mesh_lod_pixels,
            if s.mesh_gradient_normal {
                " gradient-normal"
            } else {
                ""
            },
            if s.mesh_fragment { " fragment" } else { "" },
            if s.mesh_texel_centres {
                " texel-centres"
            } else {
                ""
            }
        )
    },
    keep: |from, to| {
        to.mesh_quality = from.mesh_quality;
        to.mesh_outline = from.mesh_outline;
        to.mesh_lod_pixels = from.mesh_lod_pixels;
        to.mesh_gradient_normal = from.mesh_gradient_normal;
        to.mesh_fragment = from.mesh_fragment;
        to.mesh_texel_centres = from.mesh_texel_centres;
    },
    sliders: &[
        Slider {
            name: "mesh-quality",
            label: "mesh quality",
            kind: SliderKind::Number { min: 0.0, max: 1.0 },
            get: |s| s.mesh_quality,
            put: |s, v| s.mesh_quality = v,
            // A new fit, in the background: when the drag ends.
            live: false,
        },
        Slider {
            name: "mesh-outline",
            label: "mesh outline-constrained (refits)",
            kind: SliderKind::Toggle,
            get: |s| f32::from(u8::from(s.mesh_outline)),
            put: |s, v| s.mesh_outline = v != 0.0,
            live: true,
        },
        Slider {
            name: "mesh-lod-pixels",
            label: "mesh LOD px",
            kind: SliderKind::Number {
                min: 0.25,
                max: 16.0,
            },
            get: |s| s.mesh_lod_pixels,
            put: |s, v| s.mesh_lod_pixels = v,
            live: false,
        },
    ],
    flags: &[
        Flag {
            long: "mesh-quality",
            value: Some("Q"),
            help: "`mesh`: fit quality q in [0, 1]; max error 2^(4(1-q)) height units.",
            default: |s| s.mesh_quality.to_string(),
            apply: |text, s| {
                s.mesh_quality = match text.trim().parse::<f32>() {
                    Ok(q) if (0.0..=1.0).contains(&q) => q,
                    Ok(q) => return Err(format!("mesh quality {q} is outside [0, 1]")),
                    Err(_) => return Err(format!("`{text}` is not a number in [0, 1]")),
                };
                Ok(())
            },
        },
        Flag {
            long: "mesh-outline",
            value: None,
            help: "`mesh`: constrain the fit to the single/double region outline.",
            default: |_| String::new(),
            apply: |_, s| {
                s.mesh_outline = true;
                Ok(())
            },
        },
        Flag {
            long: "mesh-lod-pixels",
            value: Some("PX"),
            help: "`mesh`: LOD by projected error: the most a chunk's max error may cover on screen, in pixels.",
            default: |s| s.mesh_lod_pixels.to_string(),
            apply: |text, s| {
                s.mesh_lod_pixels = positive(text).map_err(|_| {
                    format!("mesh LOD tolerance `{text}` is not a positive number of pixels")
                })?;
                Ok(())
            },
        },
        Flag {
            long: "mesh-fragment",
            value: None,
            help: "`mesh`: colour in the raster pass's fragments instead of the deferred compute pass (for A/B).",
            default: |_| String::new(),
            apply: |_, s| {
                s.mesh_fragment = true;
                Ok(())
            },
        },
        Flag {
            long: "mesh-texel-centres",
            value: None,
            help: "`mesh`: every sample at its texel's centre, none moved to a wall beside it (for A/B).",
            default: |_| String::new(),
            apply: |_, s| {
                s.mesh_texel_centres = true;
                Ok(())
            },
        },
        Flag {
            long: "mesh-gradient-normal",
            value: None,
            help: "`mesh`, a diagnostic: shade with the height-field gradient normal instead of the flat one.",
            default: |_| String::new(),
            apply: |_, s| {
                s.mesh_gradient_normal = true;
                Ok(())
            },
        },
    ],
};

/// `Q`, `q=Q`, `Qo` (outline-constrained), then `/PX` (the LOD tolerance in
/// pixels; `/`, as `,` separates methods), `/gradient` (the
/// gradient-normal diagnostic), `/fragment` (the fragment path's colour) and
/// `/centres` (samples at texel centres), in any order.
fn parse(text: &str, s: &mut MethodSettings) -> anyhow::Result<()> {
    let mut parts = text.split('/');
    let q = parts.next().unwrap_or_default().trim();
    let mut px = None;
    for part in parts.map(str::trim) {
        if part == "gradient" {
            s.mesh_gradient_normal = true;
        } else if part == "fragment" {
            s.mesh_fragment = true;
        } else if part == "centres" {
            s.mesh_texel_centres = true;
        } else if px.replace(part).is_some() {
            bail!("more than one LOD tolerance");
        }
    }
    let q = q.trim_start_matches("q=");
    let (q, outline) = match q.strip_suffix('o') {
        Some(q) => (q, true),
        None => (q, false),
    };
    s.mesh_quality = q
        .trim()
        .parse()
        .ok()
        .filter(|q: &f32| (0.0..=1.0).contains(q))
        .context("mesh quality must be a number in [0, 1]")?;
    s.mesh_outline = outline;
    if let Some(px) = px {
        s.mesh_lod_pixels = plain(positive(px.trim_start_matches("px=")))?;
    }
    Ok(())
}

/// `strata tune`'s sweep of the quality, also at the paper's picture size.
pub static SWEEP: Sweep = Sweep {
    order: 4,
    knob: "q",
    full: &["0", "0.25", "0.5", "0.75", "1"],
    quick: &["0", "0.5", "1"],
    at_paper_size: true,
};

#[cfg(test)]
mod tests {
    use super::{KNOBS, MethodSettings, parse};

    #[test]
    fn the_ab_knobs_parse_in_any_order() {
        for text in ["0.5/fragment/centres/2", "0.5/centres/2/fragment"] {
            let mut s = MethodSettings::default();
            parse(text, &mut s).unwrap();
            assert!(s.mesh_fragment && s.mesh_texel_centres, "{text}");
            assert_eq!(s.mesh_lod_pixels, 2.0);
            assert_eq!((KNOBS.describe)(&s), "q=0.5 lod=2px fragment texel-centres");
        }
        let mut s = MethodSettings::default();
        parse("0.5", &mut s).unwrap();
        assert!(!s.mesh_fragment && !s.mesh_texel_centres);
        assert!(parse("0.5/fragments", &mut s).is_err());
    }
}
