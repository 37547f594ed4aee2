//! The decoded terrain model: two byte planes and the rule that turns a
//! texel pair into one or two solid intervals (DESIGN §1).

use serde::{Deserialize, Serialize};

/// `meta` bit 7: baked shadow of the original renderer (ignored here).
pub const META_SHADOW: u8 = 0x80;
/// `meta` bit 6: set on both texels of a double-level pair.
pub const META_DOUBLE_LEVEL: u8 = 0x40;
/// `meta` bits 5..3: terrain type 0..7 (0 = water).
pub const META_TERRAIN_MASK: u8 = 0x38;
/// Shift of the terrain type in `meta` (`(meta & META_TERRAIN_MASK) >> 3`).
pub const META_TERRAIN_SHIFT: u8 = 3;
/// `meta` bit 2: object shadow (ignored here).
pub const META_OBJ_SHADOW: u8 = 0x04;
/// `meta` bits 1..0: two bits of the four-bit cave-gap code of a pair.
pub const META_DELTA_MASK: u8 = 0x03;

/// Number of terrain types a `meta` byte can name.
pub const TERRAIN_TYPES: usize = 8;

/// How the cave ceiling `mid` is derived from a pair's four-bit gap code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MidRule {
    /// The original game (`land.cpp`): `low + ((code + 1) << 3)`.
    #[default]
    Original,
    /// vange-rs: `low + (code << 3)`, for pixel-for-pixel comparisons with it.
    VangeRs,
}

impl MidRule {
    /// Offset of the cave ceiling above the floor for a gap code 0..15.
    pub fn gap(self, code: u8) -> u32 {
        let code = u32::from(code & 0x0f);
        match self {
            MidRule::Original => (code + 1) << 3,
            MidRule::VangeRs => code << 3,
        }
    }

    /// Inverse of [`gap`](Self::gap): the smallest code whose gap is at least
    /// `gap` units, clamped to the code range. Used by edits and the generator.
    pub fn code_for_gap(self, gap: u32) -> u8 {
        let code = match self {
            MidRule::Original => gap.div_ceil(8).saturating_sub(1),
            MidRule::VangeRs => gap.div_ceil(8),
        };
        code.min(15) as u8
    }
}

/// The solid intervals of one ground sample, decoded.
///
/// A single-level texel has `low == mid == high`. A dual one is solid in
/// `[0, low]` (the floor) and `[mid, high]` (the slab); the cave is the open
/// gap `(low, mid)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Column {
    /// Top of the floor `[0, low]`.
    pub low: u8,
    /// Bottom of the slab (the cave ceiling); `low` when single.
    pub mid: u8,
    /// Top of the slab; `low` when single.
    pub high: u8,
    /// Whether the column has a slab over a cave (its pair is double-level).
    pub dual: bool,
    /// Terrain type of the floor (the even texel of a dual pair).
    pub lower_type: u8,
    /// Terrain type of the slab (the odd texel of a dual pair).
    pub upper_type: u8,
}

impl Column {
    /// Is altitude `z` inside solid terrain? Height 0 is a real height: a
    /// texel of height 0 is solid at `z = 0` (the paper's second reference bug).
    #[inline]
    pub fn is_solid(&self, z: f32) -> bool {
        z <= f32::from(self.low)
            || (self.dual && f32::from(self.mid) <= z && z <= f32::from(self.high))
    }

    /// Altitude of the highest solid point.
    #[inline]
    pub fn top(&self) -> u8 {
        if self.dual { self.high } else { self.low }
    }
}

/// Is the texel pair containing an even `meta` byte and its odd neighbour a
/// dual pair? Decided once, here: both texels must carry the flag.
#[inline]
pub fn pair_is_dual(meta_even: u8, meta_odd: u8) -> bool {
    meta_even & meta_odd & META_DOUBLE_LEVEL != 0
}

/// Do the two texels of a pair disagree about being dual (one flag set)?
#[inline]
pub fn pair_disagrees(meta_even: u8, meta_odd: u8) -> bool {
    (meta_even ^ meta_odd) & META_DOUBLE_LEVEL != 0
}

/// Terrain type stored in a `meta` byte.
#[inline]
pub fn terrain_type(meta: u8) -> u8 {
    (meta & META_TERRAIN_MASK) >> META_TERRAIN_SHIFT
}

/// Decode the column at position `x` of a row, given the row's two planes.
/// This is the one decode rule; the WGSL surface module is its GPU twin.
#[inline]
pub fn decode_column(heights: &[u8], metas: &[u8], x: usize, mid_rule: MidRule) -> Column {
    let even = x & !1;
    let odd = even + 1;
    let (me, mo) = (metas[even], metas[odd]);
    if pair_is_dual(me, mo) {
        let low = heights[even];
        let high = heights[odd];
        let code = ((me & META_DELTA_MASK) << 2) | (mo & META_DELTA_MASK);
        let mid = (u32::from(low) + mid_rule.gap(code)).min(u32::from(high)) as u8;
        Column {
            low,
            mid,
            high,
            dual: true,
            lower_type: terrain_type(me),
            upper_type: terrain_type(mo),
        }
    } else {
        let h = heights[x];
        let t = terrain_type(metas[x]);
        Column {
            low: h,
            mid: h,
            high: h,
            dual: false,
            lower_type: t,
            upper_type: t,
        }
    }
}

/// A decoded map: the two byte planes, row-major, plus the mid convention.
/// Width and height are powers of two (the format stores them as powers) and
/// the map wraps in both directions.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Level {
    width: u32,
    height: u32,
    heights: Vec<u8>,
    metas: Vec<u8>,
    /// How `mid` is decoded from a pair's gap code.
    pub mid_rule: MidRule,
}

/// Errors constructing a [`Level`] from planes.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ShapeError {
    /// A side is not a power of two, or the width is below 2 (pairs need two texels).
    #[error("map size {width}x{height} is not a power of two in each direction (at least 2x1)")]
    NotPowerOfTwo {
        /// Width asked for, texels.
        width: u32,
        /// Height asked for, texels.
        height: u32,
    },
    /// A plane's length is not `width * height`.
    #[error("plane of {got} bytes does not match the map size {width}x{height} ({expected} bytes)")]
    PlaneSize {
        /// Map width, texels.
        width: u32,
        /// Map height, texels.
        height: u32,
        /// `width * height`.
        expected: usize,
        /// The plane's length.
        got: usize,
    },
}

impl Level {
    /// Build a level from its two planes (`width * height` bytes each).
    pub fn from_planes(
        width: u32,
        height: u32,
        heights: Vec<u8>,
        metas: Vec<u8>,
        mid_rule: MidRule,
    ) -> Result<Self, ShapeError> {
        if !width.is_power_of_two() || !height.is_power_of_two() || width < 2 {
            return Err(ShapeError::NotPowerOfTwo { width, height });
        }
        let expected = width as usize * height as usize;
        for plane in [&heights, &metas] {
            if plane.len() != expected {
                return Err(ShapeError::PlaneSize {
                    width,
                    height,
                    expected,
                    got: plane.len(),
                });
            }
        }
        Ok(Level {
            width,
            height,
            heights,
            metas,
            mid_rule,
        })
    }

    /// A flat single-level map of the given height and terrain type.
    pub fn flat(width: u32, height: u32, altitude: u8, terrain: u8) -> Result<Self, ShapeError> {
        let n = width as usize * height as usize;
        let meta = (terrain & 7) << META_TERRAIN_SHIFT;
        Self::from_planes(
            width,
            height,
            vec![altitude; n],
            vec![meta; n],
            MidRule::default(),
        )
    }

    /// Map width, texels (a power of two).
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Map height, texels (a power of two).
    pub fn height(&self) -> u32 {
        self.height
    }
    /// The height plane, row-major.
    pub fn heights(&self) -> &[u8] {
        &self.heights
    }
    /// The meta plane, row-major.
    pub fn metas(&self) -> &[u8] {
        &self.metas
    }
    /// Both planes, mutably, for edits and generators. Callers keep pairs
    /// valid; [`crate::edit`] is the checked way to change a level.
    pub fn planes_mut(&mut self) -> (&mut [u8], &mut [u8]) {
        (&mut self.heights, &mut self.metas)
    }
    /// Consume the level, returning `(heights, metas)`.
    pub fn into_planes(self) -> (Vec<u8>, Vec<u8>) {
        (self.heights, self.metas)
    }

    /// Row `y` (already wrapped) of both planes.
    #[inline]
    pub fn row(&self, y: u32) -> (&[u8], &[u8]) {
        let w = self.width as usize;
        let start = y as usize * w;
        (
            &self.heights[start..start + w],
            &self.metas[start..start + w],
        )
    }

    /// Wrap integer texel coordinates onto the torus.
    #[inline]
    pub fn wrap(&self, x: i64, y: i64) -> (u32, u32) {
        (
            (x & i64::from(self.width - 1)) as u32,
            (y & i64::from(self.height - 1)) as u32,
        )
    }

    /// The decoded column at texel (x, y), wrapping in both directions.
    #[inline]
    pub fn column(&self, x: i64, y: i64) -> Column {
        let (x, y) = self.wrap(x, y);
        let (h, m) = self.row(y);
        decode_column(h, m, x as usize, self.mid_rule)
    }

    /// The column under a world-space point: texel (floor x, floor y).
    #[inline]
    pub fn column_at(&self, x: f32, y: f32) -> Column {
        self.column(x.floor() as i64, y.floor() as i64)
    }

    /// Is the world-space point (x, y, z) inside solid terrain? Wraps in x and y.
    #[inline]
    pub fn is_solid(&self, x: f32, y: f32, z: f32) -> bool {
        self.column_at(x, y).is_solid(z)
    }

    /// Number of texels in dual pairs (both texels of each pair count).
    pub fn dual_texel_count(&self) -> u64 {
        use rayon::prelude::*;
        let w = self.width as usize;
        self.metas
            .par_chunks(w)
            .map(|row| {
                row.chunks_exact(2)
                    .filter(|p| pair_is_dual(p[0], p[1]))
                    .count() as u64
                    * 2
            })
            .sum()
    }

    /// Number of pairs whose two texels disagree about the dual flag.
    pub fn pair_disagreement_count(&self) -> u64 {
        use rayon::prelude::*;
        let w = self.width as usize;
        self.metas
            .par_chunks(w)
            .map(|row| {
                row.chunks_exact(2)
                    .filter(|p| pair_disagrees(p[0], p[1]))
                    .count() as u64
            })
            .sum()
    }

    /// SHA-256 of the size, mid rule and both planes: the key under which
    /// derived data (reference images, fits) is cached.
    pub fn content_hash(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut hasher = Sha256::new();
        hasher.update(self.width.to_le_bytes());
        hasher.update(self.height.to_le_bytes());
        hasher.update([self.mid_rule as u8]);
        hasher.update(&self.heights);
        hasher.update(&self.metas);
        let digest = hasher.finalize();
        digest.iter().map(|b| format!("{b:02x}")).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4x2 level whose first pair is dual: low 20, high 100, code 0b0110.
    fn hand_built(rule: MidRule) -> Level {
        let heights = vec![20, 100, 7, 0, 0, 0, 0, 0];
        let t_low = 2 << META_TERRAIN_SHIFT;
        let t_up = 5 << META_TERRAIN_SHIFT;
        let metas = vec![
            META_DOUBLE_LEVEL | t_low | 0b01,
            META_DOUBLE_LEVEL | t_up | 0b10,
            3 << META_TERRAIN_SHIFT,
            0,
            0,
            0,
            0,
            0,
        ];
        Level::from_planes(4, 2, heights, metas, rule).unwrap()
    }

    #[test]
    fn dual_pair_decodes_under_both_conventions() {
        // code = (0b01 << 2) | 0b10 = 6
        let original = hand_built(MidRule::Original).column(0, 0);
        assert_eq!(
            original,
            Column {
                low: 20,
                mid: 20 + 7 * 8,
                high: 100,
                dual: true,
                lower_type: 2,
                upper_type: 5
            }
        );
        // Both texels of the pair decode to the same column.
        assert_eq!(hand_built(MidRule::Original).column(1, 0), original);
        let vange = hand_built(MidRule::VangeRs).column(1, 0);
        assert_eq!(vange.mid, 20 + 6 * 8);
        assert!(original.is_solid(20.0) && !original.is_solid(20.5));
        assert!(!original.is_solid(75.9) && original.is_solid(76.0));
        assert!(original.is_solid(100.0) && !original.is_solid(100.1));
    }

    #[test]
    fn mid_is_clamped_to_high() {
        let mut level = hand_built(MidRule::Original);
        level.planes_mut().0[1] = 30; // high 30 < low + gap
        assert_eq!(level.column(0, 0).mid, 30);
    }

    #[test]
    fn single_texels_and_sea_level() {
        let level = hand_built(MidRule::Original);
        let c = level.column(2, 0);
        assert_eq!(
            (c.low, c.mid, c.high, c.dual, c.lower_type),
            (7, 7, 7, false, 3)
        );
        let sea = level.column(3, 0);
        assert_eq!(sea.low, 0);
        assert!(sea.is_solid(0.0), "height 0 is solid at z = 0");
        assert!(!sea.is_solid(0.01));
    }

    #[test]
    fn coordinates_wrap_both_ways() {
        let level = hand_built(MidRule::Original);
        assert_eq!(level.column(-4, 2), level.column(0, 0));
        assert_eq!(level.column(6, -1), level.column(2, 1));
        assert!(level.is_solid(-3.5, 4.2, 50.0) == level.is_solid(0.5, 0.2, 50.0));
    }

    #[test]
    fn half_flagged_pairs_are_single_and_counted() {
        let mut level = hand_built(MidRule::Original);
        level.planes_mut().1[1] &= !META_DOUBLE_LEVEL;
        assert!(!level.column(0, 0).dual);
        assert_eq!(level.pair_disagreement_count(), 1);
        assert_eq!(level.dual_texel_count(), 0);
    }

    #[test]
    fn gap_code_round_trips() {
        for rule in [MidRule::Original, MidRule::VangeRs] {
            for code in 0..16u8 {
                assert_eq!(rule.code_for_gap(rule.gap(code)), code, "{rule:?}");
            }
        }
    }

    #[test]
    fn shape_errors() {
        assert!(Level::from_planes(3, 4, vec![0; 12], vec![0; 12], MidRule::Original).is_err());
        assert!(Level::from_planes(4, 4, vec![0; 15], vec![0; 16], MidRule::Original).is_err());
    }
}
