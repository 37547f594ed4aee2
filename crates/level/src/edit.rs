//! Edits: changes to height and meta inside a rectangle, wrapping at the edges.
//!
//! An edit is a function from a texel's decoded [`Column`] to the column it
//! should become. [`edit_columns`] applies it over a rectangle given in
//! unwrapped integer coordinates (anything, also negative or past the map),
//! re-encodes the result keeping the pair encoding valid, and returns the
//! dirty rectangles, split at the map edges and widened to whole pairs.
//!
//! Pair rules (DESIGN §1; as the original game, a closed slab leaves the
//! column single at its top):
//! - a dual pair is edited once, at its even texel; the result applies to
//!   both texels;
//! - a single pair is edited texel by texel; if either result is dual, the
//!   pair becomes that dual column (the even texel's result first);
//! - a dual result stays dual only if its cave is at least [`MIN_CAVE`]
//!   units tall and the slab has thickness (`mid < high`). The gap code is
//!   the largest whose gap fits under `mid` (the slab never moves up into
//!   the cave). Otherwise the pair becomes single at `high` with the slab's
//!   terrain type;
//! - a single result sets the texel's height to `low`;
//! - meta bits we do not interpret (shadow, object shadow) are kept.

use crate::model::{
    Column, Level, META_DELTA_MASK, META_DOUBLE_LEVEL, META_TERRAIN_MASK, META_TERRAIN_SHIFT,
    MidRule, decode_column,
};
use crate::views::EditSite;

/// A rectangle of texels inside the map (never wrapping: an edit across the
/// map edge yields several).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DirtyRect {
    /// Left column, texels (`0..map width`).
    pub x: u32,
    /// Top row, texels (`0..map height`).
    pub y: u32,
    /// Columns; `x + width` is at most the map width.
    pub width: u32,
    /// Rows; `y + height` is at most the map height.
    pub height: u32,
}

impl DirtyRect {
    /// Whether texel `(x, y)` (map coordinates, not wrapped) is inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x && x - self.x < self.width && y >= self.y && y - self.y < self.height
    }

    /// Every texel `(x, y)` inside, row by row.
    ///
    /// ```
    /// let r = strata_level::DirtyRect { x: 2, y: 5, width: 2, height: 2 };
    /// let texels: Vec<(u32, u32)> = r.texels().collect();
    /// assert_eq!(texels, [(2, 5), (3, 5), (2, 6), (3, 6)]);
    /// assert!(texels.iter().all(|&(x, y)| r.contains(x, y)));
    /// ```
    pub fn texels(&self) -> impl Iterator<Item = (u32, u32)> + use<> {
        let (x0, x1) = (self.x, self.x + self.width);
        (self.y..self.y + self.height).flat_map(move |y| (x0..x1).map(move |x| (x, y)))
    }
}

/// A rectangle in unwrapped texel coordinates: `x .. x + width`, `y .. y + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EditRect {
    /// Left column; any value, wrapped onto the map when applied.
    pub x: i64,
    /// Top row; any value, wrapped onto the map when applied.
    pub y: i64,
    /// Columns (an edit covers at most one map width).
    pub width: u32,
    /// Rows (an edit covers at most one map height).
    pub height: u32,
}

/// The shortest cave a dual column keeps (issue 2: "a cave is at least 8 units tall").
pub const MIN_CAVE: u32 = 8;

/// The largest gap code whose gap is at most `gap`, if its gap is at least [`MIN_CAVE`].
fn code_at_most(rule: MidRule, gap: u32) -> Option<u8> {
    (0..16u8)
        .rev()
        .find(|&c| rule.gap(c) <= gap && rule.gap(c) >= MIN_CAVE)
}

/// Split `start .. start + len` (unwrapped) into in-map spans on an axis of `size`.
fn spans(start: i64, len: u32, size: u32) -> Vec<(u32, u32)> {
    let len = len.min(size);
    let first = start.rem_euclid(i64::from(size)) as u32;
    let head = len.min(size - first);
    let mut out = vec![(first, head)];
    if head < len {
        out.push((0, len - head));
    }
    out.retain(|s| s.1 > 0);
    out
}

/// What to write into one texel.
#[derive(Clone, Copy)]
enum Write {
    Single {
        height: u8,
        terrain: u8,
    },
    /// The even or odd half of a dual pair.
    Dual {
        height: u8,
        terrain: u8,
        delta: u8,
    },
}

fn apply(h: &mut u8, m: &mut u8, write: Write) -> bool {
    let keep = *m & !(META_DOUBLE_LEVEL | META_TERRAIN_MASK | META_DELTA_MASK);
    let (height, meta) = match write {
        Write::Single { height, terrain } => (height, keep | ((terrain & 7) << META_TERRAIN_SHIFT)),
        Write::Dual {
            height,
            terrain,
            delta,
        } => (
            height,
            keep | META_DOUBLE_LEVEL
                | ((terrain & 7) << META_TERRAIN_SHIFT)
                | (delta & META_DELTA_MASK),
        ),
    };
    let changed = (*h, *m) != (height, meta);
    (*h, *m) = (height, meta);
    changed
}

/// The writes for a pair whose result is the dual column `c`.
fn dual_writes(rule: MidRule, c: Column) -> [Write; 2] {
    let code = if c.mid < c.high && c.mid >= c.low {
        code_at_most(rule, u32::from(c.mid - c.low))
    } else {
        None
    };
    match code {
        Some(code) => [
            Write::Dual {
                height: c.low,
                terrain: c.lower_type,
                delta: code >> 2,
            },
            Write::Dual {
                height: c.high,
                terrain: c.upper_type,
                delta: code & 3,
            },
        ],
        None => {
            [Write::Single {
                height: c.high,
                terrain: c.upper_type,
            }; 2]
        }
    }
}

/// `rect` widened to whole pairs and clipped to one map's extent: the
/// unwrapped even start x, the width and the height; `None` when empty.
fn pair_extent(level: &Level, rect: EditRect) -> Option<(i64, u32, u32)> {
    // Even start, even end. (i128: coordinates may be anywhere in i64.)
    let x0 = rect.x.div_euclid(2) * 2;
    let x_end = (i128::from(rect.x) + i128::from(rect.width) + 1).div_euclid(2) * 2;
    let width = u32::try_from(x_end - i128::from(x0))
        .unwrap_or(u32::MAX)
        .min(level.width());
    let height = rect.height.min(level.height());
    (rect.width > 0 && height > 0).then_some((x0, width, height))
}

/// The in-map rectangles `rect` covers once widened to whole pairs (split at
/// the map edges): what an edit over `rect` may touch.
pub fn covered_rects(level: &Level, rect: EditRect) -> Vec<DirtyRect> {
    let Some((x0, width, height)) = pair_extent(level, rect) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (x, w) in spans(x0, width, level.width()) {
        for (y, h) in spans(rect.y, height, level.height()) {
            out.push(DirtyRect {
                x,
                y,
                width: w,
                height: h,
            });
        }
    }
    out
}

/// The raw bytes (heights and metas, every bit) of the texels an edit over
/// a rectangle may touch, taken before the edit so it can be undone exactly.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Snapshot {
    rects: Vec<DirtyRect>,
    heights: Vec<u8>,
    metas: Vec<u8>,
}

impl Snapshot {
    /// Copy what an edit over `rect` may change.
    pub fn take(level: &Level, rect: EditRect) -> Self {
        let rects = covered_rects(level, rect);
        let (mut heights, mut metas) = (Vec::new(), Vec::new());
        for r in &rects {
            for y in r.y..r.y + r.height {
                let (hr, mr) = level.row(y);
                let span = r.x as usize..(r.x + r.width) as usize;
                heights.extend_from_slice(&hr[span.clone()]);
                metas.extend_from_slice(&mr[span]);
            }
        }
        Snapshot {
            rects,
            heights,
            metas,
        }
    }

    /// The level must be the one the snapshot was taken of (same size).
    /// Writes the bytes back and returns the rectangles rewritten.
    pub fn restore(&self, level: &mut Level) -> Vec<DirtyRect> {
        let w = level.width() as usize;
        let (hs, ms) = level.planes_mut();
        let mut at = 0;
        for r in &self.rects {
            let n = r.width as usize;
            for y in r.y..r.y + r.height {
                let row = y as usize * w + r.x as usize;
                hs[row..row + n].copy_from_slice(&self.heights[at..at + n]);
                ms[row..row + n].copy_from_slice(&self.metas[at..at + n]);
                at += n;
            }
        }
        self.rects.clone()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.heights.len() + self.metas.len()
    }
}

/// The unwrapped rectangle [`crater`] edits.
pub fn crater_rect(site: &EditSite) -> EditRect {
    let r = i64::from(site.radius);
    EditRect {
        x: site.centre_x.saturating_sub(r),
        y: site.centre_y.saturating_sub(r),
        width: site.radius.saturating_mul(2).saturating_add(1),
        height: site.radius.saturating_mul(2).saturating_add(1),
    }
}

/// Apply `f(x, y, column) -> column` over `rect` (unwrapped coordinates;
/// `x`, `y` passed to `f` are unwrapped too, so distances from a centre
/// work across the edges). The rectangle is widened to whole pairs and
/// clipped to one map's extent. Returns the dirty rectangles (inside the
/// map, even-aligned in x) that contain every changed texel; rectangles
/// where nothing changed are left out.
pub fn edit_columns(
    level: &mut Level,
    rect: EditRect,
    mut f: impl FnMut(i64, i64, Column) -> Column,
) -> Vec<DirtyRect> {
    let (w, h) = (level.width(), level.height());
    let rule = level.mid_rule;
    let Some((x0, width, height)) = pair_extent(level, rect) else {
        return Vec::new();
    };
    let wu = w as usize;
    let mut dirty = Vec::new();
    for (sx, sw) in spans(x0, width, w) {
        for (sy, sh) in spans(rect.y, height, h) {
            let mut changed = false;
            for y in sy..sy + sh {
                // Unwrapped coordinates for `f`: the offset of this span from the rect.
                let uy = rect.y.wrapping_add(
                    (i64::from(y) - rect.y.rem_euclid(i64::from(h))).rem_euclid(i64::from(h)),
                );
                let (hs, ms) = level.planes_mut();
                let row = y as usize * wu;
                let (hr, mr) = (&mut hs[row..row + wu], &mut ms[row..row + wu]);
                for xe in (sx..sx + sw).step_by(2) {
                    let ux = x0.wrapping_add(
                        (i64::from(xe) - x0.rem_euclid(i64::from(w))).rem_euclid(i64::from(w)),
                    );
                    let xe = xe as usize;
                    let before = decode_column(hr, mr, xe, rule);
                    let writes = if before.dual {
                        let after = f(ux, uy, before);
                        if after == before {
                            continue;
                        }
                        if after.dual {
                            dual_writes(rule, after)
                        } else {
                            [Write::Single {
                                height: after.low,
                                terrain: after.lower_type,
                            }; 2]
                        }
                    } else {
                        let odd_before = decode_column(hr, mr, xe + 1, rule);
                        let even = f(ux, uy, before);
                        let odd = f(ux.wrapping_add(1), uy, odd_before);
                        if even == before && odd == odd_before {
                            continue;
                        }
                        if even.dual {
                            dual_writes(rule, even)
                        } else if odd.dual {
                            dual_writes(rule, odd)
                        } else {
                            [
                                Write::Single {
                                    height: even.low,
                                    terrain: even.lower_type,
                                },
                                Write::Single {
                                    height: odd.low,
                                    terrain: odd.lower_type,
                                },
                            ]
                        }
                    };
                    changed |= apply(&mut hr[xe], &mut mr[xe], writes[0]);
                    changed |= apply(&mut hr[xe + 1], &mut mr[xe + 1], writes[1]);
                }
            }
            if changed {
                dirty.push(DirtyRect {
                    x: sx,
                    y: sy,
                    width: sw,
                    height: sh,
                });
            }
        }
    }
    dirty
}

/// Set every texel of `rect` to a single column of `height` and `terrain`
/// (removing slabs): the simplest general edit.
pub fn fill_single(level: &mut Level, rect: EditRect, height: u8, terrain: u8) -> Vec<DirtyRect> {
    let t = terrain & 7;
    edit_columns(level, rect, |_, _, _| Column {
        low: height,
        mid: height,
        high: height,
        dual: false,
        lower_type: t,
        upper_type: t,
    })
}

/// Why [`try_crater`] refused a crater.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EditError {
    /// The depth is NaN or infinite.
    #[error("crater depth {0} is not a finite number")]
    Depth(f32),
}

/// [`crater`], refusing what makes no crater: a depth that is not finite
/// is an error. A radius of 0 digs nothing (no dirty rectangle); a centre
/// anywhere (past the map, negative, near `i64::MAX`) wraps onto the map;
/// a radius past half the map covers the whole map once, each texel at its
/// distance from the nearest copy of the centre.
pub fn try_crater(level: &mut Level, site: &EditSite) -> Result<Vec<DirtyRect>, EditError> {
    if !site.depth.is_finite() {
        return Err(EditError::Depth(site.depth));
    }
    Ok(crater(level, site))
}

/// Distance along one axis from `c` to `x` on a map of `size` that wraps:
/// to the nearest copy of `c` (exact for any i64s).
fn wrapped_offset(x: i64, c: i64, size: u32) -> f32 {
    let size = i128::from(size);
    let d = (i128::from(x) - i128::from(c)).rem_euclid(size);
    (if 2 * d >= size { d - size } else { d }) as f32
}

/// The paper's crater: inside radius `r` of the centre the floor drops by
/// `depth (1 - d²/r²)` (never below 0) and the upper layer is removed
/// (dual pairs become single at the lowered floor). The map wraps: `d` is
/// the distance to the nearest copy of the centre. A radius of 0, or a
/// depth that is not finite, changes nothing ([`try_crater`] refuses the
/// latter with an error).
pub fn crater(level: &mut Level, site: &EditSite) -> Vec<DirtyRect> {
    if site.radius == 0 || !site.depth.is_finite() {
        return Vec::new();
    }
    let r2 = (site.radius as f32).powi(2);
    let (cx, cy) = (site.centre_x, site.centre_y);
    let (w, h) = (level.width(), level.height());
    edit_columns(level, crater_rect(site), |x, y, c| {
        let (dx, dy) = (wrapped_offset(x, cx, w), wrapped_offset(y, cy, h));
        let d2 = dx * dx + dy * dy;
        if d2 >= r2 {
            return c;
        }
        let drop = site.depth * (1.0 - d2 / r2);
        let low = (f32::from(c.low) - drop).round().clamp(0.0, 255.0) as u8;
        Column {
            low,
            mid: low,
            high: low,
            dual: false,
            lower_type: c.lower_type,
            upper_type: c.lower_type,
        }
    })
}
