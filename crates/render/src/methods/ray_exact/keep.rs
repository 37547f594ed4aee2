//! Which shadow blocks cast by earlier frames a frame may keep
//! (`shadow_keep.wgsl`), and which of them an edit of the terrain spoils.
//!
//! The key names the blocks tagged since the last change that alters what a
//! block holds. It changes when the texel size or the map's plane changes,
//! when anything but this method's block pass writes the map, and when an
//! edit reaches too many blocks to name; it is 0 (keep nothing) over paged
//! terrain, whose texels depend on the pages resident.
//!
//! Within one key, a slot of the map's texture holds one lattice block at a
//! time and its tag says which; so a tag that matches is the block's. The key
//! is a frame counter of sorts: 2^32 changes, at one a frame, take two years
//! at 60 frames a second, and a wrapped key could only match a tag that old.
//!
//! An edit keeps the key: a texel's shadow ray reads only the columns it
//! passes over, so only blocks whose rays cross the edited columns (or any
//! of their images on the wrapped map) can hold something else now. Those
//! blocks' slots are cleared ([`KeyedFrame::spoiled`]): every block that
//! could hold them under this key, that is, any lattice block of the squares
//! the key's frames spanned. A game that digs a crater in front of a still
//! camera recasts a few dozen blocks, not the view's thousands.

use super::deferred::MARK_BLOCK;
use crate::frame::SHADOW_SIZE;
use glam::DVec2;
use strata_camera::light::ShadowFrame;
use strata_level::DirtyRect;

/// Blocks of the map a side (and slots of its texture).
const BLOCKS: u32 = SHADOW_SIZE / MARK_BLOCK;

/// Edited rectangles held for the next frame: beyond this many the key
/// changes instead (the test per rectangle is a few hundred blocks' worth).
const MOST_EDITS: usize = 512;

/// Wrapped images of one edit tested against the spanned squares: a key's
/// frames seldom span more than a map or two, and a wider span changes the
/// key instead.
const MOST_IMAGES: i64 = 64;

/// How far around the edited columns a shadow ray counts as crossing them,
/// units: a column's pair neighbour decodes from the same texel (the pair
/// rule of dual columns) and the march's f32 rounding.
const EDIT_MARGIN: f64 = 2.0;

/// The altitudes a shadow ray spans (`exact_shadow_ray`: from 255 down to
/// below 0), widened by the margin.
const RAY_ALTITUDES: [f64; 2] = [-1.0 - EDIT_MARGIN, 255.0 + EDIT_MARGIN];

/// How far a texel's centre may lie outside an edit's outline and still
/// count, texels (the GPU computes the centres in f32).
const TEXEL_SLACK: f64 = 1.0;

pub(super) struct ShadowKeep {
    key: u32,
    /// Texel size and plane of the key's frames (f32 bits).
    fit: Option<[u32; 4]>,
    /// `Shared::shadow_map_writes` after this method's last write.
    writes_seen: std::cell::Cell<Option<u64>>,
    /// Something since the last frame changed what blocks hold.
    stale: std::cell::Cell<bool>,
    /// The lattice blocks the key's frames' squares spanned: x0, y0, x1, y1
    /// (the last two exclusive).
    spanned: [i32; 4],
    /// Columns edited since the last frame, and the map's size.
    edits: Vec<DirtyRect>,
    map: (u32, u32),
}

/// A frame's key, and the slots of the map's texture whose blocks the
/// edits since the last frame may have spoiled (their tags must be
/// cleared before anything reads them).
#[derive(Debug, Default, PartialEq, Eq)]
pub(super) struct KeyedFrame {
    pub key: u32,
    pub spoiled: Vec<u32>,
}

impl ShadowKeep {
    pub(super) fn new() -> Self {
        ShadowKeep {
            key: 0,
            fit: None,
            writes_seen: std::cell::Cell::new(None),
            stale: std::cell::Cell::new(true),
            spanned: [0; 4],
            edits: Vec::new(),
            map: (0, 0),
        }
    }

    /// The terrain or the map changed under the kept blocks.
    pub(super) fn forget(&self) {
        self.stale.set(true);
    }

    /// The columns of `rects` of a map of `map` columns changed.
    pub(super) fn edited(&mut self, rects: &[DirtyRect], map: (u32, u32)) {
        if self.edits.len() + rects.len() > MOST_EDITS
            || (self.map != map && !self.edits.is_empty())
        {
            self.edits.clear();
            self.forget();
            return;
        }
        self.map = map;
        self.edits.extend_from_slice(rects);
    }

    /// This method's block pass wrote the map this frame (`writes`: the
    /// count it brought `Shared::shadow_map_writes` to).
    pub(super) fn wrote(&self, writes: u64) {
        self.writes_seen.set(Some(writes));
    }

    /// This frame's key: the last one when nothing changed, a new one else
    /// (0 where blocks cannot be kept: `keep` false), with the slots the
    /// edits since the last frame spoiled.
    pub(super) fn key(&mut self, frame: &ShadowFrame, writes: u64, keep: bool) -> KeyedFrame {
        let a = frame.anchor;
        let fit = [
            frame.texel.to_bits(),
            a.x.to_bits(),
            a.y.to_bits(),
            a.z.to_bits(),
        ];
        let same = self.fit == Some(fit) && self.writes_seen.get() == Some(writes);
        let mut renew = self.stale.replace(false) || !same || self.key == 0;
        let mut spoiled = Vec::new();
        if !renew && !self.edits.is_empty() {
            match spoiled_slots(frame, self.map, &self.edits, self.spanned) {
                Some(slots) => spoiled = slots,
                None => renew = true,
            }
        }
        self.edits.clear();
        let square = square_blocks(frame);
        if renew {
            self.key = self.key.wrapping_add(1).max(1);
            self.spanned = square;
            spoiled.clear();
        } else {
            let s = &mut self.spanned;
            *s = [
                s[0].min(square[0]),
                s[1].min(square[1]),
                s[2].max(square[2]),
                s[3].max(square[3]),
            ];
        }
        self.fit = Some(fit);
        if keep {
            KeyedFrame {
                key: self.key,
                spoiled,
            }
        } else {
            // Nothing clears the spoiled tags this frame: the next frame
            // that keeps starts over.
            self.forget();
            KeyedFrame::default()
        }
    }
}

/// The lattice blocks of `frame`'s square: x0, y0, x1, y1 (exclusive).
fn square_blocks(frame: &ShadowFrame) -> [i32; 4] {
    let b = MARK_BLOCK as i32;
    let (x, y) = (frame.lattice[0] / b, frame.lattice[1] / b);
    [x, y, x + BLOCKS as i32, y + BLOCKS as i32]
}

/// The texture's slot of lattice block (x, y) (`shadow_keep_tag`).
fn slot_of(x: i32, y: i32) -> u32 {
    let mask = BLOCKS as i32 - 1;
    ((y & mask) * BLOCKS as i32 + (x & mask)) as u32
}

/// The slots of every lattice block within `spanned` (x0, y0, x1, y1,
/// blocks) whose texels' shadow rays may cross a column of `edits` or of
/// its images on the map of `map` columns, which wraps; sorted. `None` when
/// the test would take too long or spoil nearly all the map (then the key
/// changes instead).
pub(super) fn spoiled_slots(
    frame: &ShadowFrame,
    map: (u32, u32),
    edits: &[DirtyRect],
    spanned: [i32; 4],
) -> Option<Vec<u32>> {
    let mut spoiled = vec![false; (BLOCKS * BLOCKS) as usize];
    let mut count = 0usize;
    for rect in edits {
        for [x0, y0, x1, y1] in crossed_blocks(frame, map, rect, spanned)? {
            for y in y0..y1 {
                for x in x0..x1 {
                    let s = slot_of(x, y) as usize;
                    count += usize::from(!spoiled[s]);
                    spoiled[s] = true;
                }
            }
        }
        // Most of the map: as cheap to start over.
        if count * 8 > spoiled.len() * 7 {
            return None;
        }
    }
    Some(
        (0..BLOCKS * BLOCKS)
            .filter(|&s| spoiled[s as usize])
            .collect(),
    )
}

/// The lattice coordinates (texel units; texel n's centre at n + 0.5) of
/// world point (x, y, z) on `frame`'s lattice.
fn lattice_coords(frame: &ShadowFrame, x: f64, y: f64, z: f64) -> DVec2 {
    let rel = glam::DVec3::new(x, y, z) - frame.anchor.as_dvec3();
    DVec2::new(rel.dot(frame.u.as_dvec3()), rel.dot(frame.v.as_dvec3())) / f64::from(frame.texel)
}

/// The block ranges (x0, y0, x1, y1, exclusive, within `spanned`) of the
/// lattice blocks with a texel whose shadow ray may cross `rect`'s columns
/// or one of their wrapped images. A ray runs along the light, so it crosses
/// the box of the columns (every altitude it spans) where its texel's
/// centre lies in the box's outline on the lattice; the outline's bounding
/// rectangle is taken.
fn crossed_blocks(
    frame: &ShadowFrame,
    (width, height): (u32, u32),
    rect: &DirtyRect,
    spanned: [i32; 4],
) -> Option<Vec<[i32; 4]>> {
    let xs = [
        f64::from(rect.x) - EDIT_MARGIN,
        f64::from(rect.x + rect.width) + EDIT_MARGIN,
    ];
    let ys = [
        f64::from(rect.y) - EDIT_MARGIN,
        f64::from(rect.y + rect.height) + EDIT_MARGIN,
    ];
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for x in xs {
        for y in ys {
            for z in RAY_ALTITUDES {
                let p = lattice_coords(frame, x, y, z);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    // One map's shift along x and along y, on the lattice.
    let origin = lattice_coords(frame, 0.0, 0.0, 0.0);
    let along_x = lattice_coords(frame, f64::from(width), 0.0, 0.0) - origin;
    let along_y = lattice_coords(frame, 0.0, f64::from(height), 0.0) - origin;
    let det = along_x.x * along_y.y - along_x.y * along_y.x;
    if det.abs() < 1e-9 {
        return None;
    }
    // The spanned texels; an image's outline reaches them where its centre
    // lies within the outline's half size of them.
    let block = f64::from(MARK_BLOCK);
    let half = 0.5 * (hi - lo) + DVec2::splat(TEXEL_SLACK);
    let centre = 0.5 * (lo + hi);
    let reach_lo = DVec2::new(f64::from(spanned[0]), f64::from(spanned[1])) * block - half;
    let reach_hi = DVec2::new(f64::from(spanned[2]), f64::from(spanned[3])) * block + half;
    // The images (k, l) whose centre `centre + k along_x + l along_y` lies
    // in that reach: the reach's corners in (k, l), bounded.
    let (mut k_lo, mut k_hi, mut l_lo, mut l_hi) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for cx in [reach_lo.x, reach_hi.x] {
        for cy in [reach_lo.y, reach_hi.y] {
            let d = DVec2::new(cx, cy) - centre;
            let k = (d.x * along_y.y - d.y * along_y.x) / det;
            let l = (along_x.x * d.y - along_x.y * d.x) / det;
            (k_lo, k_hi, l_lo, l_hi) = (k_lo.min(k), k_hi.max(k), l_lo.min(l), l_hi.max(l));
        }
    }
    let (k_lo, k_hi) = (k_lo.floor() as i64, k_hi.ceil() as i64);
    let (l_lo, l_hi) = (l_lo.floor() as i64, l_hi.ceil() as i64);
    if (k_hi - k_lo + 1) * (l_hi - l_lo + 1) > MOST_IMAGES {
        return None;
    }
    let mut ranges = Vec::new();
    for k in k_lo..=k_hi {
        for l in l_lo..=l_hi {
            let shift = along_x * k as f64 + along_y * l as f64;
            // Texels n whose centre n + 0.5 lies in the image's outline,
            // with the slack; then their blocks.
            let first = (lo + shift - DVec2::splat(0.5 + TEXEL_SLACK)).ceil();
            let last = (hi + shift - DVec2::splat(0.5 - TEXEL_SLACK)).floor();
            let b0 = (first / block).floor();
            let b1 = (last / block).floor() + DVec2::ONE;
            let r = [
                (b0.x as i32).max(spanned[0]),
                (b0.y as i32).max(spanned[1]),
                (b1.x as i32).min(spanned[2]),
                (b1.y as i32).min(spanned[3]),
            ];
            if r[0] < r[2] && r[1] < r[3] {
                ranges.push(r);
            }
        }
    }
    Some(ranges)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use strata_camera::Camera;

    fn frame_at(x: f32, y: f32, yaw: f32, pitch: f32) -> ShadowFrame {
        let camera = Camera::new(Vec3::new(x, y, 300.0), yaw, pitch, 320, 200).unwrap();
        ShadowFrame::fit(&camera, true)
    }

    /// Whether texel (i, j)'s shadow ray (lattice indices), from altitude
    /// 255 down to -1, passes over a column of `rect` or of one of its
    /// images on the wrapped map: its ground track clipped to each image.
    fn ray_crosses(frame: &ShadowFrame, i: i32, j: i32, map: (u32, u32), rect: &DirtyRect) -> bool {
        let t = f64::from(frame.texel);
        let (u, v, l) = (
            frame.u.as_dvec3(),
            frame.v.as_dvec3(),
            frame.light.as_dvec3(),
        );
        let o = frame.anchor.as_dvec3()
            + u * ((f64::from(i) + 0.5) * t)
            + v * ((f64::from(j) + 0.5) * t);
        let a = o + l * ((255.0 - o.z) / l.z);
        let b = o + l * ((-1.0 - o.z) / l.z);
        let (w, h) = (f64::from(map.0), f64::from(map.1));
        let (k0, k1) = (
            ((a.x.min(b.x)) / w).floor() as i64 - 1,
            ((a.x.max(b.x)) / w).ceil() as i64,
        );
        let (l0, l1) = (
            ((a.y.min(b.y)) / h).floor() as i64 - 1,
            ((a.y.max(b.y)) / h).ceil() as i64,
        );
        (k0..=k1).any(|k| {
            (l0..=l1).any(|n| {
                let x0 = f64::from(rect.x) + k as f64 * w;
                let y0 = f64::from(rect.y) + n as f64 * h;
                // Liang-Barsky: the track a + s (b - a), s in [0, 1].
                let (mut s0, mut s1) = (0.0f64, 1.0f64);
                for (p, q0, q1) in [
                    (b.x - a.x, x0 - a.x, x0 + f64::from(rect.width) - a.x),
                    (b.y - a.y, y0 - a.y, y0 + f64::from(rect.height) - a.y),
                ] {
                    if p.abs() < 1e-12 {
                        if q0 > 0.0 || q1 < 0.0 {
                            return false;
                        }
                        continue;
                    }
                    let (e0, e1) = ((q0 / p).min(q1 / p), (q0 / p).max(q1 / p));
                    s0 = s0.max(e0);
                    s1 = s1.min(e1);
                }
                s0 <= s1
            })
        })
    }

    #[test]
    fn every_texel_whose_ray_crosses_an_edit_is_in_a_spoiled_block() {
        let map = MAP;
        let cases = [
            // Near the camera; at the map's corner (its images matter); a
            // wider span of squares and a long thin edit.
            (frame_at(1000.0, 800.0, 37.0, -30.0), NEAR_EDIT, 0),
            (
                frame_at(30.0, 2030.0, 200.0, -60.0),
                DirtyRect {
                    x: 2040,
                    y: 4,
                    width: 8,
                    height: 8,
                },
                0,
            ),
            (
                frame_at(1500.0, 1500.0, 300.0, -90.0),
                DirtyRect {
                    x: 1480,
                    y: 1490,
                    width: 3,
                    height: 40,
                },
                40,
            ),
        ];
        for (frame, rect, widen) in cases {
            let square = square_blocks(&frame);
            let spanned = [
                square[0] - widen,
                square[1] - widen,
                square[2] + widen,
                square[3] + widen,
            ];
            let slots =
                spoiled_slots(&frame, map, &[rect], spanned).expect("a small edit is named");
            let spoiled: std::collections::HashSet<u32> = slots.iter().copied().collect();
            let b = MARK_BLOCK as i32;
            let mut crossing = std::collections::HashSet::new();
            for j in spanned[1] * b..spanned[3] * b {
                for i in spanned[0] * b..spanned[2] * b {
                    if ray_crosses(&frame, i, j, map, &rect) {
                        let (bx, by) = (i.div_euclid(b), j.div_euclid(b));
                        assert!(
                            spoiled.contains(&slot_of(bx, by)),
                            "texel ({i}, {j})'s ray crosses the edit but its block is kept"
                        );
                        crossing.insert((bx, by));
                    }
                }
            }
            eprintln!(
                "{} blocks crossed, {} slots spoiled",
                crossing.len(),
                slots.len()
            );
            assert!(
                !crossing.is_empty(),
                "the test's edit is crossed by some ray"
            );
            // Not much more than the crossed blocks: the outline's bounding
            // rectangle and the margins.
            assert!(
                slots.len() <= 4 * crossing.len() + 64,
                "{} slots for {} blocks crossed",
                slots.len(),
                crossing.len()
            );
        }
    }

    /// A small edit in front of `frame_at(1000.0, 800.0, ..)`'s camera, on a
    /// map of `MAP` columns.
    const NEAR_EDIT: DirtyRect = DirtyRect {
        x: 1010,
        y: 820,
        width: 12,
        height: 9,
    };
    const MAP: (u32, u32) = (2048, 2048);

    #[test]
    fn an_edit_keeps_the_key_and_spoils_its_slots_only() {
        let frame = frame_at(1000.0, 800.0, 37.0, -30.0);
        let mut keep = ShadowKeep::new();
        keep.wrote(3);
        let first = keep.key(&frame, 3, true);
        assert!(first.key != 0 && first.spoiled.is_empty());
        assert_eq!(keep.key(&frame, 3, true), first);
        keep.edited(&[NEAR_EDIT], MAP);
        let edited = keep.key(&frame, 3, true);
        assert_eq!(edited.key, first.key);
        assert!(!edited.spoiled.is_empty());
        assert!(edited.spoiled.len() < (BLOCKS * BLOCKS / 8) as usize);
        // Once: the next frame spoils nothing more.
        assert_eq!(keep.key(&frame, 3, true), first);
        // Too many edits change the key.
        let many: Vec<DirtyRect> = (0..MOST_EDITS as u32 + 1)
            .map(|n| DirtyRect {
                x: n % 2000,
                y: 7,
                width: 1,
                height: 1,
            })
            .collect();
        keep.edited(&many, MAP);
        let next = keep.key(&frame, 3, true);
        assert!(next.key != first.key && next.spoiled.is_empty());
        // An edit over most of the map does too.
        keep.edited(
            &[DirtyRect {
                x: 0,
                y: 0,
                width: 2048,
                height: 2048,
            }],
            MAP,
        );
        let whole = keep.key(&frame, 3, true);
        assert!(whole.key != next.key && whole.spoiled.is_empty());
        // Another writer, as before.
        let other = keep.key(&frame, 4, true);
        assert_ne!(other.key, whole.key);
        // A frame that keeps nothing clears no tag: an edit before it
        // makes the next frame that keeps start over.
        keep.wrote(4);
        assert_eq!(keep.key(&frame, 4, true).key, other.key);
        keep.edited(&[NEAR_EDIT], MAP);
        assert_eq!(keep.key(&frame, 4, false), KeyedFrame::default());
        let after = keep.key(&frame, 4, true);
        assert!(after.key != other.key && after.spoiled.is_empty());
    }
}
