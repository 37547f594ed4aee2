//! Paged worlds in the viewer (issue 33): a store, or any world given a GPU
//! budget, drawn through [`strata_render::Renderer::new_paged`], its pages
//! streamed as the camera moves (the renderer reads each frame's feedback
//! and uploads what the view asked for; `strata fly` measures the same).
//!
//! Digging writes whole chunks into an edit layer over the world's pages
//! ([`EditedPages`]): the crater is cut in a small window of the chunks it
//! touches, those chunks replace the world's in the layer, and the paged
//! terrain re-reads them ([`strata_render::Renderer::refresh_pages`]), so the
//! next frame shows it. Ctrl+S writes the edited chunks into the store in
//! place, all or nothing (`DirStore::commit_chunks`, issue 32's batches;
//! `--overwrite` as for any save over the loaded world).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use strata_level::edit::{crater, crater_rect};
use strata_level::{Column, EditSite, Level, MidRule};
use strata_render::paged::{
    AsyncPages, PAGE, PageData, PageRef, PageSource, PagedOptions, RemoteChunks,
};

/// Why `method` cannot draw a paged world (`None`: it can).
pub fn refusal(method: &str) -> Option<String> {
    // `mesh` fits its chunks on worker threads natively and, in a browser
    // page (no threads: `PagedOptions::threads` 0), between frames within a
    // few milliseconds each (`methods/mesh/fitter.rs`).
    (!strata_render::paged::PAGED_METHODS.contains(&method)).then(|| {
        format!(
            "`{method}` draws whole worlds only; paged worlds are drawn by {}",
            strata_render::paged::PAGED_METHODS.join(", ")
        )
    })
}

/// The camera of `view` over a world of `size` texels whose columns
/// `column` reads at texel (x, y) (the one under the eye); a failed read is
/// an error naming the view.
pub fn camera_over<E: std::fmt::Display>(
    size: (u32, u32),
    mut column: impl FnMut(i64, i64) -> Result<Column, E>,
    view: &strata_level::ViewSpec,
    width: u32,
    height: u32,
) -> anyhow::Result<strata_camera::Camera> {
    let mut error = None;
    let read = |x: f32, y: f32| {
        column(x.floor() as i64, y.floor() as i64).unwrap_or_else(|e| {
            error = Some(e.to_string());
            Level::flat(2, 1, 0, 0).expect("a 2x1 level").column(0, 0)
        })
    };
    let camera = strata_camera::Camera::from_view_over(size, read, view, width, height)
        .map_err(|e| anyhow::anyhow!("view `{}`: {e:#}", view.name))?;
    match error {
        Some(e) => anyhow::bail!("reading the ground under view `{}`: {e}", view.name),
        None => Ok(camera),
    }
}

/// What `Options::paged` carries: the world's pages and how to page them.
#[derive(Clone)]
pub struct PagedWorld {
    pub pages: Arc<EditedPages>,
    pub options: PagedOptions,
}

/// Where the unedited chunks come from.
pub enum Base {
    /// A world in memory (`--gpu-budget` over a Vangers world).
    Level(Arc<Level>),
    /// A store read through its chunk cache (never whole).
    #[cfg(not(target_arch = "wasm32"))]
    Store {
        cache: Arc<strata_store::ChunkCache>,
        dir: std::path::PathBuf,
    },
    /// A store streamed over HTTP (a browser page, issue 34): chunks come
    /// through a pump's asynchronous reads; the last ones read are kept.
    Remote(Arc<RemoteChunks>),
}

/// One chunk's two planes, row-major (`PAGE * PAGE` bytes each).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Planes {
    pub heights: Vec<u8>,
    pub metas: Vec<u8>,
}

/// What a dig changed: the chunks (grid row-major indices) and their
/// planes before it, for undo.
#[derive(Debug, Default)]
pub struct Dug {
    pub chunks: Vec<u32>,
    pub before: Vec<(u32, Arc<Planes>)>,
}

/// A world's pages with the session's edits over them.
pub struct EditedPages {
    base: Mutex<Base>,
    size: (u32, u32),
    mid_rule: MidRule,
    /// Edited chunks by grid index (row-major).
    edited: Mutex<HashMap<u32, Arc<Planes>>>,
    /// The streamed store, when the base is one (its reads are asynchronous).
    remote: Option<Arc<RemoteChunks>>,
}

impl EditedPages {
    /// Pages of `base` (a world of whole pages, powers of two a side).
    pub fn new(base: Base, mid_rule: MidRule) -> anyhow::Result<Self> {
        let size = match &base {
            Base::Level(level) => (level.width(), level.height()),
            #[cfg(not(target_arch = "wasm32"))]
            Base::Store { cache, .. } => (cache.store().width(), cache.store().height()),
            Base::Remote(remote) => remote.size(),
        };
        let remote = match &base {
            Base::Remote(remote) => Some(remote.clone()),
            _ => None,
        };
        if size.0 < PAGE || size.1 < PAGE || !size.0.is_power_of_two() || !size.1.is_power_of_two()
        {
            anyhow::bail!(
                "paged worlds are at least {PAGE}x{PAGE} texels, powers of two a side; this one is {}x{}",
                size.0,
                size.1
            );
        }
        Ok(EditedPages {
            base: Mutex::new(base),
            size,
            mid_rule,
            edited: Mutex::new(HashMap::new()),
            remote,
        })
    }

    /// World width and height, texels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Chunks across and down.
    pub fn grid(&self) -> (u32, u32) {
        (self.size.0 / PAGE, self.size.1 / PAGE)
    }

    /// Chunks edited since the world was opened or last saved.
    pub fn edited_chunks(&self) -> usize {
        self.edited.lock().expect("edit lock").len()
    }

    /// The streamed store's reads, when the world is one.
    pub fn remote(&self) -> Option<&Arc<RemoteChunks>> {
        self.remote.as_ref()
    }

    /// Whether the world is a store (saved in place, chunk by chunk).
    pub fn is_store(&self) -> bool {
        !matches!(&*self.base.lock().expect("base lock"), Base::Level(_))
    }

    fn base_planes(&self, cx: u32, cy: u32) -> Result<Planes, String> {
        match &*self.base.lock().expect("base lock") {
            Base::Level(level) => {
                let w = level.width() as usize;
                let (x0, y0) = ((cx * PAGE) as usize, (cy * PAGE) as usize);
                let mut planes = Planes {
                    heights: Vec::with_capacity((PAGE * PAGE) as usize),
                    metas: Vec::with_capacity((PAGE * PAGE) as usize),
                };
                for y in y0..y0 + PAGE as usize {
                    let row = y * w + x0..y * w + x0 + PAGE as usize;
                    planes
                        .heights
                        .extend_from_slice(&level.heights()[row.clone()]);
                    planes.metas.extend_from_slice(&level.metas()[row]);
                }
                Ok(planes)
            }
            #[cfg(not(target_arch = "wasm32"))]
            Base::Store { cache, .. } => {
                let c = cache
                    .chunk(u64::from(cy), u64::from(cx))
                    .map_err(|e| e.to_string())?;
                Ok(Planes {
                    heights: c.heights.clone(),
                    metas: c.metas.clone(),
                })
            }
            Base::Remote(remote) => {
                let p = remote.cached(0, cx, cy).ok_or_else(|| {
                    format!("chunk ({cx}, {cy}) of the streamed store has not been fetched yet")
                })?;
                Ok(Planes {
                    heights: p.0.clone(),
                    metas: p.1.clone(),
                })
            }
        }
    }

    /// Chunk (`cx`, `cy`) as the session sees it: edited, else the world's.
    pub fn planes(&self, cx: u32, cy: u32) -> Result<Arc<Planes>, String> {
        let index = cy * self.grid().0 + cx;
        if let Some(p) = self.edited.lock().expect("edit lock").get(&index) {
            return Ok(p.clone());
        }
        self.base_planes(cx, cy).map(Arc::new)
    }

    /// The column at texel (`x`, `y`), wrapping (one chunk read).
    pub fn column(&self, x: i64, y: i64) -> Result<Column, String> {
        let (w, h) = self.size;
        let (x, y) = (x.rem_euclid(i64::from(w)), y.rem_euclid(i64::from(h)));
        let (cx, cy) = ((x / i64::from(PAGE)) as u32, (y / i64::from(PAGE)) as u32);
        let p = self.planes(cx, cy)?;
        let chunk = Level::from_planes(
            PAGE,
            PAGE,
            p.heights.clone(),
            p.metas.clone(),
            self.mid_rule,
        )
        .map_err(|e| e.to_string())?;
        Ok(chunk.column(x % i64::from(PAGE), y % i64::from(PAGE)))
    }

    /// Cut `site`'s crater into the chunks it touches (a window of them,
    /// whole chunks a side, as a small level); they go into the edit layer.
    pub fn dig(&self, site: &EditSite) -> anyhow::Result<Dug> {
        let rect = crater_rect(site);
        let page = i64::from(PAGE);
        let (gx, gy) = self.grid();
        // One texel of margin each side: edits widen to whole texel pairs.
        let span = |start: i64, len: u32, chunks: u32| -> anyhow::Result<(i64, u32)> {
            let first = (start - 1).div_euclid(page);
            let last = (start + i64::from(len)).div_euclid(page);
            let n = ((last - first + 1) as u32).next_power_of_two();
            if n > chunks {
                anyhow::bail!(
                    "a crater of radius {} spans more chunks than this world has ({}x{})",
                    site.radius,
                    gx,
                    gy
                );
            }
            Ok((first, n))
        };
        let (x0, nx) = span(rect.x, rect.width, gx)?;
        let (y0, ny) = span(rect.y, rect.height, gy)?;
        let (ww, wh) = (nx * PAGE, ny * PAGE);
        let global = |i: u32, j: u32| {
            let cx = (x0 + i64::from(i)).rem_euclid(i64::from(gx)) as u32;
            let cy = (y0 + i64::from(j)).rem_euclid(i64::from(gy)) as u32;
            (cx, cy)
        };
        let mut heights = vec![0u8; (ww * wh) as usize];
        let mut metas = vec![0u8; (ww * wh) as usize];
        let mut before = HashMap::new();
        for j in 0..ny {
            for i in 0..nx {
                let (cx, cy) = global(i, j);
                let p = self
                    .planes(cx, cy)
                    .map_err(|e| anyhow::anyhow!("reading chunk ({cx}, {cy}) to dig: {e}"))?;
                for r in 0..PAGE {
                    let src = (r * PAGE) as usize..((r + 1) * PAGE) as usize;
                    let at = ((j * PAGE + r) * ww + i * PAGE) as usize;
                    heights[at..at + PAGE as usize].copy_from_slice(&p.heights[src.clone()]);
                    metas[at..at + PAGE as usize].copy_from_slice(&p.metas[src]);
                }
                before.insert((i, j), p);
            }
        }
        let mut window = Level::from_planes(ww, wh, heights, metas, self.mid_rule)?;
        let local = EditSite {
            centre_x: site.centre_x - x0 * page,
            centre_y: site.centre_y - y0 * page,
            ..site.clone()
        };
        let dirty = crater(&mut window, &local);
        let mut touched = Vec::new();
        for r in &dirty {
            for j in r.y / PAGE..(r.y + r.height).div_ceil(PAGE) {
                for i in r.x / PAGE..(r.x + r.width).div_ceil(PAGE) {
                    touched.push((i, j));
                }
            }
        }
        touched.sort_unstable();
        touched.dedup();
        let mut dug = Dug::default();
        let mut edited = self.edited.lock().expect("edit lock");
        for (i, j) in touched {
            let mut planes = Planes {
                heights: Vec::with_capacity((PAGE * PAGE) as usize),
                metas: Vec::with_capacity((PAGE * PAGE) as usize),
            };
            for r in 0..PAGE {
                let at = ((j * PAGE + r) * ww + i * PAGE) as usize;
                let row = at..at + PAGE as usize;
                planes
                    .heights
                    .extend_from_slice(&window.heights()[row.clone()]);
                planes.metas.extend_from_slice(&window.metas()[row]);
            }
            let (cx, cy) = global(i, j);
            let index = cy * gx + cx;
            edited.insert(index, Arc::new(planes));
            dug.chunks.push(index);
            dug.before.push((index, before[&(i, j)].clone()));
        }
        Ok(dug)
    }

    /// Put chunks back as they were (undo); returns their indices. A chunk
    /// back to the world's own bytes leaves the edit layer.
    pub fn restore(&self, before: Vec<(u32, Arc<Planes>)>) -> Vec<u32> {
        let gx = self.grid().0;
        before
            .into_iter()
            .map(|(index, planes)| {
                let unedited = self
                    .base_planes(index % gx, index / gx)
                    .is_ok_and(|b| b == *planes);
                let mut edited = self.edited.lock().expect("edit lock");
                if unedited {
                    edited.remove(&index);
                } else {
                    edited.insert(index, planes);
                }
                index
            })
            .collect()
    }

    /// The world in memory with the edits in it (a world in memory only;
    /// the layer is then folded into it).
    pub fn edited_level(&self) -> anyhow::Result<Level> {
        let mut base = self.base.lock().expect("base lock");
        // Irrefutable in a browser, where a store is not a base.
        #[allow(irrefutable_let_patterns)]
        let Base::Level(level) = &*base else {
            anyhow::bail!("a store is saved chunk by chunk, not as a level");
        };
        let mut edited = self.edited.lock().expect("edit lock");
        let (w, gx) = (level.width() as usize, self.grid().0);
        let mut heights = level.heights().to_vec();
        let mut metas = level.metas().to_vec();
        for (&index, p) in edited.iter() {
            let (x0, y0) = ((index % gx * PAGE) as usize, (index / gx * PAGE) as usize);
            for r in 0..PAGE as usize {
                let src = r * PAGE as usize..(r + 1) * PAGE as usize;
                let at = (y0 + r) * w + x0;
                heights[at..at + PAGE as usize].copy_from_slice(&p.heights[src.clone()]);
                metas[at..at + PAGE as usize].copy_from_slice(&p.metas[src]);
            }
        }
        let out = Level::from_planes(level.width(), level.height(), heights, metas, self.mid_rule)?;
        *base = Base::Level(Arc::new(out.clone()));
        edited.clear();
        Ok(out)
    }

    /// Write the edited chunks into the store in `dir` (the store this
    /// world was opened from), all or nothing; the layer is then empty and
    /// the chunks are read from the store again. Returns a line for the log.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn save_store(&self, dir: &std::path::Path, overwrite: bool) -> anyhow::Result<String> {
        use anyhow::Context;
        let start = web_time::Instant::now();
        let base = self.base.lock().expect("base lock");
        let Base::Store { cache, dir: source } = &*base else {
            anyhow::bail!("not a store");
        };
        let same = matches!((source.canonicalize(), dir.canonicalize()), (Ok(a), Ok(b)) if a == b);
        if !same {
            anyhow::bail!(
                "a store drawn paged is saved in place only ({}); {} is another directory (copy the store there first)",
                source.display(),
                dir.display()
            );
        }
        if !overwrite {
            anyhow::bail!(
                "{} is the store this session loaded; saving over it needs --overwrite",
                dir.display()
            );
        }
        let mut edited = self.edited.lock().expect("edit lock");
        let gx = self.grid().0;
        let mut chunks: Vec<(u64, u64, strata_store::Chunk)> = edited
            .iter()
            .map(|(&index, p)| {
                (
                    u64::from(index / gx),
                    u64::from(index % gx),
                    strata_store::Chunk {
                        rows: PAGE,
                        cols: PAGE,
                        heights: p.heights.clone(),
                        metas: p.metas.clone(),
                    },
                )
            })
            .collect();
        chunks.sort_unstable_by_key(|c| (c.0, c.1));
        let store = strata_store::DirStore::open(dir)
            .with_context(|| format!("opening the store in {}", dir.display()))?;
        store
            .commit_chunks(&chunks)
            .with_context(|| format!("saving the edits into the store {}", dir.display()))?;
        let cells: Vec<(u64, u64)> = chunks.iter().map(|c| (c.0, c.1)).collect();
        cache.invalidate(&cells);
        edited.clear();
        Ok(format!(
            "saved {} edited chunk(s) into the store {} (all or nothing) in {:.2} s",
            cells.len(),
            dir.display(),
            start.elapsed().as_secs_f64()
        ))
    }
}

impl PageSource for EditedPages {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn mid_rule(&self) -> MidRule {
        self.mid_rule
    }

    fn chunk_tops(&self) -> Result<Vec<u8>, String> {
        let mut tops = match &*self.base.lock().expect("base lock") {
            Base::Level(level) => strata_render::paged::LevelPages::new(level.clone())
                .map_err(|e| e.to_string())?
                .chunk_tops()?,
            #[cfg(not(target_arch = "wasm32"))]
            Base::Store { cache, .. } => {
                strata_render::paged::StorePages::new(cache.clone(), self.mid_rule)
                    .map_err(|e| e.to_string())?
                    .chunk_tops()?
            }
            Base::Remote(remote) => remote.chunk_tops()?,
        };
        for (&index, p) in self.edited.lock().expect("edit lock").iter() {
            tops[index as usize] =
                PageData::from_planes(&p.heights, &p.metas, self.mid_rule, 1)?.top(1);
        }
        Ok(tops)
    }

    fn read_page(&self, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        let p = self.planes(cx, cy)?;
        PageData::from_planes(&p.heights, &p.metas, self.mid_rule, step)
    }

    fn async_pages(&self) -> Option<&dyn AsyncPages> {
        self.remote.as_ref().map(|_| self as &dyn AsyncPages)
    }
}

/// A streamed store's reads, with the session's edits over what they bring.
impl AsyncPages for EditedPages {
    fn want(&self, pages: &[PageRef]) {
        if let Some(remote) = &self.remote {
            remote.want(pages);
        }
    }

    fn take_finished(
        &self,
        most: usize,
    ) -> Vec<(u32, Result<strata_render::paged::Planes, String>)> {
        let Some(remote) = &self.remote else {
            return Vec::new();
        };
        let edited = self.edited.lock().expect("edit lock");
        remote
            .take_finished(most)
            .into_iter()
            .map(|(id, read)| match edited.get(&id) {
                Some(p) => (id, Ok((p.heights.clone(), p.metas.clone()))),
                None => (id, read),
            })
            .collect()
    }

    fn in_flight(&self) -> usize {
        self.remote.as_ref().map_or(0, |r| r.in_flight())
    }

    fn is_in_flight(&self, id: u32) -> bool {
        self.remote.as_ref().is_some_and(|r| r.is_in_flight(id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world() -> Level {
        strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 5,
            width: 1024,
            height: 512,
        })
        .unwrap()
        .level
    }

    #[test]
    fn a_dig_through_the_layer_equals_the_same_crater_on_the_whole_level() {
        let level = world();
        let pages = EditedPages::new(Base::Level(Arc::new(level.clone())), level.mid_rule).unwrap();
        // Across a chunk corner and across the world's wrap.
        for (x, y, r) in [(256, 255, 20), (1020, 3, 30), (600, 300, 100)] {
            let site = EditSite {
                centre_x: x,
                centre_y: y,
                radius: r,
                depth: 30.0,
                ..EditSite::fostral()
            };
            let mut whole = level.clone();
            crater(&mut whole, &site);
            let fresh =
                EditedPages::new(Base::Level(Arc::new(level.clone())), level.mid_rule).unwrap();
            let dug = fresh.dig(&site).unwrap();
            assert!(!dug.chunks.is_empty());
            assert_eq!(
                fresh.edited_level().unwrap(),
                whole,
                "crater at {x},{y} r {r}"
            );
        }
        // Undo puts the chunks back.
        let site = EditSite {
            centre_x: 512,
            centre_y: 256,
            radius: 40,
            ..EditSite::fostral()
        };
        let dug = pages.dig(&site).unwrap();
        assert_eq!(dug.chunks.len(), 4, "a crater on a chunk corner touches 4");
        let page = pages.read_page(2, 1, 1).unwrap();
        assert_ne!(
            page,
            LevelPagesTwin::page(&level, 2, 1),
            "the edit shows in the page"
        );
        assert_eq!(pages.edited_chunks(), 4);
        pages.restore(dug.before);
        assert_eq!(pages.edited_chunks(), 0, "undone chunks leave the layer");
        assert_eq!(
            pages.read_page(2, 1, 1).unwrap(),
            LevelPagesTwin::page(&level, 2, 1)
        );
        assert_eq!(pages.edited_level().unwrap(), level);
        assert!(pages.column(512, 256).unwrap() == level.column(512, 256));
        // A crater wider than the world is refused, not a panic.
        let huge = EditSite {
            radius: 5000,
            ..site
        };
        assert!(pages.dig(&huge).is_err());
    }

    struct LevelPagesTwin;
    impl LevelPagesTwin {
        fn page(level: &Level, cx: u32, cy: u32) -> PageData {
            strata_render::paged::LevelPages::new(Arc::new(level.clone()))
                .unwrap()
                .read_page(cx, cy, 1)
                .unwrap()
        }
    }
}
