//! `compare --gameplay`: what a game pays per frame while it edits the
//! terrain all the time (issue 35). K small edits a frame (tracks, a few
//! craters, slabs carved and built, old edits undone) along the video's
//! default camera path, through every method's own update path; per method
//! the cost of the edits and of the frame, and whether the edited renderer
//! still matches a fresh build of the edited level at sampled frames.

use crate::stats::percentile;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use strata_markdown::{Align, Table, cell_text};

/// The workload as run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GameplayResults {
    /// Small edits (track stamps) a frame: K.
    pub edits_per_frame: u32,
    /// Frames of edits.
    pub frames: u32,
    /// A fresh build is compared every this many frames (and at the end).
    pub check_every: u32,
    /// The workload's seed: the same seed gives the same edits.
    pub seed: u64,
    /// Edits of every kind over the run (tracks, craters, slabs, undos).
    pub edits_total: u64,
    /// Texels the dirty rectangles covered, per frame (mean).
    pub dirty_texels_per_frame: f64,
    /// CPU ms a frame of editing the level itself costs (every method pays
    /// it once; not in the per-method numbers).
    pub level_edit_ms: Spread,
    /// The terrain collider (`strata_collide`) following the same edits.
    pub collider: Option<ColliderFollow>,
    /// One row per method.
    pub rows: Vec<GameplayRow>,
}

/// The 50th / 99th percentile and the largest of per-frame samples, ms.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    pub p50: f64,
    pub p99: f64,
    pub max: f64,
}

impl Spread {
    /// The spread of `samples` (`None` when there are none).
    pub fn of(samples: &[f64]) -> Option<Spread> {
        Some(Spread {
            p50: percentile(samples, 0.5)?,
            p99: percentile(samples, 0.99)?,
            max: samples
                .iter()
                .copied()
                .filter(|x| x.is_finite())
                .fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// The collider's refit (`TerrainCollider::apply_edit`) per frame of edits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColliderFollow {
    /// CPU ms of one frame's refit, one thread.
    pub refit_ms: Spread,
    /// Whether the followed collider equals one built fresh from the edited
    /// level at every check.
    pub consistent: bool,
}

/// One check of the edited renderer against a fresh build of the edited level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GameplayCheck {
    /// The workload frame after whose edits the check was made.
    pub frame: u32,
    /// Extra frames (no further edits) until the images agreed, as the
    /// single-crater protocol counts them: 0 = the frame itself agreed;
    /// `None` when not within 16.
    pub consistent_after_frames: Option<u32>,
    /// Percent of pixels where one image has terrain and the other sky (at
    /// the last check made).
    pub class_mismatch: f64,
    /// 95th percentile of |distance difference| where both hit, world units.
    pub depth_p95: f64,
    /// Percent of pixels that differ at all: terrain against sky, or
    /// distances more than 0.1 apart (the p95 misses small edits).
    pub differing_pixels: f64,
}

/// One method under the workload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GameplayRow {
    pub method: String,
    /// `Renderer::apply_edit` of a frame's edits: uploads and the method's
    /// own update (pyramid marks, mesh refit), CPU wall clock.
    pub edit_cpu_ms: Spread,
    /// GPU ms of the passes that bring derived data up to date (labels
    /// ending in `update`), part of the frame; `None` without timestamps.
    pub edit_gpu_ms: Option<Spread>,
    /// The frame after the edits: `apply_edit` + record + submit-and-wait,
    /// CPU wall clock.
    pub with_edits_cpu_ms: Spread,
    /// The same frame's GPU ms (its update passes included).
    pub with_edits_gpu_ms: Option<Spread>,
    /// The frame again at the same camera with no edit: the frame alone.
    pub alone_cpu_ms: Spread,
    pub alone_gpu_ms: Option<Spread>,
    /// Every check against a fresh build.
    pub checks: Vec<GameplayCheck>,
    /// Every check agreed within 16 frames.
    pub consistent: bool,
    /// Frames until a frame's edits are drawn in full, p50 / p99 / max: 0
    /// when the first frame after `apply_edit` shows them (`mesh` refits off
    /// the frame). Every frame drawn counts; batches a check settles are left
    /// out. `None` in results from before it was measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edit_lag_frames: Option<Spread>,
    /// Per-frame samples (ms), frame order: `apply_edit` CPU, the frame
    /// with edits (CPU wall; GPU where timed).
    pub edit_cpu_samples: Vec<f64>,
    pub with_edits_cpu_samples: Vec<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub with_edits_gpu_samples: Vec<f64>,
}

impl GameplayRow {
    /// p99 of the frame with edits over p99 of the frame alone (GPU where
    /// both are timed, else CPU): the "≤ 2x the frame alone".
    pub fn p99_ratio(&self) -> f64 {
        match (&self.with_edits_gpu_ms, &self.alone_gpu_ms) {
            (Some(w), Some(a)) => w.p99 / a.p99,
            _ => self.with_edits_cpu_ms.p99 / self.alone_cpu_ms.p99,
        }
    }
}

fn spread(s: &Spread) -> String {
    format!("{:.2} / {:.2} / {:.2}", s.p50, s.p99, s.max)
}

fn spread_opt(s: &Option<Spread>) -> String {
    s.as_ref().map_or("—".into(), spread)
}

fn checks_label(r: &GameplayRow) -> String {
    let late = r
        .checks
        .iter()
        .filter(|c| c.consistent_after_frames != Some(0))
        .count();
    match (r.consistent, late) {
        (true, 0) => format!("yes ({} checks)", r.checks.len()),
        (true, n) => format!("yes ({} checks, {n} after extra frames)", r.checks.len()),
        (false, _) => {
            let worst = r
                .checks
                .iter()
                .filter(|c| c.consistent_after_frames.is_none())
                .map(|c| {
                    format!(
                        "frame {}: {:.4} % / {:.2} / {:.3} % differ",
                        c.frame, c.class_mismatch, c.depth_p95, c.differing_pixels
                    )
                })
                .next()
                .unwrap_or_default();
            format!("**no** ({worst})")
        }
    }
}

/// Which methods draw a frame's edits late, and by how many frames.
fn lag_line(md: &mut String, rows: &[GameplayRow]) {
    let measured: Vec<(&str, &Spread)> = rows
        .iter()
        .filter_map(|r| Some((r.method.as_str(), r.edit_lag_frames.as_ref()?)))
        .collect();
    if measured.is_empty() {
        return;
    }
    let late: Vec<String> = measured
        .iter()
        .filter(|(_, s)| s.max > 0.0)
        .map(|(m, s)| format!("{m} {:.0} / {:.0} / {:.0}", s.p50, s.p99, s.max))
        .collect();
    if late.is_empty() {
        let _ = writeln!(
            md,
            "Every method draws a frame's edits in the next frame.\n"
        );
    } else {
        let _ = writeln!(
            md,
            "Frames until a frame's edits are drawn in full (p50 / p99 / max; 0: the next frame; \
             the others draw them in the next frame): {}.\n",
            late.join(", ")
        );
    }
}

/// The report's gameplay section (nothing when no run has one).
pub(crate) fn section(md: &mut String, runs: &[crate::RunResults]) {
    if runs.iter().all(|r| r.gameplay.is_none()) {
        return;
    }
    md.push_str("## Gameplay edits\n\n");
    for run in runs {
        let Some(g) = &run.gameplay else { continue };
        let _ = writeln!(
            md,
            "{}: {} small edits a frame for {} frames along the default camera path (seed {}; \
             tracks of radius 2–6, a crater, a slab carved or built and old edits undone now and \
             then: {} edits, {:.0} dirty texels a frame), checked against a fresh build every {} \
             frames and at the end. ms as p50 / p99 / max; edits: `apply_edit` (CPU) and the \
             update passes (GPU); edits + frame: `apply_edit` + the frame (CPU wall) and that \
             frame's GPU time; alone: the same camera again with no edit. Editing the level \
             itself: {} ms.\n",
            cell_text(&run.adapter.name),
            g.edits_per_frame,
            g.frames,
            g.seed,
            g.edits_total,
            g.dirty_texels_per_frame,
            g.check_every,
            spread(&g.level_edit_ms),
        );
        let mut t = Table::new()
            .left("method")
            .columns(
                [
                    "edits CPU",
                    "edits GPU",
                    "edits + frame CPU",
                    "edits + frame GPU",
                    "alone CPU",
                    "alone GPU",
                    "p99 ratio",
                ],
                Align::Right,
            )
            .left("matches fresh build");
        for r in &g.rows {
            t.row([
                r.method.clone(),
                spread(&r.edit_cpu_ms),
                spread_opt(&r.edit_gpu_ms),
                spread(&r.with_edits_cpu_ms),
                spread_opt(&r.with_edits_gpu_ms),
                spread(&r.alone_cpu_ms),
                spread_opt(&r.alone_gpu_ms),
                format!("{:.2}", r.p99_ratio()),
                checks_label(r),
            ]);
        }
        t.write_to(md);
        md.push('\n');
        lag_line(md, &g.rows);
        if let Some(c) = &g.collider {
            let _ = writeln!(
                md,
                "Collider (`strata_collide`, one thread) following the same edits: refit {} ms a \
                 frame; {}.\n",
                spread(&c.refit_ms),
                if c.consistent {
                    "equal to a fresh build at every check"
                } else {
                    "**differs from a fresh build**"
                }
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreads_and_ratio() {
        let xs: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = Spread::of(&xs).unwrap();
        assert_eq!((s.p50, s.p99, s.max), (50.0, 99.0, 100.0));
        assert!(Spread::of(&[]).is_none());
        let one = Spread {
            p50: 1.0,
            p99: 2.0,
            max: 3.0,
        };
        let row = GameplayRow {
            method: "m".into(),
            edit_cpu_ms: one,
            edit_gpu_ms: None,
            with_edits_cpu_ms: Spread { p99: 6.0, ..one },
            with_edits_gpu_ms: None,
            alone_cpu_ms: Spread { p99: 3.0, ..one },
            alone_gpu_ms: None,
            checks: vec![GameplayCheck {
                frame: 10,
                consistent_after_frames: Some(0),
                class_mismatch: 0.0,
                depth_p95: 0.0,
                differing_pixels: 0.0,
            }],
            consistent: true,
            edit_lag_frames: None,
            edit_cpu_samples: vec![],
            with_edits_cpu_samples: vec![],
            with_edits_gpu_samples: vec![],
        };
        assert_eq!(row.p99_ratio(), 2.0);
        assert_eq!(checks_label(&row), "yes (1 checks)");
    }
}
