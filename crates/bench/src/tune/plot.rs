//! Cost versus combined error per method (SVG and PNG, plotters): every
//! point of the sweep, the chosen one ringed, the one-point band shaded.

use super::MethodTuning;
use crate::figures::ImageBackend;
use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const SIZE: (u32, u32) = (640, 400);

/// `tune-<method>-<W>x<H>`.
pub fn file_stem(m: &MethodTuning) -> String {
    format!("tune-{}-{}x{}", m.method, m.size[0], m.size[1])
}

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing a tuning plot: {e:?}")
}

fn draw<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, m: &MethodTuning) -> anyhow::Result<()> {
    area.fill(&WHITE).map_err(err)?;
    let pts: Vec<(f64, f64, String)> = m
        .points
        .iter()
        .filter(|p| p.cost_ms.is_finite() && p.combined.is_finite())
        .map(|p| {
            (
                p.cost_ms.max(1e-3),
                p.combined,
                p.setting.clone().unwrap_or_default(),
            )
        })
        .collect();
    let (x0, x1) = pts
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let y1 = pts.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let (x0, x1) = if x0 <= x1 {
        (x0 / 1.5, x1 * 1.5)
    } else {
        (0.1, 10.0)
    };
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "{} {}x{}: cost vs combined error",
                m.method, m.size[0], m.size[1]
            ),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(32)
        .y_label_area_size(48)
        .build_cartesian_2d((x0..x1).log_scale(), 0.0..(y1 * 1.2).max(1.0))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("frame ms (log)")
        .y_desc("combined error %")
        .draw()
        .map_err(err)?;
    if let Some(b) = m.best {
        let best = m.points[b].combined;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x0, best), (x1, best + super::rule::TOLERANCE_POINTS)],
                RGBColor(200, 230, 200).filled(),
            )))
            .map_err(err)?;
    }
    chart
        .draw_series(LineSeries::new(
            pts.iter().map(|p| (p.0, p.1)),
            BLUE.stroke_width(1),
        ))
        .map_err(err)?;
    chart
        .draw_series(
            pts.iter()
                .map(|p| Circle::new((p.0, p.1), 4, BLUE.filled())),
        )
        .map_err(err)?;
    chart
        .draw_series(
            pts.iter()
                .map(|p| Text::new(p.2.clone(), (p.0, p.1), ("sans-serif", 12).into_font())),
        )
        .map_err(err)?;
    if let Some(c) = m.chosen {
        let p = &m.points[c];
        chart
            .draw_series(std::iter::once(Circle::new(
                (p.cost_ms.max(1e-3), p.combined),
                9,
                RED.stroke_width(2),
            )))
            .map_err(err)?;
    }
    area.present().map_err(err)
}

/// Write the plot as PNG and SVG into `dir`; returns their file names.
pub fn write(m: &MethodTuning, dir: &Path) -> anyhow::Result<(String, String)> {
    let stem = file_stem(m);
    let (png, svg) = (format!("{stem}.png"), format!("{stem}.svg"));
    draw(
        &SVGBackend::new(&dir.join(&svg), SIZE).into_drawing_area(),
        m,
    )
    .with_context(|| format!("writing {svg}"))?;
    draw(
        &ImageBackend::new(SIZE, &dir.join(&png)).into_drawing_area(),
        m,
    )
    .with_context(|| format!("writing {png}"))?;
    Ok((png, svg))
}
