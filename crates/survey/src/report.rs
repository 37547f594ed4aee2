//! `survey.md` and `survey.json`: the paper's table, the correlations, the
//! insertion causes against quality, and links to the plots.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use serde::Serialize;

use crate::correlate::pearson;
use crate::run::{FitRow, Survey, WorldRow};

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
    let _ = writeln!(
        md,
        "| world | texels | tris | red. | slab | dual | r_f | r_s | fit s |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut rows: Vec<&WorldRow> = survey.worlds.iter().collect();
    rows.sort_by(|a, b| {
        let red = |w: &WorldRow| w.fit_at(q).map_or(f64::INFINITY, |f| -f.reduction);
        red(a).total_cmp(&red(b))
    });
    for w in rows {
        match w.fit_at(q) {
            Some(f) => {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {:.1}× | {:.1} % | {:.1} % | {:.2} | {:.2} | {:.2} |",
                    w.label,
                    millions(w.texels),
                    millions(f.triangles),
                    f.reduction,
                    f.slab_share,
                    w.dual_percent,
                    w.r_f,
                    w.r_s,
                    f.fit_seconds
                );
            }
            None => {
                let _ = writeln!(
                    md,
                    "| {} | — | — | — | — | — | — | — | failed: {} |",
                    w.label,
                    w.error.as_deref().unwrap_or("no fit at this quality")
                );
            }
        }
    }
    let _ = writeln!(
        md,
        "\nslab: share of finest planar triangles that carry a slab; dual: texels in dual pairs; r_f, r_s: rough(floor), rough(surface) as `strata info` prints them.\n"
    );
    let _ = writeln!(md, "## Correlation of log reduction\n");
    let _ = writeln!(md, "| q | worlds | r_f | dual % | r_s | slab share |");
    let _ = writeln!(md, "|---:|---:|---:|---:|---:|---:|");
    for c in corr {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} |",
            c.quality,
            c.worlds,
            opt(c.r_f),
            opt(c.dual),
            opt(c.r_s),
            opt(c.slab_share)
        );
    }
    let _ = writeln!(
        md,
        "\nThe paper, ten shipped worlds: r_f −0.17, dual −0.77, r_s −0.82, slab share −0.89.\n"
    );
    let _ = writeln!(md, "## Insertion causes against quality (all worlds)\n");
    let _ = writeln!(
        md,
        "| q | max error | floor | slab interior | boundary | chunk border | boundary share |"
    );
    let _ = writeln!(md, "|---:|---:|---:|---:|---:|---:|---:|");
    for &(qq, causes) in &cause_totals(survey) {
        let total: u64 = causes.iter().sum();
        let _ = writeln!(
            md,
            "| {qq} | {} | {} | {} | {} | {} | {:.1} % |",
            strata_mesh::tolerance_for_quality(qq).unwrap_or(f64::NAN),
            causes[0],
            causes[1],
            causes[2],
            causes[3],
            100.0 * causes[2] as f64 / total.max(1) as f64
        );
    }
    let _ = writeln!(md, "\n### Boundary insertions per world\n");
    let mut head = String::from("| world |");
    let mut rule = String::from("|---|");
    for qq in &survey.qualities {
        let _ = write!(head, " q={qq} |");
        rule.push_str("---:|");
    }
    let _ = writeln!(md, "{head}\n{rule}");
    for w in &survey.worlds {
        let mut line = format!("| {} |", w.label);
        for &qq in &survey.qualities {
            match w.fit_at(qq) {
                Some(f) => {
                    let _ = write!(line, " {} |", f.causes[2]);
                }
                None => line.push_str(" — |"),
            }
        }
        let _ = writeln!(md, "{line}");
    }
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
