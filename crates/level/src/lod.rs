//! Coarser copies of a world for level of detail (issue 33): level k holds
//! one texel per 2^k x 2^k block of the map, in the same two planes and
//! pair encoding, so every reader of the map reads them unchanged.
//!
//! A coarse texel pair is a *copy* of one pair of the level below, the one
//! with the highest top among the 2x2 pairs it stands for: heights and metas
//! (terrain types, the dual flag, the mid code) come along together, so a
//! dual pair stays a valid dual pair. Level k is made from level k-1, so a
//! pair of level k is the highest-topped pair of its 2^k x 2^k block of
//! pairs up to ties. No average is taken: a far peak keeps its height (the
//! top silhouette is the highest of what it stands for), and a slab over a
//! cave stays a slab rather than a blur of floor and slab. What is lost is
//! everything narrower than a block beside the kept pair; renderers that
//! draw these levels measure that error (see `strata fly`).

use crate::model::pair_is_dual;

/// The highest top of a texel pair: the odd texel's height (the slab's top)
/// for a dual pair, else the higher of the two single columns.
#[inline]
pub fn pair_top(h_even: u8, h_odd: u8, m_even: u8, m_odd: u8) -> u8 {
    if pair_is_dual(m_even, m_odd) {
        h_odd
    } else {
        h_even.max(h_odd)
    }
}

/// Halve planes of `width` x `height` texels (`width` a multiple of 4,
/// `height` even): the level above, `width / 2` x `height / 2`. Each output
/// pair copies the input pair with the highest [`pair_top`] among the four
/// it stands for, the first of equals in the order (left, top), (right,
/// top), (left, bottom), (right, bottom).
pub fn halve(heights: &[u8], metas: &[u8], width: usize, height: usize) -> (Vec<u8>, Vec<u8>) {
    assert!(
        width.is_multiple_of(4) && height.is_multiple_of(2),
        "halve needs a width that is a multiple of 4 and an even height, got {width}x{height}"
    );
    assert!(heights.len() == width * height && metas.len() == width * height);
    let (ow, oh) = (width / 2, height / 2);
    let mut out_h = vec![0u8; ow * oh];
    let mut out_m = vec![0u8; ow * oh];
    for r in 0..oh {
        for j in 0..ow / 2 {
            let mut best = (0usize, None::<u8>);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let i = (2 * r + dy) * width + 2 * (2 * j + dx);
                let top = pair_top(heights[i], heights[i + 1], metas[i], metas[i + 1]);
                if best.1.is_none_or(|b| top > b) {
                    best = (i, Some(top));
                }
            }
            let (i, o) = (best.0, r * ow + 2 * j);
            out_h[o..o + 2].copy_from_slice(&heights[i..i + 2]);
            out_m[o..o + 2].copy_from_slice(&metas[i..i + 2]);
        }
    }
    (out_h, out_m)
}

/// Most coarse levels kept: level 8 stands one texel for a 256-texel tile,
/// the coarsest tile the renderers' pyramids keep anyway.
pub const MAX_LOD: u32 = 8;

/// Coarse levels a map of `width` x `height` texels in chunks of
/// `chunk_width` x `chunk_height` can have: until a level is one chunk
/// across or down, at most [`MAX_LOD`]; none when the chunk width is not a
/// multiple of 4 or its height odd (pairs are halved).
pub fn possible_levels(width: u32, height: u32, chunk_width: u32, chunk_height: u32) -> u32 {
    if !chunk_width.is_multiple_of(4) || !chunk_height.is_multiple_of(2) || chunk_width == 0 {
        return 0;
    }
    let (gy, gx) = (height / chunk_height, width / chunk_width);
    gy.min(gx).max(1).ilog2().min(MAX_LOD)
}

/// One `side` x `side` chunk of a coarser level from the four chunks of the
/// level below it covers, `[top-left, top-right, bottom-left,
/// bottom-right]`, each `side` x `side` planes `(heights, metas)`.
pub fn merge_quad(quad: [(&[u8], &[u8]); 4], side: usize) -> (Vec<u8>, Vec<u8>) {
    let half = side / 2;
    let mut out_h = vec![0u8; side * side];
    let mut out_m = vec![0u8; side * side];
    for (q, (h, m)) in quad.into_iter().enumerate() {
        let (hh, mm) = halve(h, m, side, side);
        let (ox, oy) = ((q % 2) * half, (q / 2) * half);
        for y in 0..half {
            let dst = (oy + y) * side + ox;
            out_h[dst..dst + half].copy_from_slice(&hh[y * half..(y + 1) * half]);
            out_m[dst..dst + half].copy_from_slice(&mm[y * half..(y + 1) * half]);
        }
    }
    (out_h, out_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MidRule;
    use crate::model::{META_DOUBLE_LEVEL, decode_column};

    #[test]
    fn a_dual_pair_wins_by_its_slab_top_and_moves_whole() {
        // 4x2 texels: pairs (0,0) single 10/20, (1,0) dual 5..200,
        // (0,1) single 100/3, (1,1) single 7/7.
        let d = META_DOUBLE_LEVEL | 0b1000_0001;
        let heights = [10, 20, 5, 200, 100, 3, 7, 7];
        let metas = [0, 0, d, d, 0, 0, 0, 0];
        let (h, m) = halve(&heights, &metas, 4, 2);
        assert_eq!(h, vec![5, 200]);
        assert_eq!(m, vec![d, d]);
        let c = decode_column(&h, &m, 0, MidRule::Original);
        assert!(c.dual && c.low == 5 && c.high == 200);
    }

    #[test]
    fn ties_keep_the_first_pair_and_tops_never_drop() {
        let heights = [9, 1, 9, 2, 3, 9, 0, 0];
        let metas = [1, 2, 3, 4, 5, 6, 7, 8];
        let (h, m) = halve(&heights, &metas, 4, 2);
        assert_eq!((h, m), (vec![9, 1], vec![1, 2]));
        // The highest top of a random map survives every halving.
        let mut s = 12345u32;
        let mut next = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 24) as u8
        };
        let n = 64;
        let hs: Vec<u8> = (0..n * n).map(|_| next()).collect();
        let ms: Vec<u8> = (0..n * n).map(|_| next() & !META_DOUBLE_LEVEL).collect();
        let top = *hs.iter().max().unwrap();
        let (mut h, mut m, mut side) = (hs, ms, n);
        while side >= 4 {
            (h, m) = halve(&h, &m, side, side);
            side /= 2;
            assert_eq!(*h.iter().max().unwrap(), top);
        }
    }

    #[test]
    fn a_quad_is_its_four_halves_side_by_side() {
        let side = 8;
        let planes: Vec<(Vec<u8>, Vec<u8>)> = (0..4u8)
            .map(|q| {
                let h = (0..side * side)
                    .map(|i| (i as u8).wrapping_mul(3) ^ q)
                    .collect();
                (h, vec![0u8; side * side])
            })
            .collect();
        let quad = [0, 1, 2, 3].map(|q| (planes[q].0.as_slice(), planes[q].1.as_slice()));
        let (h, _) = merge_quad(quad, side);
        let (h1, _) = halve(&planes[1].0, &planes[1].1, side, side);
        // Quadrant 1 lands at the top right.
        for y in 0..side / 2 {
            assert_eq!(
                &h[y * side + side / 2..(y + 1) * side],
                &h1[y * side / 2..(y + 1) * side / 2]
            );
        }
    }
}
