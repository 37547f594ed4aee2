//! What `strata tune` writes: `tuning.md` (a table per method, the chosen row
//! bold, the paper's setting beside ours), `tuning.json` ([`Tuning`]), the
//! plots, and `settings.json` ([`TunedSettings`]) for `compare --settings`.

use super::{MethodTuning, Tuning};
use crate::plan::MethodChoice;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use strata_markdown::{Align, Table};

/// `settings.json`: the chosen setting per method, in `--methods name:setting`
/// syntax (`"ray": "64"`). Methods without a knob are absent.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TunedSettings {
    /// Level, adapter and size the settings were tuned on.
    pub tuned_on: String,
    pub methods: BTreeMap<String, String>,
}

impl TunedSettings {
    /// The rule's choices; the mesh takes its largest-size pass (the paper
    /// tunes it at 1280x800), and the compute twins their method's setting.
    pub fn from_tuning(t: &Tuning) -> Self {
        let mut methods = BTreeMap::new();
        let mut mesh_area = 0u64;
        for m in &t.methods {
            let Some(setting) = m.chosen_setting() else {
                continue;
            };
            let area = u64::from(m.size[0]) * u64::from(m.size[1]);
            if m.method == "mesh" {
                if area < mesh_area {
                    continue;
                }
                mesh_area = area;
            }
            methods.insert(m.method.clone(), setting.to_string());
            // The methods that share the tuned one's knobs and are not swept.
            if let Ok(tuned) = strata_render::methods::entry(&m.method) {
                for twin in strata_render::methods::METHODS.iter().filter(|e| {
                    e.tune.is_none() && e.name != tuned.name && std::ptr::eq(e.knobs, tuned.knobs)
                }) {
                    methods.insert(twin.name.to_string(), setting.to_string());
                }
            }
        }
        let size = t
            .methods
            .first()
            .map_or(String::new(), |m| format!("{}x{}", m.size[0], m.size[1]));
        TunedSettings {
            tuned_on: format!("{} on {} at {size}", t.level, t.adapter),
            methods,
        }
    }

    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading settings file {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| {
            format!(
                "settings file {}: not a `strata tune` settings.json ({{\"methods\": {{\"ray\": \"64\", …}}}})",
                path.display()
            )
        })
    }

    /// Give every method chosen without an explicit setting its tuned one.
    pub fn apply(&self, methods: &mut [MethodChoice]) {
        for m in methods {
            if m.setting.is_none() {
                m.setting = self.methods.get(m.method.name).cloned();
            }
        }
    }
}

/// Write `tuning.md`, `tuning.json`, `settings.json` and the plots into `dir`.
/// Returns the paths of `tuning.md` and `settings.json`.
pub fn write(t: &Tuning, dir: &Path) -> anyhow::Result<(PathBuf, PathBuf)> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let write = |name: &str, text: String| -> anyhow::Result<PathBuf> {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    };
    write("tuning.json", serde_json::to_string_pretty(t)?)?;
    let settings = TunedSettings::from_tuning(t);
    let settings_path = write("settings.json", serde_json::to_string_pretty(&settings)?)?;
    let mut plots = Vec::new();
    for m in &t.methods {
        if m.points.len() > 1 {
            plots.push(super::plot::write(m, dir)?);
        }
    }
    let md = markdown(t, &plots);
    let md_path = write("tuning.md", md)?;
    Ok((md_path, settings_path))
}

fn fmt(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "—".into()
    }
}

fn title(m: &MethodTuning) -> String {
    format!("{} at {}x{}", m.method, m.size[0], m.size[1])
}

/// `tuning.md`.
pub fn markdown(t: &Tuning, plots: &[(String, String)]) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Tuning: {}\n", t.level);
    let views: Vec<String> = t
        .views
        .iter()
        .map(|v| format!("`{}` ({}°)", v.name, v.pitch))
        .collect();
    let _ = writeln!(
        md,
        "Adapter {} ({}), cost = mean frame ms ({}), {} timed frame(s) per view, shadows {}. \
         Views: {}. Combined error = see-through + covers-sky + coherence (% of pixels, mean over \
         the views). The chosen setting (**bold**) is the cheapest within {} percentage point of \
         the method's best combined error{}. {:.0} s.\n",
        t.adapter,
        t.backend,
        t.timing_source,
        t.frames,
        if t.shadows { "on" } else { "off" },
        views.join(", "),
        t.tolerance_points,
        if t.quick {
            " (`--quick`: fewer points)"
        } else {
            ""
        },
        t.seconds
    );
    md.push_str("## Chosen settings\n\n");
    let mut chosen = Table::new()
        .columns(["method", "size", "ours", "paper"], Align::Left)
        .columns(
            [
                "combined % (ours)",
                "combined % (paper)",
                "ms (ours)",
                "ms (paper)",
            ],
            Align::Right,
        );
    for m in &t.methods {
        let ours = m.chosen.map(|i| &m.points[i]);
        let paper = m
            .paper_setting
            .as_ref()
            .and_then(|p| m.points.iter().find(|q| q.setting.as_deref() == Some(p)));
        chosen.row([
            m.method.clone(),
            format!("{}x{}", m.size[0], m.size[1]),
            ours.map_or("—".into(), |p| p.label.clone()),
            m.paper_setting
                .clone()
                .unwrap_or_else(|| "(no knob)".into()),
            ours.map_or("—".into(), |p| fmt(p.combined, 2)),
            paper.map_or("—".into(), |p| fmt(p.combined, 2)),
            ours.map_or("—".into(), |p| fmt(p.cost_ms, 3)),
            paper.map_or("—".into(), |p| fmt(p.cost_ms, 3)),
        ]);
    }
    let _ = writeln!(md, "{chosen}");
    for m in &t.methods {
        let _ = writeln!(md, "## {} ({})\n", title(m), m.knob);
        let mut sweep = Table::new()
            .left("setting")
            .columns(
                [
                    "see-through %",
                    "covers-sky %",
                    "coherence %",
                    "combined %",
                    "ms",
                ],
                Align::Right,
            )
            .left("");
        for (i, p) in m.points.iter().enumerate() {
            let bold = |s: String| {
                if m.chosen == Some(i) {
                    format!("**{s}**")
                } else {
                    s
                }
            };
            let mut notes = Vec::new();
            if m.chosen == Some(i) {
                notes.push("chosen");
            }
            if m.best == Some(i) {
                notes.push("best");
            }
            if p.setting.is_some() && p.setting == m.paper_setting {
                notes.push("paper");
            }
            sweep.row([
                bold(p.label.clone()),
                bold(fmt(p.see_through, 2)),
                bold(fmt(p.covers_sky, 2)),
                bold(fmt(p.coherence, 2)),
                bold(fmt(p.combined, 2)),
                bold(fmt(p.cost_ms, 3)),
                format!(
                    "{}{}",
                    notes.join(", "),
                    p.error
                        .as_ref()
                        .map_or(String::new(), |e| format!(" failed: {e}"))
                ),
            ]);
        }
        let _ = write!(md, "{sweep}");
        if let Some((png, svg)) = plots
            .iter()
            .find(|(png, _)| png.contains(&super::plot::file_stem(m)))
        {
            let _ = writeln!(md, "\n![{}]({png}) ([svg]({svg}))", title(m));
        }
        md.push('\n');
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tune::{MethodTuning, TunePoint};

    fn point(setting: &str, combined: f64, cost: f64) -> TunePoint {
        TunePoint {
            setting: Some(setting.into()),
            label: setting.into(),
            see_through: combined,
            covers_sky: 0.0,
            coherence: 0.0,
            combined,
            cost_ms: cost,
            error: None,
        }
    }

    fn tuning(size: [u32; 2], method: &str, chosen: usize, points: Vec<TunePoint>) -> MethodTuning {
        MethodTuning {
            method: method.into(),
            knob: "k".into(),
            size,
            points,
            chosen: Some(chosen),
            best: Some(0),
            paper_setting: Some("128".into()),
        }
    }

    #[test]
    fn settings_take_the_choices_and_the_largest_mesh_pass() {
        let t = Tuning {
            level: "w".into(),
            level_hash: "h".into(),
            adapter: "a".into(),
            backend: "vulkan".into(),
            timing_source: "gpu-timestamps".into(),
            views: Vec::new(),
            quick: false,
            frames: 1,
            shadows: true,
            tolerance_points: 1.0,
            methods: vec![
                tuning(
                    [400, 260],
                    "ray",
                    1,
                    vec![point("128", 1.0, 5.0), point("64", 1.5, 3.0)],
                ),
                tuning([400, 260], "mesh", 0, vec![point("0.25", 1.0, 1.0)]),
                tuning([1280, 800], "mesh", 0, vec![point("0.75", 1.0, 1.0)]),
            ],
            seconds: 1.0,
        };
        let s = TunedSettings::from_tuning(&t);
        assert_eq!(s.methods["ray"], "64");
        assert_eq!(s.methods["ray-compute"], "64");
        assert_eq!(s.methods["mesh"], "0.75");
        // Applied only where the command line named no setting.
        let mut choices = vec![
            MethodChoice {
                method: strata_render::methods::entry("ray").unwrap(),
                setting: None,
            },
            MethodChoice {
                method: strata_render::methods::entry("mesh").unwrap(),
                setting: Some("0.5".into()),
            },
            MethodChoice {
                method: strata_render::methods::entry("painted").unwrap(),
                setting: None,
            },
        ];
        s.apply(&mut choices);
        assert_eq!(choices[0].setting.as_deref(), Some("64"));
        assert_eq!(choices[1].setting.as_deref(), Some("0.5"));
        assert_eq!(choices[2].setting, None);
        // The chosen row is bold, the paper's marked.
        let md = markdown(&t, &[]);
        assert!(md.contains("| **64** |"), "{md}");
        assert!(md.contains("paper"));
        // A file that is not a settings.json is a clear error naming it.
        let dir = std::env::temp_dir().join(format!("strata-tune-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.json");
        std::fs::write(&bad, "[1, 2]").unwrap();
        let e = TunedSettings::read(&bad).unwrap_err();
        assert!(format!("{e:#}").contains("bad.json"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
