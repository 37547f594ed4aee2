//! The paper's figures for `report.md`, drawn with plotters as SVG and PNG:
//! frame time by pitch (one line per method, per adapter when merged),
//! preparation costs, retained memory, and the edit figure (the edit
//! camera before the crater and on the first post-edit frame for one
//! method of each update class).
//!
//! The PNGs go through [`ImageBackend`], which writes text with the grid's
//! bitmap font: plotters' own PNG text needs a system font (fontconfig and
//! FreeType), which a fresh CI machine does not have.

use crate::report::{self, Pictures};
use crate::results::{Row, RunResults};
use crate::{font, grid, stats};
use anyhow::Context;
use image::{Rgba, RgbaImage};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters_backend::text_anchor::{HPos, Pos, VPos};
use plotters_backend::{BackendColor, BackendCoord, BackendTextStyle, DrawingErrorKind};
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (720, 420);

pub use crate::report::Figure;

/// `pictures` with the figures of `runs` drawn into `dir` (a failure costs
/// the figures, with a warning, never the report).
pub fn with_figures(mut pictures: Pictures, runs: &[RunResults], dir: &Path) -> Pictures {
    match write_all(runs, dir) {
        Ok(f) => pictures.figures = f,
        Err(e) => eprintln!("warning: figures not drawn: {e:#}"),
    }
    if let Some(base) = runs.first() {
        match edit_figure(base, dir) {
            Ok(f) => pictures.edit_figure = f,
            Err(e) => eprintln!("warning: edit figure not drawn: {e:#}"),
        }
    }
    pictures
}

/// Draw every figure the runs support into `dir/figures/`.
pub fn write_all(runs: &[RunResults], dir: &Path) -> anyhow::Result<Vec<Figure>> {
    let Some(base) = runs.first() else {
        return Ok(Vec::new());
    };
    let fig_dir = dir.join("figures");
    std::fs::create_dir_all(&fig_dir).with_context(|| format!("creating {}", fig_dir.display()))?;
    let mut out = Vec::new();
    if runs.iter().any(|r| !r.rows.is_empty()) {
        out.push(plot(
            &fig_dir,
            "frame-time-by-pitch",
            "Frame time by pitch (ms, log scale)",
            Chart::FrameTime(runs),
        )?);
    }
    if !base.rows.is_empty() {
        out.push(plot(
            &fig_dir,
            "preparation",
            "Preparation costs (ms, log scale): setup, first frame, warm-up",
            Chart::Preparation(base),
        )?);
        out.push(plot(
            &fig_dir,
            "memory",
            "Retained memory (MiB): GPU, CPU",
            Chart::Memory(base),
        )?);
    }
    Ok(out)
}

/// The charts: one generic `draw` serves both backends.
enum Chart<'a> {
    FrameTime(&'a [RunResults]),
    Preparation(&'a RunResults),
    Memory(&'a RunResults),
    /// Lines over world size (texels, log scale): caption, y axis, series.
    BySize(&'a str, &'a str, &'a [(String, Vec<(f64, f64)>)]),
}

/// `strata fly --scale`'s figure `name` (`.svg` and `.png` in `dir`): each
/// series a line of (world texels, value), x on a log scale.
pub fn by_world_size(
    dir: &Path,
    name: &str,
    caption: &str,
    y_desc: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> anyhow::Result<Figure> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    plot(dir, name, caption, Chart::BySize(caption, y_desc, series))
}

fn by_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> anyhow::Result<()> {
    let labels: Vec<String> = series.iter().map(|(l, _)| l.clone()).collect();
    let area = with_legend(area, &labels, Swatch::Line)?;
    let points = || series.iter().flat_map(|(_, s)| s.iter().copied());
    let (x_lo, x_hi) = points().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let y_hi = points().fold(0.0f64, |m, p| m.max(p.1));
    let (x_lo, x_hi) = if x_lo < x_hi {
        (x_lo / 2.0, x_hi * 2.0)
    } else {
        (1.0, 10.0)
    };
    let mut chart = ChartBuilder::on(&area)
        .caption(caption, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), 0.0..(y_hi * 1.15).max(1e-3))
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("world texels")
        .y_desc(y_desc)
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| tick(*y))
        .draw()
        .map_err(plot_error)?;
    for (i, (_, line)) in series.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(line.clone(), c.stroke_width(2)))
            .map_err(plot_error)?;
        chart
            .draw_series(line.iter().map(|p| Circle::new(*p, 3, c.filled())))
            .map_err(plot_error)?;
    }
    Ok(())
}

impl Chart<'_> {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> anyhow::Result<()> {
        area.fill(&WHITE).map_err(plot_error)?;
        match self {
            Chart::FrameTime(runs) => frame_time_by_pitch(area, runs)?,
            Chart::Preparation(run) => preparation(area, run)?,
            Chart::Memory(run) => memory(area, run)?,
            Chart::BySize(caption, y_desc, series) => by_size(area, caption, y_desc, series)?,
        }
        area.present().map_err(plot_error)
    }
}

/// Draw one chart as SVG and PNG.
fn plot(dir: &Path, name: &str, title: &str, chart: Chart<'_>) -> anyhow::Result<Figure> {
    let svg_path = dir.join(format!("{name}.svg"));
    chart.draw(&SVGBackend::new(&svg_path, SIZE).into_drawing_area())?;
    let png_path = dir.join(format!("{name}.png"));
    chart.draw(&ImageBackend::new(SIZE, &png_path).into_drawing_area())?;
    Ok(Figure {
        title: title.to_string(),
        png: format!("figures/{name}.png"),
        svg: format!("figures/{name}.svg"),
    })
}

fn plot_error<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow::anyhow!("drawing a figure: {e:?}")
}

fn colour(i: usize) -> RGBColor {
    let c = Palette99::pick(i).to_rgba();
    RGBColor(c.0, c.1, c.2)
}

/// Mean frame time of `method` at each pitch of `run`.
fn pitch_series(run: &RunResults, method: &str) -> Vec<(f64, f64)> {
    report::pitches(run)
        .into_iter()
        .filter_map(|p| {
            let xs: Vec<f64> = run
                .rows
                .iter()
                .filter(|r| r.method == method && r.pitch == p)
                .map(Row::frame_ms)
                .collect();
            stats::mean(&xs).map(|m| (f64::from(p), m.max(1e-3)))
        })
        .collect()
}

fn frame_time_by_pitch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    runs: &[RunResults],
) -> anyhow::Result<()> {
    let mut series = Vec::new();
    for run in runs {
        for m in &run.settings.methods {
            let label = if runs.len() > 1 {
                format!("{m} ({})", run.adapter.name)
            } else {
                m.clone()
            };
            series.push((label, pitch_series(run, m)));
        }
    }
    let labels: Vec<String> = series.iter().map(|(l, _)| l.clone()).collect();
    let area = with_legend(area, &labels, Swatch::Line)?;
    let ys = series.iter().flat_map(|(_, s)| s.iter().map(|p| p.1));
    let (lo, hi) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
    // Out to the powers of ten around the lines, so both ends are labelled.
    let (lo, hi) = if lo <= hi {
        (
            10f64.powf((lo / 1.2).log10().floor()),
            10f64.powf((hi * 1.2).log10().ceil()),
        )
    } else {
        (0.1, 10.0)
    };
    let mut chart = ChartBuilder::on(&area)
        .caption("frame time by pitch (ms)", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(50)
        .build_cartesian_2d(-95.0f64..5.0f64, (lo..hi).log_scale())
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("pitch (degrees)")
        .x_labels(5)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| tick(*y))
        .draw()
        .map_err(plot_error)?;
    for (i, (_, points)) in series.into_iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(points.clone(), c.stroke_width(2)))
            .map_err(plot_error)?;
        chart
            .draw_series(points.into_iter().map(|p| Circle::new(p, 3, c.filled())))
            .map_err(plot_error)?;
    }
    Ok(())
}

/// Width of the area left of a bar chart for the axis's labels.
const Y_LABEL_AREA: u32 = 60;

/// Height of the area under a chart for the axis's labels and title (two
/// lines of the bitmap font and their gaps).
const X_LABEL_AREA: u32 = 44;

/// An axis value without a needless `.0`: `100`, `2.5`, `0.25`.
fn tick(v: f64) -> String {
    if v >= 10.0 || v == v.round() {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// What a legend entry shows beside its label.
#[derive(Clone, Copy)]
enum Swatch {
    Line,
    Block,
}

/// Legend text, in the SVG; the PNG writes the bitmap font whatever the size.
const LEGEND_FONT: f64 = 15.0;
/// Legend rows start below the caption.
const LEGEND_TOP: i32 = 44;
/// Room left of a legend label for its swatch.
const SWATCH_WIDTH: u32 = 26;

/// Draw a legend (colour `i` for label `i`) in a panel at the right of
/// `area`, as wide as its longest label (at most 45 % of the figure), and
/// return the rest of the area for the chart: the legend never covers it.
fn with_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labels: &[String],
    swatch: Swatch,
) -> anyhow::Result<DrawingArea<DB, Shift>> {
    let (w, h) = area.dim_in_pixel();
    let longest = labels
        .iter()
        .map(|l| font::text_width(l))
        .max()
        .unwrap_or(0);
    let panel = (longest + SWATCH_WIDTH + 12).min(w * 45 / 100);
    let (chart, side) = area.split_horizontally(w - panel);
    let n = labels.len().max(1) as i32;
    let step = ((h as i32 - LEGEND_TOP - 10) / n).clamp(font::LINE as i32, 20);
    let style = ("sans-serif", LEGEND_FONT)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let room = panel.saturating_sub(SWATCH_WIDTH + 4);
    for (i, label) in labels.iter().enumerate() {
        let c = colour(i);
        let y = LEGEND_TOP + step * i as i32;
        match swatch {
            Swatch::Line => side.draw(&PathElement::new(vec![(2, y), (20, y)], c.stroke_width(2))),
            Swatch::Block => side.draw(&Rectangle::new([(6, y - 5), (16, y + 5)], c.filled())),
        }
        .map_err(plot_error)?;
        side.draw(&Text::new(
            shortened(label, room),
            (SWATCH_WIDTH as i32, y),
            style.clone(),
        ))
        .map_err(plot_error)?;
    }
    Ok(chart)
}

/// `text` cut to `width` pixels of the bitmap font, `..` marking a cut.
fn shortened(text: &str, width: u32) -> String {
    if font::text_width(text) <= width {
        return text.to_string();
    }
    let keep = (width / font::ADVANCE).saturating_sub(2) as usize;
    format!("{}..", text.chars().take(keep).collect::<String>())
}

/// Grouped bars: one group per method, one bar per value; the methods
/// are named under their groups (on staggered lines where one line would
/// run them together).
fn bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    methods: &[String],
    values: &[Vec<f64>],
    names: &[&str],
    log: bool,
) -> anyhow::Result<()> {
    let labels: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    let area = with_legend(area, &labels, Swatch::Block)?;
    // Lines the group names need: one, unless the widest name is wider
    // than the groups are apart (the chart's width less the y labels and
    // margins, over the groups).
    let pitch =
        area.dim_in_pixel().0.saturating_sub(Y_LABEL_AREA + 20) / methods.len().max(1) as u32;
    let widest = methods
        .iter()
        .map(|m| font::text_width(m))
        .max()
        .unwrap_or(0);
    let lines = (widest + font::ADVANCE).div_ceil(pitch.max(1)).clamp(1, 4);
    let k = names.len().max(1) as f64;
    let top = values
        .iter()
        .flatten()
        .copied()
        .fold(0.0f64, f64::max)
        .max(1e-3);
    let hi = if log { top * 2.0 } else { top * 1.1 };
    let lo = values
        .iter()
        .flatten()
        .copied()
        .filter(|v| *v > 0.0)
        .fold(f64::MAX, f64::min)
        .min(hi)
        / 2.0;
    // Group i is centred on x = i.
    let n = methods.len() as f64 - 0.5;
    macro_rules! draw_bars {
        ($chart:expr, $floor:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .disable_x_mesh()
                .x_labels(0)
                .y_label_formatter(&|y| tick(*y))
                .draw()
                .map_err(plot_error)?;
            for (j, _) in names.iter().enumerate() {
                let c = colour(j);
                let rects = values.iter().enumerate().map(|(i, v)| {
                    let x0 = i as f64 - 0.4 + 0.8 * j as f64 / k;
                    let y = v.get(j).copied().unwrap_or(0.0).max($floor);
                    Rectangle::new([(x0, $floor), (x0 + 0.8 / k, y)], c.filled())
                });
                chart.draw_series(rects).map_err(plot_error)?;
            }
            let at: Vec<BackendCoord> = (0..methods.len())
                .map(|i| chart.backend_coord(&(i as f64, $floor)))
                .collect();
            group_labels(&area, methods, &at, lines)?;
        }};
    }
    let builder = |area| {
        let mut b = ChartBuilder::on(area);
        b.caption(caption, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(8 + lines * (font::LINE + 4))
            .y_label_area_size(Y_LABEL_AREA);
        b
    };
    if log {
        let chart = builder(&area)
            .build_cartesian_2d(-0.5..n, (lo.max(1e-3)..hi).log_scale())
            .map_err(plot_error)?;
        draw_bars!(chart, lo.max(1e-3));
    } else {
        let chart = builder(&area)
            .build_cartesian_2d(-0.5..n, 0.0..hi)
            .map_err(plot_error)?;
        draw_bars!(chart, 0.0);
    }
    Ok(())
}

/// Name each group under the axis at `at` (the groups' centres on the
/// axis, backend pixels), group `i` on line `i % lines`.
fn group_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    methods: &[String],
    at: &[BackendCoord],
    lines: u32,
) -> anyhow::Result<()> {
    let style = ("sans-serif", 12.0)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    for (i, (m, &(x, y))) in methods.iter().zip(at).enumerate() {
        let line = (i as u32 % lines) as i32;
        let y = y + 6 + line * (font::LINE as i32 + 4);
        area.draw(&Text::new(m.clone(), (x, y), style.clone()))
            .map_err(plot_error)?;
    }
    Ok(())
}

/// Per method: the largest setup, first-frame and warm-up cost over its rows.
fn preparation<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    run: &RunResults,
) -> anyhow::Result<()> {
    let methods = methods_with_rows(run);
    let values: Vec<Vec<f64>> = methods
        .iter()
        .map(|m| {
            let rows: Vec<&Row> = run.rows.iter().filter(|r| &r.method == m).collect();
            let max = |f: fn(&Row) -> f64| rows.iter().map(|r| f(r)).fold(0.0, f64::max);
            vec![
                max(|r| r.prep_setup_ms),
                max(|r| r.prep_first_frame_ms),
                max(|r| r.prep_warmup_ms),
            ]
        })
        .collect();
    bars(
        area,
        "preparation (ms)",
        &methods,
        &values,
        &["setup", "first frame", "warm-up"],
        true,
    )
}

fn memory<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    run: &RunResults,
) -> anyhow::Result<()> {
    let methods = methods_with_rows(run);
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    let values: Vec<Vec<f64>> = methods
        .iter()
        .map(|m| {
            let r = run.rows.iter().find(|r| &r.method == m);
            vec![
                r.map_or(0.0, |r| mib(r.gpu_bytes)),
                r.map_or(0.0, |r| mib(r.cpu_bytes)),
            ]
        })
        .collect();
    bars(
        area,
        "retained memory (MiB)",
        &methods,
        &values,
        &["GPU", "CPU"],
        false,
    )
}

fn methods_with_rows(run: &RunResults) -> Vec<String> {
    run.settings
        .methods
        .iter()
        .filter(|m| run.rows.iter().any(|r| &r.method == *m))
        .cloned()
        .collect()
}

/// The method names of each update class, in the order the figure shows them.
pub const UPDATE_CLASSES: [(&str, &[&str]); 3] = [
    (
        "direct read",
        &["ray", "ray-compute", "painted", "sliced", "scattered"],
    ),
    ("incremental rebuild", &["voxel", "voxel-compute"]),
    ("mesh refit", &["mesh"]),
];

/// The edit figure: rows = one method per update class (the first the run
/// has pictures of), columns = before the crater, first post-edit frame.
/// Written as `figures/edit.png`; `None` without edit pictures (or when
/// none of them is found).
pub fn edit_figure(run: &RunResults, dir: &Path) -> anyhow::Result<Option<(String, Vec<String>)>> {
    let mut rows = Vec::new();
    let mut cells = Vec::new();
    for (class, names) in UPDATE_CLASSES {
        let Some(pics) = names.iter().find_map(|n| {
            run.edit_images
                .iter()
                .find(|e| e.method.split(':').next() == Some(*n))
        }) else {
            continue;
        };
        let load = |rel: &str| {
            image::open(dir.join(rel))
                .ok()
                .map(|i| grid::thumbnail(&i.to_rgba8()))
        };
        // Pictures not beside the results file (a copied results file):
        // no row, rather than a row of empty cells.
        let (Some(before), Some(after)) = (load(&pics.before), load(&pics.after)) else {
            continue;
        };
        rows.push(format!("{} ({class})", pics.method));
        cells.push(vec![Some(before), Some(after)]);
    }
    if rows.is_empty() {
        return Ok(None);
    }
    let columns = vec!["before".to_string(), "first post-edit frame".to_string()];
    let img = grid::compose(&rows, &columns, &cells);
    let fig_dir = dir.join("figures");
    std::fs::create_dir_all(&fig_dir).with_context(|| format!("creating {}", fig_dir.display()))?;
    let path = fig_dir.join("edit.png");
    img.save(&path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(Some(("figures/edit.png".into(), rows)))
}

/// A plotters backend over an RGBA image, with the bitmap font for text;
/// `present` writes it as a PNG.
pub struct ImageBackend {
    image: RgbaImage,
    path: PathBuf,
}

impl ImageBackend {
    pub fn new((w, h): (u32, u32), path: &Path) -> Self {
        ImageBackend {
            image: RgbaImage::from_pixel(w, h, Rgba([255, 255, 255, 255])),
            path: path.to_path_buf(),
        }
    }
}

impl DrawingBackend for ImageBackend {
    type ErrorType = std::io::Error;

    fn get_size(&self) -> (u32, u32) {
        self.image.dimensions()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        Ok(())
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.image
            .save(&self.path)
            .map_err(|e| DrawingErrorKind::DrawingError(std::io::Error::other(e)))
    }

    fn draw_pixel(
        &mut self,
        (x, y): BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let (w, h) = self.image.dimensions();
        if x < 0 || y < 0 || x as u32 >= w || y as u32 >= h {
            return Ok(());
        }
        let a = color.alpha.clamp(0.0, 1.0);
        let px = self.image.get_pixel_mut(x as u32, y as u32);
        let (r, g, b) = color.rgb;
        for (c, v) in px.0.iter_mut().zip([r, g, b]) {
            *c = (f64::from(*c) * (1.0 - a) + f64::from(v) * a).round() as u8;
        }
        Ok(())
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        _style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        Ok((font::text_width(text), font::LINE))
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        (x, y): BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let (w, h) = (font::text_width(text) as i32, font::LINE as i32);
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0,
            HPos::Center => w / 2,
            HPos::Right => w,
        };
        let dy = match anchor.v_pos {
            VPos::Top => 0,
            VPos::Center => h / 2,
            VPos::Bottom => h,
        };
        let (r, g, b) = style.color().rgb;
        let (px, py) = ((x - dx).max(0) as u32, (y - dy).max(0) as u32);
        font::draw_text(&mut self.image, px, py, text, Rgba([r, g, b, 255]));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    #[test]
    fn figures_are_written_as_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("strata-figures-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let runs = [fixtures::run("GPU A"), fixtures::run("GPU B")];
        let figs = write_all(&runs, &dir).unwrap();
        let names: Vec<&str> = figs.iter().map(|f| f.png.as_str()).collect();
        assert_eq!(
            names,
            [
                "figures/frame-time-by-pitch.png",
                "figures/preparation.png",
                "figures/memory.png"
            ]
        );
        for f in &figs {
            let png = image::open(dir.join(&f.png)).unwrap().to_rgba8();
            assert_eq!(png.dimensions(), SIZE);
            // Something besides the white background was drawn.
            assert!(png.pixels().any(|p| p.0 != [255, 255, 255, 255]));
            let svg = std::fs::read_to_string(dir.join(&f.svg)).unwrap();
            assert!(svg.starts_with("<svg"), "{}", &svg[..40.min(svg.len())]);
        }
        // Merged runs name their adapter in the legend.
        let svg = std::fs::read_to_string(dir.join("figures/frame-time-by-pitch.svg")).unwrap();
        assert!(svg.contains("ray (GPU B)"), "legend per adapter");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The panel width `with_legend` gives these labels in a figure of
    /// [`SIZE`].
    fn panel_width(labels: &[String]) -> u32 {
        let longest = labels.iter().map(|l| font::text_width(l)).max().unwrap();
        (longest + SWATCH_WIDTH + 12).min(SIZE.0 * 45 / 100)
    }

    #[test]
    fn the_legend_stands_beside_the_committed_runs_lines() {
        let results = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../bench/results-nvidia-h100-80gb-hbm3.json"
        );
        let run = crate::merge::read_run(std::path::Path::new(results)).unwrap();
        let dir = std::env::temp_dir().join(format!("strata-legend-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        write_all(std::slice::from_ref(&run), &dir).unwrap();
        let png = image::open(dir.join("figures/frame-time-by-pitch.png"))
            .unwrap()
            .to_rgba8();
        let methods = &run.settings.methods;
        let panel = panel_width(methods);
        // Under the legend's rows the panel is empty: no line, grid or
        // label of the chart reaches into it.
        let below = LEGEND_TOP as u32 + 20 * methods.len() as u32;
        for y in below..SIZE.1 {
            for x in SIZE.0 - panel..SIZE.0 {
                assert_eq!(png.get_pixel(x, y).0, [255; 4], "chart pixel at ({x}, {y})");
            }
        }
        // Every method's name is whole in the legend.
        let svg = std::fs::read_to_string(dir.join("figures/frame-time-by-pitch.svg")).unwrap();
        for m in methods {
            assert!(svg.contains(&format!(">\n{m}\n</text>")), "{m}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn long_labels_are_cut_to_the_panel() {
        assert_eq!(shortened("ray", 100), "ray");
        let cut = shortened("ray-exact-fragment (NVIDIA H100 80GB HBM3)", 80);
        assert!(font::text_width(&cut) <= 80 && cut.ends_with(".."), "{cut}");
    }

    #[test]
    fn an_edit_figure_without_its_pictures_is_not_drawn() {
        let mut run = fixtures::run("GPU A");
        run.edit_images.push(crate::results::EditImages {
            method: "ray".into(),
            before: "cells/missing-before.png".into(),
            after: "cells/missing-after.png".into(),
        });
        let dir = std::env::temp_dir().join(format!("strata-edit-fig-{}", std::process::id()));
        assert_eq!(edit_figure(&run, &dir).unwrap(), None);
        assert!(!dir.join("figures/edit.png").exists());
    }
}
