//! Method settings from the command line: `name` takes the tuned default
//! (the paper's publication setting); `name:setting` overrides the one knob
//! that method has.

use crate::plan::MethodChoice;
use anyhow::{Context, bail};
use strata_render::MethodSettings;

/// The tuned settings of `choice`, with its override applied and `shadows` set.
pub fn settings_for(choice: &MethodChoice, shadows: bool) -> anyhow::Result<MethodSettings> {
    let mut s = MethodSettings {
        shadows,
        ..MethodSettings::default()
    };
    let Some(text) = choice.setting.as_deref() else {
        return Ok(s);
    };
    let name = choice.name.as_str();
    let ctx = || format!("method `{}`: setting `{text}`", choice.label());
    match name {
        "ray" | "ray-compute" => s.ray_steps = positive(text).with_context(ctx)?,
        "sliced" => {
            // `N` (the paper's plain slicer) or `N/refine`.
            let (n, refine) = match text.split_once('/') {
                Some((n, "refine")) => (n, true),
                Some((_, other)) => bail!("{}: `{other}` is not `refine`", ctx()),
                None => (text, false),
            };
            s.slices = positive(n).with_context(ctx)?;
            s.sliced_refine = refine;
        }
        "voxel" | "voxel-compute" => {
            // `X,Y,Z/STEPS`, `(X,Y,Z)/STEPS`, `X,Y,Z` or `/STEPS`.
            let (grid, steps) = match text.split_once('/') {
                Some((g, st)) => (g, Some(st)),
                None => (text, None),
            };
            let grid = grid.trim().trim_start_matches('(').trim_end_matches(')');
            if !grid.is_empty() {
                let v: Vec<u32> = grid
                    .split(',')
                    .map(positive)
                    .collect::<anyhow::Result<_>>()
                    .with_context(ctx)?;
                let [x, y, z] = v[..] else {
                    bail!("{}: the voxel grid needs three sizes X,Y,Z", ctx())
                };
                s.voxel_size = [x, y, z];
            }
            if let Some(st) = steps {
                s.voxel_steps = positive(st).with_context(ctx)?;
            }
        }
        "scattered" => {
            let v: Vec<f32> = text
                .split(',')
                .map(positive_f32)
                .collect::<anyhow::Result<_>>()
                .with_context(ctx)?;
            s.scatter_density = match v[..] {
                [d] => [d; 3],
                [x, y, z] => [x, y, z],
                _ => bail!("{}: scattered density is D or X,Y,Z", ctx()),
            };
        }
        "mesh" => {
            // `Q`, `q=Q`, `Qo` (outline-constrained), then `/PX` (the LOD
            // tolerance in pixels; `/`, as `,` separates methods) and
            // `/gradient` (the gradient-normal diagnostic), in either order.
            let mut parts = text.split('/');
            let q = parts.next().unwrap_or_default().trim();
            let mut px = None;
            for part in parts.map(str::trim) {
                if part == "gradient" {
                    s.mesh_gradient_normal = true;
                } else if px.replace(part).is_some() {
                    bail!("{}: more than one LOD tolerance", ctx());
                }
            }
            let q = q.trim_start_matches("q=");
            let (q, outline) = match q.strip_suffix('o') {
                Some(q) => (q, true),
                None => (q, false),
            };
            let q: f32 = q
                .trim()
                .parse()
                .ok()
                .filter(|q: &f32| (0.0..=1.0).contains(q))
                .with_context(|| format!("{}: mesh quality must be a number in [0, 1]", ctx()))?;
            s.mesh_quality = q;
            s.mesh_outline = outline;
            if let Some(px) = px {
                let px = px.trim_start_matches("px=");
                s.mesh_lod_pixels = positive_f32(px).with_context(ctx)?;
            }
        }
        _ => bail!("{}: `{name}` has no setting to change", ctx()),
    }
    Ok(s)
}

fn positive(text: &str) -> anyhow::Result<u32> {
    match text.trim().parse::<u32>() {
        Ok(v) if v > 0 => Ok(v),
        _ => bail!("`{}` is not a positive whole number", text.trim()),
    }
}

fn positive_f32(text: &str) -> anyhow::Result<f32> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => bail!("`{}` is not a positive number", text.trim()),
    }
}

/// The knob that matters for `name`, for the results' settings record.
pub fn describe(name: &str, s: &MethodSettings) -> String {
    match name {
        "ray" | "ray-compute" => format!("{name} steps={}", s.ray_steps),
        "voxel" | "voxel-compute" => {
            let [x, y, z] = s.voxel_size;
            format!("{name} grid=({x},{y},{z}) steps={}", s.voxel_steps)
        }
        "sliced" if s.sliced_refine => format!("{name} slices={} refined", s.slices),
        "sliced" => format!("{name} slices={}", s.slices),
        "scattered" => {
            let [x, y, z] = s.scatter_density;
            format!("{name} density={x},{y},{z}")
        }
        "mesh" => format!(
            "{name} q={}{} lod={}px{}",
            s.mesh_quality,
            if s.mesh_outline { " outline" } else { "" },
            s.mesh_lod_pixels,
            if s.mesh_gradient_normal {
                " gradient-normal"
            } else {
                ""
            }
        ),
        _ => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn choice(name: &str, setting: Option<&str>) -> MethodChoice {
        MethodChoice {
            name: name.into(),
            setting: setting.map(String::from),
        }
    }

    #[test]
    fn defaults_are_the_tuned_settings() {
        let s = settings_for(&choice("voxel", None), false).unwrap();
        assert_eq!(
            (s.voxel_size, s.voxel_steps, s.shadows),
            ([4, 8, 2], 100, false)
        );
        assert_eq!(
            describe("mesh", &settings_for(&choice("mesh", None), true).unwrap()),
            "mesh q=0.5 lod=1px"
        );
    }

    #[test]
    fn overrides_change_one_knob() {
        assert_eq!(
            settings_for(&choice("ray", Some("64")), true)
                .unwrap()
                .ray_steps,
            64
        );
        let v = settings_for(&choice("voxel-compute", Some("(2,2,1)/50")), true).unwrap();
        assert_eq!((v.voxel_size, v.voxel_steps), ([2, 2, 1], 50));
        assert_eq!(
            settings_for(&choice("voxel", Some("/7")), true)
                .unwrap()
                .voxel_size,
            [4, 8, 2]
        );
        assert_eq!(
            settings_for(&choice("scattered", Some("2")), true)
                .unwrap()
                .scatter_density,
            [2.0; 3]
        );
        assert_eq!(
            settings_for(&choice("mesh", Some("q=0.25")), true)
                .unwrap()
                .mesh_quality,
            0.25
        );
        let o = settings_for(&choice("mesh", Some("0.5o/2")), true).unwrap();
        assert_eq!(
            (o.mesh_quality, o.mesh_outline, o.mesh_lod_pixels),
            (0.5, true, 2.0)
        );
        assert_eq!(describe("mesh", &o), "mesh q=0.5 outline lod=2px");
        assert!(!o.mesh_gradient_normal);
        for text in ["0.5/gradient/2", "0.5/2/gradient"] {
            let g = settings_for(&choice("mesh", Some(text)), true).unwrap();
            assert_eq!((g.mesh_lod_pixels, g.mesh_gradient_normal), (2.0, true));
        }
        let g = settings_for(&choice("mesh", Some("0.25/gradient")), true).unwrap();
        assert_eq!(describe("mesh", &g), "mesh q=0.25 lod=1px gradient-normal");
        for bad in [
            "0.5x",
            "0.5o,2",
            "0.5/px=0",
            "0.5/-1",
            "1.5o",
            "0.5/1/2",
            "0.5/gradiant",
        ] {
            assert!(
                settings_for(&choice("mesh", Some(bad)), true).is_err(),
                "{bad}"
            );
        }
    }

    #[test]
    fn bad_settings_are_errors() {
        for (n, s) in [
            ("ray", "0"),
            ("ray", "x"),
            ("voxel", "1,2/3"),
            ("mesh", "2"),
            ("painted", "3"),
            ("scattered", "1,2"),
        ] {
            let err = settings_for(&choice(n, Some(s)), true);
            assert!(err.is_err(), "{n}:{s}");
        }
    }
}
