//! The CPU side of residency, no GPU: how a byte budget becomes atlas slots
//! ([`BudgetPlan`]), and which chunk each slot holds ([`Residency`]: the page
//! table the GPU reads, least-recently-used eviction by the frames' own
//! record of the slots they read).

use super::source::PAGE;

/// Bytes of one page in the atlas: `PAGE / 2` pair texels of 4 bytes by
/// `PAGE` rows.
pub const PAGE_ATLAS_BYTES: u64 = (PAGE as u64 / 2) * PAGE as u64 * 4;

/// Words at the start of the feedback buffer: pending pixels, request
/// count, pending shadow-map texels.
pub const FEEDBACK_HEADER: u32 = 3;

/// Most page requests one frame records (more wait for the next frame).
pub const MAX_REQUESTS: u32 = 1024;

/// Most pages an atlas layer holds: 16 across, 8 down (2048x2048 pair
/// texels, 16 MiB), inside WebGPU's default texture limits.
const MAX_PER_LAYER: u32 = 128;

/// How a GPU budget is spent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct BudgetPlan {
    /// The budget asked for, bytes.
    pub budget: u64,
    /// Chunks in the world.
    pub chunks: u32,
    /// Pages of every level ([`super::PageIds::total`]; the chunks when
    /// there is no level of detail): the page table's and the feedback
    /// stamps' length.
    pub pages: u32,
    /// Atlas slots (pages resident at most).
    pub slots: u32,
    /// log2 of pages across one atlas layer.
    pub across_log2: u32,
    /// log2 of pages per atlas layer.
    pub per_layer_log2: u32,
    /// Atlas layers.
    pub layers: u32,
    /// Bytes of one slot's pyramid.
    pub pyramid_stride: u32,
    /// Bytes of the atlas texture.
    pub atlas_bytes: u64,
    /// Bytes of the level buffer: the coarse level (chunk tops, padded to 4)
    /// then every slot's pyramid.
    pub levels_bytes: u64,
    /// Bytes of the page table (a word per page).
    pub table_bytes: u64,
    /// Bytes of the feedback buffer (header, request list, slot and page
    /// stamps) and of its read-back copy.
    pub feedback_bytes: u64,
    /// Bytes of the parameters uniform.
    pub params_bytes: u64,
}

impl BudgetPlan {
    /// Everything the plan keeps on the GPU; never above [`BudgetPlan::budget`].
    pub fn total(&self) -> u64 {
        self.atlas_bytes
            + self.levels_bytes
            + self.table_bytes
            + self.feedback_bytes
            + self.params_bytes
    }

    /// Bytes that do not depend on the slots.
    fn fixed(chunks: u32, pages: u32, params_bytes: u64) -> u64 {
        let tops = u64::from(chunks.div_ceil(4) * 4);
        let table = 4 * u64::from(pages);
        // Feedback: header, request list, page stamps; its read-back copy
        // holds the header and the list.
        let feedback = 4 * u64::from(FEEDBACK_HEADER + MAX_REQUESTS + pages)
            + 4 * u64::from(FEEDBACK_HEADER + MAX_REQUESTS);
        tops + table + feedback + params_bytes
    }

    /// Bytes each slot costs: its atlas page, its pyramid, its stamp (and
    /// the stamp's read-back copy).
    fn per_slot(pyramid_stride: u32) -> u64 {
        PAGE_ATLAS_BYTES + u64::from(pyramid_stride) + 8
    }

    /// The smallest budget that works for a world of `chunks` chunks and
    /// `pages` pages of every level: the fixed part and two slots (an atlas
    /// has at least two layers; see `terrain.rs` on GL).
    pub fn smallest(chunks: u32, pages: u32, pyramid_stride: u32, params_bytes: u64) -> u64 {
        Self::fixed(chunks, pages, params_bytes) + 2 * Self::per_slot(pyramid_stride)
    }

    /// Spend `budget` bytes on a world of `chunks` chunks and `pages` pages
    /// of every level (at least `chunks`), whose pages have
    /// pyramids of `pyramid_stride` bytes, within `max_layers` texture
    /// layers and `max_binding` bytes of storage binding. A budget below
    /// [`BudgetPlan::smallest`] is refused, naming that size.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        budget: u64,
        chunks: u32,
        pages: u32,
        pyramid_stride: u32,
        params_bytes: u64,
        max_layers: u32,
        max_binding: u64,
    ) -> Result<Self, String> {
        let pages = pages.max(chunks);
        let smallest = Self::smallest(chunks, pages, pyramid_stride, params_bytes);
        if budget < smallest {
            return Err(format!(
                "a GPU budget of {budget} bytes cannot hold the coarse level, page table and feedback of {chunks} chunks plus two pages; the smallest budget that works is {smallest} bytes ({:.2} MiB)",
                smallest as f64 / 1048576.0
            ));
        }
        let fixed = Self::fixed(chunks, pages, params_bytes);
        let per_slot = Self::per_slot(pyramid_stride);
        let tops = u64::from(chunks.div_ceil(4) * 4);
        // No more slots than chunks, layers or the level buffer's binding allow.
        let by_binding =
            (max_binding.saturating_sub(tops) / u64::from(pyramid_stride.max(1))) as u32;
        let most = (((budget - fixed) / per_slot) as u32)
            .min(pages.max(2))
            .min(by_binding)
            .min(max_layers.saturating_mul(MAX_PER_LAYER));
        if most < 2 {
            return Err(format!(
                "this adapter's limits leave room for {most} pages ({max_layers} texture layers, {max_binding} bytes per storage binding)"
            ));
        }
        // Pages per layer: a power of two, at most half the slots (two layers
        // at least), at most MAX_PER_LAYER.
        let per_layer = (1u32 << (most / 2).ilog2()).min(MAX_PER_LAYER);
        let layers = (most / per_layer).min(max_layers);
        let slots = per_layer * layers;
        let across = per_layer.min(16);
        let plan = BudgetPlan {
            budget,
            chunks,
            pages,
            slots,
            across_log2: across.ilog2(),
            per_layer_log2: per_layer.ilog2(),
            layers,
            pyramid_stride,
            atlas_bytes: u64::from(slots) * PAGE_ATLAS_BYTES,
            levels_bytes: tops + u64::from(slots) * u64::from(pyramid_stride),
            table_bytes: 4 * u64::from(pages),
            feedback_bytes: 4 * u64::from(FEEDBACK_HEADER + MAX_REQUESTS + pages + slots)
                + 4 * u64::from(FEEDBACK_HEADER + MAX_REQUESTS + slots),
            params_bytes,
        };
        debug_assert!(plan.total() <= budget, "{plan:?}");
        Ok(plan)
    }

    /// Pages across and down one atlas layer.
    pub fn layer_pages(&self) -> (u32, u32) {
        let across = 1 << self.across_log2;
        (across, (1 << self.per_layer_log2) / across)
    }

    /// Where slot `slot` lies: layer, and its first pair texel (x, y) there.
    pub fn slot_origin(&self, slot: u32) -> (u32, u32, u32) {
        let layer = slot >> self.per_layer_log2;
        let in_layer = slot & ((1 << self.per_layer_log2) - 1);
        let across = 1 << self.across_log2;
        (
            layer,
            (in_layer % across) * (PAGE / 2),
            (in_layer / across) * PAGE,
        )
    }
}

/// Which chunk each slot holds, and since when it was last read.
#[derive(Clone, Debug)]
pub struct Residency {
    /// Per chunk: its slot + 1, or 0 (the page table as the GPU reads it).
    table: Vec<u32>,
    /// Per slot: its chunk, or `None` while free.
    slot_chunk: Vec<Option<u32>>,
    /// Per slot: the last frame stamp that read it (from the GPU's
    /// feedback) or that placed it.
    last_used: Vec<u32>,
}

/// A placement: the slot, and the chunk it held before (now evicted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The slot the page goes to.
    pub slot: u32,
    /// The chunk evicted from it, if the slot was taken.
    pub evicted: Option<u32>,
}

impl Residency {
    /// Nothing resident: `chunks` chunks, `slots` slots.
    pub fn new(chunks: u32, slots: u32) -> Self {
        Residency {
            table: vec![0; chunks as usize],
            slot_chunk: vec![None; slots as usize],
            last_used: vec![0; slots as usize],
        }
    }

    /// The page table: per chunk its slot + 1, or 0.
    pub fn table(&self) -> &[u32] {
        &self.table
    }

    /// The slot holding `chunk`.
    pub fn slot_of(&self, chunk: u32) -> Option<u32> {
        match self.table.get(chunk as usize) {
            Some(&e) if e != 0 => Some(e - 1),
            _ => None,
        }
    }

    /// Pages resident.
    pub fn resident(&self) -> usize {
        self.slot_chunk.iter().filter(|c| c.is_some()).count()
    }

    /// Slots in all.
    pub fn slots(&self) -> usize {
        self.slot_chunk.len()
    }

    /// Slot `slot` was read by the frame stamped `stamp`.
    pub fn touch(&mut self, slot: u32, stamp: u32) {
        if let Some(t) = self.last_used.get_mut(slot as usize)
            && stamp_after(stamp, *t)
        {
            *t = stamp;
        }
    }

    /// A slot for `chunk` at frame `stamp`: a free one, else the least
    /// recently read one that was not read at `keep_from` or later (pages in
    /// use: evicting them would make the view thrash). When every page is
    /// in use (the budget is smaller than what the view reads), the page
    /// farthest from the eye by `distance` makes room if it is farther than
    /// `chunk`: near terrain wins, and the far end stays pending. `None` when
    /// no page is farther.
    pub fn place(
        &mut self,
        chunk: u32,
        stamp: u32,
        keep_from: u32,
        distance: impl Fn(u32) -> f32,
    ) -> Option<Placement> {
        if let Some(slot) = self.slot_of(chunk) {
            self.touch(slot, stamp);
            return Some(Placement {
                slot,
                evicted: None,
            });
        }
        let slot = match self.slot_chunk.iter().position(Option::is_none) {
            Some(free) => free,
            None => {
                let (oldest, &t) = self
                    .last_used
                    .iter()
                    .enumerate()
                    .max_by_key(|(_, t)| stamp.wrapping_sub(**t))?;
                if t != keep_from && stamp_after(keep_from, t) {
                    oldest
                } else {
                    // Everything is in use: the farthest page, if farther.
                    let (far, d) = self
                        .slot_chunk
                        .iter()
                        .enumerate()
                        .filter_map(|(s, c)| c.map(|c| (s, distance(c))))
                        .max_by(|a, b| a.1.total_cmp(&b.1))?;
                    if d <= distance(chunk) {
                        return None;
                    }
                    far
                }
            }
        };
        let evicted = self.slot_chunk[slot].take();
        if let Some(old) = evicted {
            self.table[old as usize] = 0;
        }
        self.slot_chunk[slot] = Some(chunk);
        self.table[chunk as usize] = slot as u32 + 1;
        self.last_used[slot] = stamp;
        Some(Placement {
            slot: slot as u32,
            evicted,
        })
    }

    /// Drop `chunk` (its page failed to read, or an edit made it stale and
    /// it is not worth keeping).
    pub fn evict(&mut self, chunk: u32) -> Option<u32> {
        let slot = self.slot_of(chunk)?;
        self.table[chunk as usize] = 0;
        self.slot_chunk[slot as usize] = None;
        Some(slot)
    }
}

/// `a` is at or after `b` in wrapping frame stamps.
fn stamp_after(a: u32, b: u32) -> bool {
    a.wrapping_sub(b) < u32::MAX / 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_stay_within_the_budget_and_refuse_below_the_smallest() {
        for budget in [1u64 << 20, 3 << 20, 16 << 20, 256 << 20, 1 << 30] {
            for chunks in [4u32, 64, 512, 65536] {
                match BudgetPlan::new(budget, chunks, chunks, 21848, 64, 256, 128 << 20) {
                    Ok(p) => {
                        assert!(p.total() <= budget, "{p:?}");
                        assert!(p.slots >= 2 && p.layers >= 2, "{p:?}");
                        assert!(p.slots <= chunks.max(2), "{p:?}");
                    }
                    Err(e) => {
                        let smallest = BudgetPlan::smallest(chunks, chunks, 21848, 64);
                        assert!(budget < smallest || e.contains("limits"), "{e}");
                        assert!(
                            e.contains(&smallest.to_string()) || e.contains("limits"),
                            "{e}"
                        );
                        assert!(
                            BudgetPlan::new(smallest, chunks, chunks, 21848, 64, 256, 128 << 20)
                                .is_ok()
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn slots_tile_the_atlas_without_overlap() {
        let p = BudgetPlan::new(64 << 20, 1024, 1024, 21848, 64, 256, 128 << 20).unwrap();
        let (across, down) = p.layer_pages();
        let mut seen = std::collections::HashSet::new();
        for s in 0..p.slots {
            let (layer, x, y) = p.slot_origin(s);
            assert!(layer < p.layers && x < across * 128 && y < down * 256);
            assert!(seen.insert((layer, x, y)));
        }
    }

    #[test]
    fn eviction_is_least_recently_read_and_spares_pages_in_use() {
        let mut r = Residency::new(16, 3);
        // Distance from the eye: the chunk number.
        let d = |c: u32| c as f32;
        for (chunk, stamp) in [(0, 1), (1, 2), (2, 3)] {
            assert_eq!(r.place(chunk, stamp, stamp, d).unwrap().evicted, None);
        }
        // Chunk 0's slot read at frame 4: chunk 1 is the oldest.
        r.touch(r.slot_of(0).unwrap(), 4);
        let p = r.place(3, 5, 4, d).unwrap();
        assert_eq!(p.evicted, Some(1));
        assert_eq!(r.slot_of(1), None);
        assert_eq!(r.slot_of(3), Some(p.slot));
        // Every slot read at frame 6: only a page farther than the new one
        // may go.
        for c in [0, 2, 3] {
            r.touch(r.slot_of(c).unwrap(), 6);
        }
        assert_eq!(r.place(4, 7, 6, d), None);
        assert_eq!(r.resident(), 3);
        let p = r.place(1, 7, 6, d).unwrap();
        assert_eq!(p.evicted, Some(3));
        assert_eq!(r.table().iter().filter(|&&e| e != 0).count(), 3);
    }
}
