//! Fitting the chunks under a region of a map read through a
//! [`ColumnSource`] (a store's chunk cache), in bounded memory: each chunk's
//! fit depends on its own `(size + 1)²` samples alone (see
//! [`ChunkSamples::load`](crate::samples::ChunkSamples::load)), so a chunk
//! is fitted from a small patch level holding just those texels, and the
//! result is the chunk's mesh of the whole-map fit, index for index.

use crate::emit::ChunkMesh;
use crate::fit::{ChunkFitter, FitOptions};
use crate::level_mesh::MeshStats;
use crate::samples::{CHUNK, ChunkLayout};
use rayon::prelude::*;
use strata_level::Level;
use strata_level::source::{ColumnSource, SourceError, read_window};

/// The fit's chunks of a `width x height` map ([`ChunkLayout::of`] for a
/// level of that size).
pub fn layout_for(width: u32, height: u32) -> ChunkLayout {
    let size_x = CHUNK.min(width);
    let size_y = CHUNK.min(height);
    ChunkLayout {
        size_x,
        size_y,
        chunks_x: width / size_x,
        chunks_y: height / size_y,
    }
}

/// The chunk cells `(gx, gy)` (unwrapped: a region past the map's edge
/// continues in cells past it) whose squares hold a point of the half-open
/// texel region `[x0, x1) x [y0, y1)`. Chunk squares start at texel
/// centres: cell g covers `[g size + 0.5, (g + 1) size + 0.5]`.
pub fn region_cells(layout: &ChunkLayout, x0: i64, y0: i64, x1: i64, y1: i64) -> Vec<(i64, i64)> {
    let (sx, sy) = (i64::from(layout.size_x), i64::from(layout.size_y));
    let cells = |lo: i64, hi: i64, s: i64| {
        let first = (lo as f64 - 0.5).div_euclid(s as f64) as i64;
        let last = (hi as f64 - 0.5).div_euclid(s as f64) as i64;
        first..=last
    };
    cells(y0, y1, sy)
        .flat_map(|gy| cells(x0, x1, sx).map(move |gx| (gx, gy)))
        .collect()
}

/// The chunk index of cell `(gx, gy)`, wrapped onto the map.
pub fn cell_chunk(layout: &ChunkLayout, gx: i64, gy: i64) -> usize {
    layout.index(
        gx.rem_euclid(i64::from(layout.chunks_x)) as u32,
        gy.rem_euclid(i64::from(layout.chunks_y)) as u32,
    )
}

/// Fit chunk `(cx, cy)` of the map `source` reads. A level in memory is
/// fitted directly; any other source through a patch level holding the
/// chunk's samples (and the pair partner of its last column).
pub fn fit_chunk_from(
    fitter: &mut ChunkFitter,
    source: &dyn ColumnSource,
    layout: &ChunkLayout,
    (cx, cy): (u32, u32),
    tol: f64,
    options: FitOptions,
) -> Result<ChunkMesh, SourceError> {
    if let Some(level) = source.as_level() {
        return Ok(fitter.fit_with(level, layout, cx, cy, tol, options));
    }
    Ok(Patch::read(source, layout, (cx, cy))?.fit(fitter, tol, options))
}

/// A chunk's samples in a small level of their own: the chunk's
/// `(size + 1)²` samples and the pair partner of its last column, at the
/// origin. Fitting its chunk 0 gives the chunk's mesh of the whole-map fit,
/// index for index; an edit's refit can take one off the render thread
/// without the rest of the map.
pub struct Patch {
    /// The samples at the origin (power-of-two sides, zero past them).
    pub level: Level,
    /// The map's chunk size over the patch (its chunk 0 is the chunk).
    pub layout: ChunkLayout,
}

impl Patch {
    /// Chunk `(cx, cy)` of `layout` over the map `source` reads (a
    /// [`Level`] is a source too).
    pub fn read(
        source: &dyn ColumnSource,
        layout: &ChunkLayout,
        (cx, cy): (u32, u32),
    ) -> Result<Patch, SourceError> {
        // Samples 0..=size in each direction, plus one column so the last
        // sample's pair (it starts on an even texel) decodes from raw bytes.
        let (ww, wh) = (layout.size_x + 2, layout.size_y + 1);
        let (pw, ph) = (ww.next_power_of_two(), wh.next_power_of_two());
        let (x0, y0) = (
            i64::from(cx) * i64::from(layout.size_x),
            i64::from(cy) * i64::from(layout.size_y),
        );
        let (mut heights, mut metas) =
            (vec![0u8; (pw * ph) as usize], vec![0u8; (pw * ph) as usize]);
        let (ww, pw_) = (ww as usize, pw as usize);
        if let Some(level) = source.as_level() {
            // Row by row, in at most two runs where the map wraps (an
            // edit's refit copies its chunks on the render thread).
            let (w, h) = (level.width() as usize, level.height() as usize);
            for j in 0..wh as usize {
                let (hr, mr) = level.row(((y0 as usize) + j).rem_euclid(h) as u32);
                let (mut x, mut i) = ((x0 as usize) % w, 0);
                while i < ww {
                    let run = (w - x).min(ww - i);
                    let at = j * pw_ + i;
                    heights[at..at + run].copy_from_slice(&hr[x..x + run]);
                    metas[at..at + run].copy_from_slice(&mr[x..x + run]);
                    (x, i) = (0, i + run);
                }
            }
        } else {
            let (wh_bytes, wm_bytes) = read_window(source, x0, y0, ww as u32, wh)?;
            for j in 0..wh as usize {
                let (src, dst) = (j * ww, j * pw_);
                heights[dst..dst + ww].copy_from_slice(&wh_bytes[src..src + ww]);
                metas[dst..dst + ww].copy_from_slice(&wm_bytes[src..src + ww]);
            }
        }
        let level = Level::from_planes(pw, ph, heights, metas, source.mid_rule())
            .map_err(|e| SourceError(format!("patch for chunk ({cx}, {cy}): {e}")))?;
        let layout = ChunkLayout {
            size_x: layout.size_x,
            size_y: layout.size_y,
            chunks_x: pw / layout.size_x,
            chunks_y: ph / layout.size_y,
        };
        Ok(Patch { level, layout })
    }

    /// Fit the patch's chunk at finest tolerance `tol` with `options`.
    pub fn fit(&self, fitter: &mut ChunkFitter, tol: f64, options: FitOptions) -> ChunkMesh {
        fitter.fit_with(&self.level, &self.layout, 0, 0, tol, options)
    }
}

/// Fit the chunks `ids` (indices of `layout`) of the map `source` reads,
/// in parallel on the current rayon pool, in order.
pub fn fit_chunks_from(
    source: &dyn ColumnSource,
    layout: &ChunkLayout,
    ids: &[usize],
    tol: f64,
    options: FitOptions,
) -> Result<Vec<ChunkMesh>, SourceError> {
    ids.par_iter()
        .map_init(ChunkFitter::default, |f, &i| {
            fit_chunk_from(f, source, layout, layout.coords(i), tol, options)
        })
        .collect()
}

/// Fit the chunks `ids` and keep only their totals: batches of `batch`
/// chunks at a time, so memory does not grow with the number of chunks
/// (a whole store's fit). `tol` is the finest LOD's max error.
pub fn fit_stats_from(
    source: &dyn ColumnSource,
    layout: &ChunkLayout,
    ids: &[usize],
    tol: f64,
    options: FitOptions,
    batch: usize,
) -> Result<MeshStats, SourceError> {
    let mut stats = MeshStats {
        tolerance: tol,
        ..MeshStats::default()
    };
    for part in ids.chunks(batch.max(1)) {
        for mesh in fit_chunks_from(source, layout, part, tol, options)? {
            stats.add_chunk(&mesh);
        }
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LevelMesh;
    use crate::synthetic::synthetic_level;
    use std::sync::Arc;
    use strata_level::source::SourceTile;
    use strata_level::{Level, MidRule};

    /// A level read as 64x64 tiles, without its fast path.
    struct Tiled(Level);
    struct Owned(Vec<u8>, Vec<u8>);
    impl SourceTile for Owned {
        fn planes(&self) -> (&[u8], &[u8]) {
            (&self.0, &self.1)
        }
    }
    impl ColumnSource for Tiled {
        fn size(&self) -> (u32, u32) {
            (self.0.width(), self.0.height())
        }
        fn mid_rule(&self) -> MidRule {
            self.0.mid_rule
        }
        fn tile_shape(&self) -> (u32, u32) {
            (64, 64)
        }
        fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError> {
            let (h, m) = read_window(&self.0, tx as i64 * 64, ty as i64 * 64, 64, 64)?;
            Ok(Arc::new(Owned(h, m)))
        }
    }

    #[test]
    fn chunks_fitted_from_tiles_equal_the_whole_fit() {
        let level = synthetic_level(512, 256, 3);
        let tol = 2.0;
        for options in [FitOptions::default(), FitOptions { outline: true }] {
            let whole = LevelMesh::fit_with_options(&level, tol, options, &|_, _| {});
            let layout = layout_for(512, 256);
            assert_eq!(layout, whole.layout);
            let ids: Vec<usize> = (0..layout.count()).collect();
            let tiled = Tiled(level.clone());
            let got = fit_chunks_from(&tiled, &layout, &ids, tol, options).unwrap();
            assert_eq!(got, whole.chunks, "outline {}", options.outline);
            let stats = fit_stats_from(&tiled, &layout, &ids, tol, options, 3).unwrap();
            assert_eq!(stats, whole.stats());
        }
        // Cells of a region across the right edge wrap onto the map.
        let layout = layout_for(512, 256);
        let cells = region_cells(&layout, 500, 0, 530, 10);
        assert_eq!(cells, vec![(3, -1), (4, -1), (3, 0), (4, 0)]);
        assert_eq!(cell_chunk(&layout, 4, -1), layout.index(0, 1));
    }

    /// A level's patches (copied row by row) equal those read through
    /// tiles, and fit to the whole fit's chunks, wrapping at the map's
    /// edges, on a map narrower than a patch too.
    #[test]
    fn patches_of_a_level_equal_patches_read_through_tiles() {
        for (w, h) in [(512, 256), (64, 128)] {
            let level = synthetic_level(w, h, 5);
            let layout = layout_for(w, h);
            let whole = LevelMesh::fit(&level, 2.0);
            let tiled = Tiled(level.clone());
            let mut fitter = ChunkFitter::default();
            for i in 0..layout.count() {
                let from_level = Patch::read(&level, &layout, layout.coords(i)).unwrap();
                let from_tiles = Patch::read(&tiled, &layout, layout.coords(i)).unwrap();
                assert_eq!(from_level.layout, from_tiles.layout);
                assert_eq!(
                    from_level.level.content_hash(),
                    from_tiles.level.content_hash(),
                    "{w}x{h} chunk {i}"
                );
                let mesh = from_level.fit(&mut fitter, 2.0, FitOptions::default());
                assert_eq!(mesh, whole.chunks[i], "{w}x{h} chunk {i}");
            }
        }
    }
}
