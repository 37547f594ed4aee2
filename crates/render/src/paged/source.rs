//! Where pages come from: a [`PageSource`] hands out one 256x256 chunk of
//! the world at a time, already in the GPU's layout ([`PageData`]), and the
//! coarse level every ray starts from (each chunk's highest top).
//!
//! Two sources: [`LevelPages`] over a world in memory (tests; the
//! whole-world image a paged render must converge to) and [`StorePages`]
//! over a Zarr store's [`ChunkCache`] (worlds of any size).

use std::sync::Arc;
use strata_level::model::decode_column;
use strata_level::{Level, MidRule};
use strata_maxmip::Layout;
#[cfg(not(target_arch = "wasm32"))]
use strata_store::ChunkCache;

/// Texels per side of a page: the store's chunk, and the coarsest tile of
/// the exact march's pyramid (`strata_maxmip::MAX_LEVEL`), so a page is
/// exactly one tile of the always-resident coarse level.
pub const PAGE: u32 = 256;

/// A page in the GPU's layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PageData {
    /// `PAGE / 2 * PAGE` pair texels, `(height even, meta even, height odd,
    /// meta odd)` row-major: the terrain texture's layout (`terrain.rs`).
    pub pairs: Vec<u8>,
    /// The page's own max-height pyramid, levels 1..8 of a 256x256 map laid
    /// out by [`page_pyramid_layout`].
    pub pyramid: Vec<u8>,
}

/// The layout of a page's pyramid: that of a 256x256 map, with `step`
/// ([`strata_maxmip::Layout::with_step`]) as the method builds.
pub fn page_pyramid_layout(step: u32) -> Layout {
    Layout::with_step(PAGE, PAGE, step)
}

impl PageData {
    /// A page from the chunk's two planes (`PAGE * PAGE` bytes each).
    pub fn from_planes(
        heights: &[u8],
        metas: &[u8],
        mid_rule: MidRule,
        step: u32,
    ) -> Result<Self, String> {
        let n = (PAGE * PAGE) as usize;
        if heights.len() != n || metas.len() != n {
            return Err(format!(
                "a page needs {n} bytes per plane, got {} and {}",
                heights.len(),
                metas.len()
            ));
        }
        let mut pairs = Vec::with_capacity(2 * n);
        for (h, m) in heights.chunks_exact(2).zip(metas.chunks_exact(2)) {
            pairs.extend_from_slice(&[h[0], m[0], h[1], m[1]]);
        }
        Ok(PageData {
            pairs,
            pyramid: page_pyramid(heights, metas, mid_rule, step),
        })
    }

    /// The page's highest top: its tile of the coarse level (the pyramid's
    /// last level, one 256-texel tile).
    pub fn top(&self, step: u32) -> u8 {
        let layout = page_pyramid_layout(step);
        self.pyramid[layout.level(layout.top()).offset as usize]
    }

    /// Bytes of the page as uploaded.
    pub fn bytes(&self) -> usize {
        self.pairs.len() + self.pyramid.len()
    }
}

/// The page's max-height pyramid on the calling thread, the same bytes as
/// `strata_maxmip::Pyramid::with_step` over the page (tested). Not that
/// build: it fans out over rayon's pool, where a page reader would wait
/// behind whatever else the process runs there.
fn page_pyramid(heights: &[u8], metas: &[u8], mid_rule: MidRule, step: u32) -> Vec<u8> {
    let layout = page_pyramid_layout(step);
    let mut data = vec![0u8; layout.bytes as usize];
    let side = PAGE as usize;
    let mut below: Vec<u8> = (0..side * side)
        .map(|i| {
            let row = i / side * side..(i / side + 1) * side;
            decode_column(&heights[row.clone()], &metas[row], i % side, mid_rule).top()
        })
        .collect();
    let mut n = side;
    for k in 1..=strata_maxmip::MAX_LEVEL {
        n /= 2;
        let level: Vec<u8> = (0..n * n)
            .map(|i| {
                let (x, y) = (2 * (i % n), 2 * (i / n));
                let w = 2 * n;
                below[y * w + x]
                    .max(below[y * w + x + 1])
                    .max(below[(y + 1) * w + x])
                    .max(below[(y + 1) * w + x + 1])
            })
            .collect();
        if k % step == 0 {
            let info = layout.level(k);
            data[info.offset as usize..info.offset as usize + level.len()].copy_from_slice(&level);
        }
        below = level;
    }
    data
}

/// A world, a page at a time. `Send + Sync`: the streamer reads on a thread
/// of its own.
pub trait PageSource: Send + Sync {
    /// World width and height, texels (powers of two, at least [`PAGE`]).
    fn size(&self) -> (u32, u32);

    /// How the mid byte is read.
    fn mid_rule(&self) -> MidRule;

    /// The highest top of every chunk, row-major over the chunk grid: the
    /// always-resident coarse level (from a store's summaries, without
    /// reading a chunk).
    fn chunk_tops(&self) -> Result<Vec<u8>, String>;

    /// Chunk (`cx`, `cy`) as a page, its pyramid built with `step`.
    fn read_page(&self, cx: u32, cy: u32, step: u32) -> Result<PageData, String>;

    /// Coarse levels of detail the source has (`strata_level::lod`: level
    /// k is the map halved k times, cut in pages like the map); 0: none.
    fn lod_levels(&self) -> u32 {
        0
    }

    /// Page (`cx`, `cy`) of level `level` (0: [`PageSource::read_page`]).
    fn read_lod_page(&self, level: u32, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        if level == 0 {
            self.read_page(cx, cy, step)
        } else {
            Err(format!("this source has no level of detail {level}"))
        }
    }

    /// A source whose reads complete later, on their own (a browser's
    /// fetches): the [`super::Streamer`] then hands it the wanted pages and
    /// takes the finished ones back instead of calling
    /// [`PageSource::read_lod_page`]. `None` (the default): reads block.
    fn async_pages(&self) -> Option<&dyn AsyncPages> {
        None
    }
}

/// A page to read: its id and where it lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageRef {
    /// The page's id ([`super::PageIds`]).
    pub id: u32,
    /// Its level (0: the map's chunks).
    pub level: u32,
    /// Its column in that level's grid.
    pub cx: u32,
    /// Its row in that level's grid.
    pub cy: u32,
}

/// One chunk's two planes (heights, metas), `PAGE * PAGE` bytes each.
pub type Planes = (Vec<u8>, Vec<u8>);

/// The seam for reads that cannot block (issue 34: a browser page has no
/// threads; its fetches complete after the page yields). The streamer
/// calls [`AsyncPages::want`] with each frame's wanted pages and
/// [`AsyncPages::take_finished`] before uploading; whoever does the reads
/// (see [`super::remote::RemoteChunks`]) starts, caps and cancels them.
pub trait AsyncPages: Send + Sync {
    /// Make `pages` (most wanted first) the wanted reads: those not started
    /// yet replace the queue, reads in flight that are not among them are
    /// cancelled.
    fn want(&self, pages: &[PageRef]);
    /// Reads finished since the last call, at most `most`: the page id and
    /// its planes, or why the read failed.
    fn take_finished(&self, most: usize) -> Vec<(u32, Result<Planes, String>)>;
    /// Reads queued, in flight, or finished and not yet taken.
    fn in_flight(&self) -> usize;
    /// Whether page `id` is queued, in flight, or finished and not taken.
    fn is_in_flight(&self, id: u32) -> bool;
}

/// Pages cut from a world in memory.
pub struct LevelPages {
    level: Arc<Level>,
    /// The coarse levels' planes, 1.., made at the first ask.
    lods: std::sync::OnceLock<Vec<(Vec<u8>, Vec<u8>)>>,
}

impl LevelPages {
    /// Pages of `level` (refused below one page a side).
    pub fn new(level: Arc<Level>) -> anyhow::Result<Self> {
        check_size(level.width(), level.height())?;
        Ok(LevelPages {
            level,
            lods: std::sync::OnceLock::new(),
        })
    }

    /// The world.
    pub fn level(&self) -> &Arc<Level> {
        &self.level
    }

    fn planes(&self, cx: u32, cy: u32) -> (Vec<u8>, Vec<u8>) {
        cut_page(
            self.level.heights(),
            self.level.metas(),
            self.level.width() as usize,
            cx,
            cy,
        )
    }

    /// Every coarse level's planes, halving the map level by level.
    fn lod_planes(&self) -> &[(Vec<u8>, Vec<u8>)] {
        self.lods.get_or_init(|| {
            let (mut w, mut h) = (self.level.width() as usize, self.level.height() as usize);
            let mut out: Vec<(Vec<u8>, Vec<u8>)> = Vec::new();
            for _ in 0..self.lod_levels() {
                let (hs, ms) = match out.last() {
                    Some((hs, ms)) => strata_level::lod::halve(hs, ms, w, h),
                    None => {
                        strata_level::lod::halve(self.level.heights(), self.level.metas(), w, h)
                    }
                };
                out.push((hs, ms));
                (w, h) = (w / 2, h / 2);
            }
            out
        })
    }
}

impl PageSource for LevelPages {
    fn size(&self) -> (u32, u32) {
        (self.level.width(), self.level.height())
    }

    fn mid_rule(&self) -> MidRule {
        self.level.mid_rule
    }

    fn chunk_tops(&self) -> Result<Vec<u8>, String> {
        let (gx, gy) = (self.level.width() / PAGE, self.level.height() / PAGE);
        let mut tops = vec![0u8; (gx * gy) as usize];
        for cy in 0..gy {
            for cx in 0..gx {
                let mut top = 0;
                for y in cy * PAGE..(cy + 1) * PAGE {
                    for x in cx * PAGE..(cx + 1) * PAGE {
                        top = top.max(self.level.column(i64::from(x), i64::from(y)).top());
                    }
                }
                tops[(cy * gx + cx) as usize] = top;
            }
        }
        Ok(tops)
    }

    fn read_page(&self, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        let (heights, metas) = self.planes(cx, cy);
        PageData::from_planes(&heights, &metas, self.level.mid_rule, step)
    }

    fn lod_levels(&self) -> u32 {
        strata_level::lod::possible_levels(self.level.width(), self.level.height(), PAGE, PAGE)
    }

    fn read_lod_page(&self, level: u32, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        if level == 0 {
            return self.read_page(cx, cy, step);
        }
        let Some((hs, ms)) = self.lod_planes().get(level as usize - 1) else {
            return Err(format!(
                "level of detail {level} asked for; this world has {}",
                self.lod_levels()
            ));
        };
        let w = (self.level.width() >> level) as usize;
        if (cx + 1) * PAGE > w as u32 || (cy + 1) as usize * PAGE as usize * w > hs.len() {
            return Err(format!(
                "page ({cx}, {cy}) is outside level of detail {level}"
            ));
        }
        let (heights, metas) = cut_page(hs, ms, w, cx, cy);
        PageData::from_planes(&heights, &metas, self.level.mid_rule, step)
    }
}

/// Page (`cx`, `cy`) of planes `width` texels wide.
fn cut_page(hs: &[u8], ms: &[u8], width: usize, cx: u32, cy: u32) -> (Vec<u8>, Vec<u8>) {
    let (x0, y0) = ((cx * PAGE) as usize, (cy * PAGE) as usize);
    let mut heights = Vec::with_capacity((PAGE * PAGE) as usize);
    let mut metas = Vec::with_capacity((PAGE * PAGE) as usize);
    for y in y0..y0 + PAGE as usize {
        let row = y * width + x0..y * width + x0 + PAGE as usize;
        heights.extend_from_slice(&hs[row.clone()]);
        metas.extend_from_slice(&ms[row]);
    }
    (heights, metas)
}

/// Pages read through a store's chunk cache (the cache's byte budget bounds
/// the CPU memory; the GPU budget is the renderer's). Native only: zarrs'
/// storage is neither Send nor Sync on wasm32, where a page reader over
/// HTTP is issue 34's.
#[cfg(not(target_arch = "wasm32"))]
pub struct StorePages {
    cache: Arc<ChunkCache>,
    mid_rule: MidRule,
}

#[cfg(not(target_arch = "wasm32"))]
impl StorePages {
    /// Pages of the store behind `cache`; its chunks must be pages.
    pub fn new(cache: Arc<ChunkCache>, mid_rule: MidRule) -> anyhow::Result<Self> {
        let store = cache.store();
        check_size(store.width(), store.height())?;
        if store.chunk_shape() != (PAGE, PAGE) {
            anyhow::bail!(
                "paged rendering reads {PAGE}x{PAGE} chunks; store `{}` has {}x{} chunks (rewrite it with `strata convert`)",
                store.what(),
                store.chunk_shape().1,
                store.chunk_shape().0
            );
        }
        Ok(StorePages { cache, mid_rule })
    }

    /// The cache pages are read through.
    pub fn cache(&self) -> &Arc<ChunkCache> {
        &self.cache
    }
}

#[cfg(not(target_arch = "wasm32"))]
impl PageSource for StorePages {
    fn size(&self) -> (u32, u32) {
        let s = self.cache.store();
        (s.width(), s.height())
    }

    fn mid_rule(&self) -> MidRule {
        self.mid_rule
    }

    fn chunk_tops(&self) -> Result<Vec<u8>, String> {
        let summaries = self.cache.store().summaries().map_err(|e| e.to_string())?;
        Ok(summaries.iter().map(|s| s.top_max).collect())
    }

    fn read_page(&self, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        let chunk = self
            .cache
            .chunk(u64::from(cy), u64::from(cx))
            .map_err(|e| e.to_string())?;
        PageData::from_planes(&chunk.heights, &chunk.metas, self.mid_rule(), step)
    }

    fn lod_levels(&self) -> u32 {
        self.cache.store().lod_levels()
    }

    fn read_lod_page(&self, level: u32, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        if level == 0 {
            return self.read_page(cx, cy, step);
        }
        // Not through the cache: a coarse page is read once and then kept on
        // the GPU; the cache's budget is for the map's chunks.
        let chunk = self
            .cache
            .store()
            .read_lod_chunk(level, u64::from(cy), u64::from(cx))
            .map_err(|e| e.to_string())?;
        PageData::from_planes(&chunk.heights, &chunk.metas, self.mid_rule(), step)
    }
}

/// Paged worlds are whole pages, powers of two a side.
pub(crate) fn check_size(width: u32, height: u32) -> anyhow::Result<()> {
    if width < PAGE || height < PAGE || !width.is_power_of_two() || !height.is_power_of_two() {
        anyhow::bail!(
            "paged rendering needs a world of at least {PAGE}x{PAGE} texels, powers of two a side; this one is {width}x{height}"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_pyramid_is_the_maxmip_twin() {
        let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 3,
            width: 512,
            height: 512,
        })
        .unwrap();
        let pages = LevelPages::new(Arc::new(world.level.clone())).unwrap();
        for step in [1, 2] {
            for (cx, cy) in [(0, 0), (1, 0), (1, 1)] {
                let page = pages.read_page(cx, cy, step).unwrap();
                let (h, m) = pages.planes(cx, cy);
                let level = Level::from_planes(PAGE, PAGE, h, m, world.level.mid_rule).unwrap();
                let twin = strata_maxmip::Pyramid::with_step(&level, step).data;
                assert_eq!(page.pyramid, twin, "step {step} chunk ({cx}, {cy})");
            }
        }
    }
}

#[cfg(test)]
mod lod_tests {
    use super::*;

    #[test]
    fn coarse_pages_keep_the_highest_tops() {
        let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 6,
            width: 2048,
            height: 2048,
        })
        .unwrap();
        let pages = LevelPages::new(Arc::new(world.level.clone())).unwrap();
        assert_eq!(pages.lod_levels(), 3);
        for level in 1..=3u32 {
            let page = pages.read_lod_page(level, 0, 0, 1).unwrap();
            let max_pair = page.pairs.chunks_exact(2).map(|p| p[0]).max().unwrap();
            // Page (0, 0) of level k covers 256 * 2^k texels a side.
            let side = (256u32 << level) as i64;
            let mut top = 0;
            for y in 0..side {
                for x in 0..side {
                    top = top.max(world.level.column(x, y).top());
                }
            }
            eprintln!(
                "level {level}: page top {} pairs max {max_pair} map top {top}",
                page.top(1)
            );
            assert_eq!(page.top(1), top, "level {level}");
        }
    }
}
