//! Dirty rectangles merged into a few bounding boxes before a pyramid update
//! dispatches for them: each rectangle costs a dispatch per level (and a
//! barrier), which for a game's frame of many small edits costs far more
//! than the extra texels a bounding box recomputes. Exact either way: every
//! texel of the input stays covered.

use strata_level::DirtyRect;
use strata_occupancy::TileRange;

/// An axis-aligned box that can be merged with another.
pub(crate) trait Box2 {
    /// Cells covered.
    fn area(&self) -> u64;
    /// The bounding box of both.
    fn union(&self, other: &Self) -> Self;
}

impl Box2 for DirtyRect {
    fn area(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
    fn union(&self, b: &Self) -> Self {
        let (x0, y0) = (self.x.min(b.x), self.y.min(b.y));
        let x1 = (self.x + self.width).max(b.x + b.width);
        let y1 = (self.y + self.height).max(b.y + b.height);
        DirtyRect {
            x: x0,
            y: y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }
}

impl Box2 for TileRange {
    fn area(&self) -> u64 {
        u64::from(self.x1 - self.x0 + 1) * u64::from(self.y1 - self.y0 + 1)
    }
    fn union(&self, b: &Self) -> Self {
        TileRange {
            x0: self.x0.min(b.x0),
            y0: self.y0.min(b.y0),
            x1: self.x1.max(b.x1),
            y1: self.y1.max(b.y1),
        }
    }
}

/// Merge boxes until at most `cap` are left, each time the pair whose
/// bounding box adds the fewest cells beyond the two (duplicates and
/// overlaps first).
pub(crate) fn coalesce<B: Box2>(boxes: &mut Vec<B>, cap: usize) {
    while boxes.len() > cap.max(1) {
        let mut best = (u64::MAX, 0, 1);
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                let extra = boxes[i]
                    .union(&boxes[j])
                    .area()
                    .saturating_sub(boxes[i].area() + boxes[j].area());
                if extra < best.0 {
                    best = (extra, i, j);
                }
            }
        }
        let (_, i, j) = best;
        let merged = boxes[i].union(&boxes[j]);
        boxes.swap_remove(j);
        boxes[i] = merged;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coalescing_keeps_every_texel_and_merges_neighbours_first() {
        let r = |x, y, width, height| DirtyRect {
            x,
            y,
            width,
            height,
        };
        // Two clusters of track stamps far apart, and one lone stamp.
        let mut rects: Vec<DirtyRect> = (0..20)
            .map(|k| r(100 + 2 * k, 50, 5, 5))
            .chain((0..20).map(|k| r(1000, 2000 + 3 * k, 7, 7)))
            .chain([r(4000, 100, 3, 3)])
            .collect();
        let before = rects.clone();
        coalesce(&mut rects, 3);
        assert_eq!(rects.len(), 3);
        for b in &before {
            assert!(
                rects.iter().any(|m| m.x <= b.x
                    && m.y <= b.y
                    && m.x + m.width >= b.x + b.width
                    && m.y + m.height >= b.y + b.height),
                "{b:?} lost"
            );
        }
        let texels: u64 = rects
            .iter()
            .map(|m| u64::from(m.width) * u64::from(m.height))
            .sum();
        // The three clusters' boxes: 43x5 + 7x64 + 3x3, not the map.
        assert_eq!(texels, 43 * 5 + 7 * 64 + 9);
        let mut few = before[..2].to_vec();
        coalesce(&mut few, 3);
        assert_eq!(few, before[..2]);
    }
}
