//! The survey's figures, SVG: reduction against each predictor (log scale,
//! one panel per predictor) and the insertion causes against quality.

use std::path::Path;

use anyhow::{Context, anyhow};
use plotters::prelude::*;

use crate::report::{PREDICTORS, cause_totals};
use crate::run::Survey;

fn plot_error<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing a plot: {e:?}")
}

/// Draw both figures into `dir`; returns (title, file name) of each.
pub fn write_all(dir: &Path, survey: &Survey) -> anyhow::Result<Vec<(String, String)>> {
    let mut out = Vec::new();
    let file = "survey-reduction.svg";
    reduction(&dir.join(file), survey)
        .with_context(|| format!("plotting {}", dir.join(file).display()))?;
    out.push((
        format!(
            "Reduction against each predictor at q = {}",
            survey.table_quality
        ),
        file.to_string(),
    ));
    let file = "survey-causes.svg";
    causes(&dir.join(file), survey)
        .with_context(|| format!("plotting {}", dir.join(file).display()))?;
    out.push((
        "Insertion causes against quality (all worlds)".to_string(),
        file.to_string(),
    ));
    Ok(out)
}

fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if lo > hi {
        (0.0, 1.0)
    } else if hi - lo < 1e-9 {
        (lo - 0.5, hi + 0.5)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

fn reduction(path: &Path, survey: &Survey) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let q = survey.table_quality;
    let fits: Vec<_> = survey
        .worlds
        .iter()
        .filter_map(|w| w.fit_at(q).map(|f| (w, f)))
        .collect();
    let (rlo, rhi) = span(fits.iter().map(|(_, f)| f.reduction));
    let (rlo, rhi) = (rlo.max(1.0) * 0.9, rhi.max(1.0) * 1.1);
    for (panel, (name, get)) in root.split_evenly((2, 2)).iter().zip(PREDICTORS) {
        let points: Vec<(f64, f64)> = fits.iter().map(|(w, f)| (get(w, f), f.reduction)).collect();
        let (xlo, xhi) = span(points.iter().map(|p| p.0));
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("reduction vs {name}"), ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(44)
            .build_cartesian_2d(xlo..xhi, (rlo..rhi).log_scale())
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc(name)
            .y_desc("reduction (x)")
            .draw()
            .map_err(plot_error)?;
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 4, BLUE.filled())))
            .map_err(plot_error)?;
    }
    root.present().map_err(plot_error)
}

fn causes(path: &Path, survey: &Survey) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (720, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let totals = cause_totals(survey);
    let hi = totals
        .iter()
        .flat_map(|(_, c)| c.iter().copied())
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "insertions by cause against quality (all worlds)",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.02f64..1.02, (1.0..hi * 2.0).log_scale())
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("quality q (max error 2^(4(1-q)))")
        .y_desc("insertions")
        .draw()
        .map_err(plot_error)?;
    let names = [
        "floor",
        "slab interior",
        "single/double boundary",
        "chunk border",
    ];
    let colours = [GREEN, BLUE, RED, BLACK];
    for (k, (name, colour)) in names.iter().zip(colours).enumerate() {
        let points: Vec<(f64, f64)> = totals
            .iter()
            .map(|(q, c)| (*q, (c[k] as f64).max(1.0)))
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
            .map_err(plot_error)?
            .label(*name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(
                points
                    .into_iter()
                    .map(|p| Circle::new(p, 3, colour.filled())),
            )
            .map_err(plot_error)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error)?;
    root.present().map_err(plot_error)
}
