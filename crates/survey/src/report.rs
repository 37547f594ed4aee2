//! `survey.md` and `survey.json`: the paper's table, the correlations, the
//! insertion causes against quality, and links to the plots.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use serde::Serialize;

use crate::correlate::pearson;
use crate::run::{FitRow, Survey, WorldRow};
use strata_markdown::{Align, Table};

/// Correlations of log reduction against each predictor at one quality,
/// over the worlds that have a fit there.
#[derive(Clone, Debug, Serialize)]
pub struct Correlations {
    pub quality: f64,
    pub worlds: usize,
    pub r_f: Option<f64>,
    pub dual: Option<f64>,
    pub r_s: Option<f64>,
    pub slab_share: Option<f64>,
}

/// How to read one predictor from a world and its fit.
pub type Predictor = fn(&WorldRow, &FitRow) -> f64;

/// The predictors, in table order: name and how to read one.
pub const PREDICTORS: [(&str, Predictor); 4] = [
    ("r_f", |w, _| w.r_f),
    ("dual %", |w, _| w.dual_percent),
    ("r_s", |w, _| w.r_s),
    ("slab share %", |_, f| f.slab_share),
];

pub fn correlations(survey: &Survey) -> Vec<Correlations> {
    survey
        .qualities
        .iter()
        .map(|&q| {
            let fits: Vec<(&WorldRow, &FitRow)> = survey
                .worlds
                .iter()
                .filter_map(|w| w.fit_at(q).map(|f| (w, f)))
                .collect();
            let r = |k: usize| {
                let pairs: Vec<(f64, f64)> = fits
                    .iter()
                    .map(|(w, f)| (PREDICTORS[k].1(w, f), f.reduction.ln()))
                    .collect();
                pearson(&pairs)
            };
            Correlations {
                quality: q,
                worlds: fits.len(),
                r_f: r(0),
                dual: r(1),
                r_s: r(2),
                slab_share: r(3),
            }
        })
        .collect()
}

#[derive(Serialize)]
struct Json<'a> {
    command: &'a str,
    survey: &'a Survey,
    correlations: Vec<Correlations>,
}

/// Write `survey.json` and `survey.md` into `dir`; `figures` are the plot
/// files (relative to `dir`) to link.
pub fn write(
    dir: &Path,
    command: &str,
    survey: &Survey,
    figures: &[(String, String)],
) -> anyhow::Result<()> {
    let corr = correlations(survey);
    let json = serde_json::to_string_pretty(&Json {
        command,
        survey,
        correlations: corr.clone(),
    })?;
    let path = dir.join("survey.json");
    std::fs::write(&path, json).with_context(|| format!("writing {}", path.display()))?;
    let path = dir.join("survey.md");
    std::fs::write(&path, markdown(command, survey, &corr, figures))
        .with_context(|| format!("writing {}", path.display()))
}

fn opt(r: Option<f64>) -> String {
    r.map_or_else(|| "n/a".to_string(), |r| format!("{r:+.2}"))
}

fn millions(n: u64) -> String {
    format!("{:.2} M", n as f64 / 1e6)
}

pub fn markdown(
    command: &str,
    survey: &Survey,
    corr: &[Correlations],
    figures: &[(String, String)],
) -> String {
    let mut md = String::new();
    let q = survey.table_quality;
    let _ = writeln!(md, "# Fit survey\n");
    let _ = writeln!(
        md,
        "`{command}` — {} worlds × {} qualities, {} fit (max error 2^(4(1−q))), {:.0} s on {} threads.\n",
        survey.worlds.len(),
        survey.qualities.len(),
        if survey.outline {
            "outline-constrained"
        } else {
            "unconstrained"
        },
        survey.wall_seconds,
        survey.threads
    );
    let _ = writeln!(md, "## The table at q = {q}\n");
    let mut rows: Vec<&WorldRow> = survey.worlds.iter().collect();
    rows.sort_by(|a, b| {
        let red = |w: &WorldRow| w.fit_at(q).map_or(f64::INFINITY, |f| -f.reduction);
        red(a).total_cmp(&red(b))
    });
    let mut t = Table::new().left("world").columns(
        [
            "texels", "tris", "red.", "slab", "dual", "r_f", "r_s", "fit s",
        ],
        Align::Right,
    );
    for w in rows {
        match w.fit_at(q) {
            Some(f) => t.row([
                w.label.clone(),
                millions(w.texels),
                millions(f.triangles),
                format!("{:.1}×", f.reduction),
                format!("{:.1} %", f.slab_share),
                format!("{:.1} %", w.dual_percent),
                format!("{:.2}", w.r_f),
                format!("{:.2}", w.r_s),
                format!("{:.2}", f.fit_seconds),
            ]),
            None => {
                let why = w.error.as_deref().unwrap_or("no fit at this quality");
                t.row(
                    std::iter::once(w.label.clone())
                        .chain(std::iter::repeat_n("—".to_string(), 7))
                        .chain([format!("failed: {why}")]),
                );
            }
        }
    }
    t.write_to(&mut md);
    let _ = writeln!(
        md,
        "\nslab: share of finest planar triangles that carry a slab; dual: texels in dual pairs; r_f, r_s: rough(floor), rough(surface) as `strata info` prints them.\n"
    );
    let _ = writeln!(md, "## Correlation of log reduction\n");
    let mut t = Table::new().columns(
        ["q", "worlds", "r_f", "dual %", "r_s", "slab share"],
        Align::Right,
    );
    for c in corr {
        t.row([
            c.quality.to_string(),
            c.worlds.to_string(),
            opt(c.r_f),
            opt(c.dual),
            opt(c.r_s),
            opt(c.slab_share),
        ]);
    }
    t.write_to(&mut md);
    let _ = writeln!(
        md,
        "\nThe paper, ten shipped worlds: r_f −0.17, dual −0.77, r_s −0.82, slab share −0.89.\n"
    );
    let _ = writeln!(md, "## Insertion causes against quality (all worlds)\n");
    let mut t = Table::new().columns(
        [
            "q",
            "max error",
            "floor",
            "slab interior",
            "boundary",
            "chunk border",
            "boundary share",
        ],
        Align::Right,
    );
    for &(qq, causes) in &cause_totals(survey) {
        let total: u64 = causes.iter().sum();
        t.row([
            qq.to_string(),
            strata_mesh::tolerance_for_quality(qq)
                .unwrap_or(f64::NAN)
                .to_string(),
            causes[0].to_string(),
            causes[1].to_string(),
            causes[2].to_string(),
            causes[3].to_string(),
            format!("{:.1} %", 100.0 * causes[2] as f64 / total.max(1) as f64),
        ]);
    }
    t.write_to(&mut md);
    let _ = writeln!(md, "\n### Boundary insertions per world\n");
    let qualities = survey.qualities.iter().map(|qq| format!("q={qq}"));
    let mut t = Table::new().left("world").columns(qualities, Align::Right);
    for w in &survey.worlds {
        let cells = survey.qualities.iter().map(|&qq| {
            w.fit_at(qq)
                .map_or("—".to_string(), |f| f.causes[2].to_string())
        });
        t.row(std::iter::once(w.label.clone()).chain(cells));
    }
    t.write_to(&mut md);
    if !figures.is_empty() {
        let _ = writeln!(md, "\n## Plots\n");
        for (title, file) in figures {
            let _ = writeln!(md, "![{title}]({file})\n");
        }
    }
    let failed: Vec<&WorldRow> = survey.worlds.iter().filter(|w| w.error.is_some()).collect();
    if !failed.is_empty() {
        let _ = writeln!(md, "## Failed\n");
        for w in failed {
            let _ = writeln!(md, "- {}: {}", w.label, w.error.as_deref().unwrap_or(""));
        }
    }
    md
}

/// Per quality, the insertion causes summed over the worlds.
pub fn cause_totals(survey: &Survey) -> Vec<(f64, [u64; strata_mesh::CAUSES])> {
    survey
        .qualities
        .iter()
        .map(|&q| {
            let mut sum = [0u64; strata_mesh::CAUSES];
            for f in survey.worlds.iter().filter_map(|w| w.fit_at(q)) {
                for (s, c) in sum.iter_mut().zip(f.causes) {
                    *s += c;
                }
            }
            (q, sum)
        })
        .collect()
}
