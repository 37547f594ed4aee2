//! Method settings from the command line: `name` takes the tuned default
//! (the paper's publication setting); `name:setting` overrides that method's
//! knobs, in the form its entry in `strata_render::methods::METHODS` reads.

use crate::plan::MethodChoice;
use anyhow::Context;
use strata_render::{MethodEntry, MethodSettings};

/// The tuned settings of `choice`, with its override applied and `shadows` set.
pub fn settings_for(choice: &MethodChoice, shadows: bool) -> anyhow::Result<MethodSettings> {
    let mut s = MethodSettings {
        shadows,
        ..MethodSettings::default()
    };
    if let Some(text) = choice.setting.as_deref() {
        choice
            .method
            .apply_setting(text, &mut s)
            .with_context(|| format!("method `{}`: setting `{text}`", choice.label()))?;
    }
    Ok(s)
}

/// The knobs that matter for `method`, for the results' settings record.
pub fn describe(method: &MethodEntry, s: &MethodSettings) -> String {
    method.describe(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn choice(name: &str, setting: Option<&str>) -> MethodChoice {
        MethodChoice {
            method: strata_render::methods::entry(name).unwrap(),
            setting: setting.map(String::from),
        }
    }

    fn describe(name: &str, s: &MethodSettings) -> String {
        super::describe(strata_render::methods::entry(name).unwrap(), s)
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
