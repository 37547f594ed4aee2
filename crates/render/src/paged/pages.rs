//! Page ids: one number per page of every level the paged terrain draws,
//! the map's chunks first (id = `cy * across + cx`, as before there were
//! levels), then each coarser level's pages (`strata_level::lod`: level k
//! is the map halved k times, cut in pages of the same 256x256 texels, so a
//! page of level k covers 256 * 2^k texels of the map a side). The page
//! table, the feedback's stamps and requests, and the residency all count
//! in these ids; `paged.wgsl`'s `paged_page` is the GPU twin of [`PageIds::id`].

use super::source::PAGE;

/// Most levels: the map and 8 coarser ones (`strata_level::lod::MAX_LOD`).
const MAX_LEVELS: usize = 9;

/// The id space of a world's pages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageIds {
    /// Chunks across and down (level 0's pages).
    grid: (u32, u32),
    /// Coarse levels (0: the map's chunks only).
    levels: u32,
    /// The first id of each level, then the total.
    first: [u32; MAX_LEVELS + 1],
}

impl PageIds {
    /// Ids for a grid of `grid` chunks and `levels` coarse levels (clamped
    /// to what the grid allows: a level at least one page across and down).
    pub fn new(grid: (u32, u32), levels: u32) -> Self {
        let most = grid.0.min(grid.1).max(1).ilog2();
        let levels = levels.min(most).min(MAX_LEVELS as u32 - 1);
        let mut first = [0u32; MAX_LEVELS + 1];
        let mut next = 0;
        for (k, f) in first.iter_mut().enumerate() {
            *f = next;
            if k as u32 <= levels {
                next += (grid.0 >> k) * (grid.1 >> k);
            }
        }
        PageIds {
            grid,
            levels,
            first,
        }
    }

    /// Coarse levels.
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// The map's chunks (the ids below this are level 0).
    pub fn chunks(&self) -> u32 {
        self.grid.0 * self.grid.1
    }

    /// Pages of every level.
    pub fn total(&self) -> u32 {
        self.first[self.levels as usize + 1]
    }

    /// Pages across and down at `level`.
    pub fn grid(&self, level: u32) -> (u32, u32) {
        (self.grid.0 >> level, self.grid.1 >> level)
    }

    /// The id of page (`cx`, `cy`) of `level`.
    pub fn id(&self, level: u32, cx: u32, cy: u32) -> u32 {
        self.first[level as usize] + cy * (self.grid.0 >> level) + cx
    }

    /// Level, column and row of page `id` (`None` past the last).
    pub fn locate(&self, id: u32) -> Option<(u32, u32, u32)> {
        if id >= self.total() {
            return None;
        }
        let level = (0..=self.levels)
            .rev()
            .find(|&k| id >= self.first[k as usize])?;
        let i = id - self.first[level as usize];
        let across = self.grid.0 >> level;
        Some((level, i % across, i / across))
    }

    /// The first id of each level for `PagedParams::lod_pages`
    /// (`[k / 4][k % 4]`).
    pub fn first_ids(&self) -> [[u32; 4]; 3] {
        let mut out = [[0u32; 4]; 3];
        // Levels 0..=8 fill 9 of the 12 places.
        for k in 0..MAX_LEVELS {
            out[k / 4][k % 4] = self.first[k];
        }
        out
    }

    /// The coarse pages over chunk `chunk`, one per level.
    pub fn above(&self, chunk: u32) -> impl Iterator<Item = u32> + '_ {
        let (cx, cy) = (chunk % self.grid.0, chunk / self.grid.0);
        (1..=self.levels).map(move |k| self.id(k, cx >> k, cy >> k))
    }

    /// Squared distance from `eye` to the nearest wrapped copy of page
    /// `id`'s centre, in texels (pages of coarser levels are larger).
    pub fn distance(&self, eye: glam::Vec2, id: u32) -> f32 {
        let Some((level, cx, cy)) = self.locate(id) else {
            return f32::MAX;
        };
        let side = (PAGE << level) as f32;
        let axis = |i: u32, n: u32, e: f32| {
            let span = (n * PAGE) as f32;
            let d = (i as f32 + 0.5) * side - e;
            d - span * (d / span).round()
        };
        let dx = axis(cx, self.grid.0, eye.x);
        let dy = axis(cy, self.grid.1, eye.y);
        dx * dx + dy * dy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_round_trip_and_levels_stop_at_one_page() {
        let ids = PageIds::new((8, 64), 8);
        // 8 across: levels 1, 2, 3 (1 page across at 3).
        assert_eq!(ids.levels(), 3);
        assert_eq!(ids.total(), 8 * 64 + 4 * 32 + 2 * 16 + 8);
        for id in 0..ids.total() {
            let (k, cx, cy) = ids.locate(id).unwrap();
            assert_eq!(ids.id(k, cx, cy), id);
        }
        assert_eq!(ids.locate(ids.total()), None);
        assert_eq!(ids.id(0, 3, 2), 2 * 8 + 3);
        let above: Vec<u32> = ids.above(ids.id(0, 5, 9)).collect();
        assert_eq!(
            above,
            vec![ids.id(1, 2, 4), ids.id(2, 1, 2), ids.id(3, 0, 1)]
        );
        assert_eq!(PageIds::new((8, 8), 0).total(), 64);
    }
}
