//! The output directory of a run: the results JSON rewritten after every cell
//! (so an interrupted run keeps its finished cells), the cell pictures, and
//! the grid and report rewritten as columns complete.

use crate::grid;
use crate::report::{self, Pictures};
use crate::results::RunResults;
use anyhow::Context;
use image::RgbaImage;
use std::path::{Path, PathBuf};

/// What `grid.png` shows in each cell.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GridMode {
    /// The method's picture (the reference column: the distance picture).
    #[default]
    Pictures,
    /// `--grid flip`: the ꟻLIP error map against the CPU colour reference
    /// (the reference column: the colour reference).
    Flip,
}

impl std::str::FromStr for GridMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "pictures" => Ok(GridMode::Pictures),
            "flip" => Ok(GridMode::Flip),
            _ => Err(format!("grid mode `{s}` is not `pictures` or `flip`")),
        }
    }
}

pub struct Session {
    pub out: PathBuf,
    pub results: RunResults,
    /// Grid columns: "reference" then the method labels.
    pub columns: Vec<String>,
    /// `thumbs[view][column]`.
    pub thumbs: Vec<Vec<Option<RgbaImage>>>,
    pub grid: GridMode,
}

impl Session {
    pub fn new(out: &Path, results: RunResults) -> Self {
        let mut columns = vec!["reference".to_string()];
        columns.extend(results.settings.methods.iter().cloned());
        let thumbs = vec![vec![None; columns.len()]; results.settings.views.len()];
        Session {
            out: out.to_path_buf(),
            results,
            columns,
            thumbs,
            grid: GridMode::Pictures,
        }
    }

    /// The grid thumbnails of cells already in the results (a resumed
    /// run's), from their pictures; a picture that cannot be read leaves
    /// its grid cell empty.
    pub fn restore_thumbnails(&mut self) {
        let settings = &self.results.settings;
        for row in &self.results.rows {
            let v = settings.views.iter().position(|v| v.name == row.view);
            let m = settings.methods.iter().position(|m| *m == row.method);
            let (Some(v), Some(m)) = (v, m) else {
                continue;
            };
            if let Ok(img) = image::open(self.out.join(&row.image)) {
                self.thumbs[v][m + 1] = Some(grid::thumbnail(&img.to_rgba8()));
            }
        }
    }

    /// Rewrite `results-<adapter>.json`.
    pub fn save_json(&self) -> anyhow::Result<PathBuf> {
        self.results.write(&self.out)
    }

    /// Write a full-size cell picture under `cells/`, and keep its
    /// thumbnail for the grid when the grid shows pictures of this `kind`
    /// ([`GridMode::Pictures`]: a method's or the reference's picture;
    /// [`GridMode::Flip`]: a ꟻLIP error map or the colour reference).
    /// Returns the path relative to the output directory.
    pub fn save_picture(
        &mut self,
        kind: GridMode,
        (view, column): (usize, usize),
        file: &str,
        img: RgbaImage,
    ) -> anyhow::Result<String> {
        let rel = format!("cells/{file}.png");
        let path = self.out.join(&rel);
        img.save(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        if kind == self.grid
            && let Some(slot) = self.thumbs.get_mut(view).and_then(|r| r.get_mut(column))
        {
            *slot = Some(grid::thumbnail(&img));
        }
        Ok(rel)
    }

    /// Save view `v`'s CPU reference picture (its first grid column) and
    /// list it in the results.
    pub fn save_reference(
        &mut self,
        v: usize,
        view: &str,
        reference: &strata_reference::Reference,
        far: f32,
    ) -> anyhow::Result<()> {
        let image = self.save_picture(
            GridMode::Pictures,
            (v, 0),
            &format!("{view}-reference"),
            reference_image(reference, far),
        )?;
        self.results
            .reference_images
            .push(crate::results::ViewImage {
                view: view.to_string(),
                image,
            });
        Ok(())
    }

    /// Rewrite `grid.png` and `report.md`.
    pub fn save_report(&self) -> anyhow::Result<PathBuf> {
        let rows: Vec<String> = self
            .results
            .settings
            .views
            .iter()
            .map(|v| v.name.clone())
            .collect();
        let grid_img = grid::compose(&rows, &self.columns, &self.thumbs);
        let grid_path = self.out.join("grid.png");
        grid_img
            .save(&grid_path)
            .with_context(|| format!("writing {}", grid_path.display()))?;
        let pictures = Pictures {
            grid: Some("grid.png".into()),
            grid_columns: self.columns.clone(),
            ..Pictures::default()
        };
        let runs = std::slice::from_ref(&self.results);
        let pictures = crate::figures::with_figures(pictures, runs, &self.out);
        let md = report::render(runs, &pictures, &[]);
        let path = self.out.join("report.md");
        std::fs::write(&path, md).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    }
}

/// An RGBA8 readback as an opaque image (alpha forced to 255 so every viewer
/// shows the colour the method wrote).
pub fn color_image(width: u32, height: u32, mut rgba: Vec<u8>) -> anyhow::Result<RgbaImage> {
    for px in rgba.chunks_exact_mut(4) {
        px[3] = 255;
    }
    RgbaImage::from_raw(width, height, rgba).context("colour readback has the wrong size")
}

/// The reference distance picture, in the reference crate's colours.
pub fn reference_image(r: &strata_reference::Reference, far: f32) -> RgbaImage {
    RgbaImage::from_fn(r.width, r.height, |x, y| {
        let d = r
            .distance
            .get((y * r.width + x) as usize)
            .copied()
            .unwrap_or(f32::INFINITY);
        let [cr, cg, cb] = strata_reference::output::distance_rgb(d, far);
        image::Rgba([cr, cg, cb, 255])
    })
}
