//! `ray-exact`'s still frames: once every shadow block of the view's cover
//! is known to be cast, a frame needs neither the deferred frame's stamps
//! nor its shadow and shading passes, and marches and shades in one pass
//! (`ray_exact.wgsl`).
//!
//! The deferred frame lists the blocks its pixels read, on the GPU, so the
//! CPU never learns which blocks a frame cast. This module keeps its own
//! record instead: the blocks *it* listed for the shadow pass, by slot of
//! the map's texture, with the key (`keep::ShadowKeep`) and the lattice
//! block each was cast for. Once the view has been still for
//! [`STILL_FRAMES`] frames (the same camera and key), a frame lists up to a
//! budget of the cover's blocks not yet recorded, and the shadow pass casts
//! them before the march (tagging them, so a deferred march keeps them
//! too). When none is left, the frame is *covered*: every texel its shading
//! can read (`ShadowCover`, which holds every texel within reach of a
//! visible point) holds what casting it now would store.
//!
//! Only a still view: a moving one changes its texel size every few frames
//! (on the video's path the key changes in 270 of 600 frames), so its cover
//! would seldom be whole before the key changes, and the casts ahead would
//! be work no frame reads (on the H100, 256 blocks a frame ahead made that
//! path's frame 0.151 -> 0.177 ms at p50: `bench/cover-whole/`).
//!
//! The record stays true because only two things write the map's blocks
//! while the key holds: these listed casts, and the deferred frame's own,
//! which cast blocks of that frame's square only. So after a deferred frame
//! every record whose lattice block is not the one the square has at its
//! slot is dropped ([`CoverKeep::after_deferred_frame`]); a record that is
//! the square's block stays right whether that frame kept or recast it. A
//! new key (an edit, another writer, a new texel size or plane) makes every
//! record stale at once.

use super::deferred::MARK_BLOCK;
use crate::frame::{SHADOW_SIZE, Shared};
use crate::methods::contract::Frame;
use strata_camera::Camera;
use strata_camera::light::{ShadowCover, ShadowFrame};

/// Frames a view must have been the same (camera and key) before the
/// cover is cast ahead: a game that draws a frame twice (the gameplay
/// protocol's frame alone) casts nothing ahead.
pub(super) const STILL_FRAMES: u32 = 2;

/// Blocks of the map a side.
const BLOCKS: u32 = SHADOW_SIZE / MARK_BLOCK;

/// How far outside a block's texel centres a cover edge may pass and still
/// count the block in, texels: the cover is evaluated in f32 on the GPU,
/// here per block, and a block too many only costs its cast.
const EDGE_SLACK: f32 = 0.5;

/// What a frame does with the cover (from [`CoverKeep::plan`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(super) struct CoverPlan {
    /// Map blocks (`by * BLOCKS + bx`) to cast before the march.
    pub cast: Vec<u32>,
    /// After those casts every block of the cover is cast: the frame
    /// marches and shades in one pass.
    pub covered: bool,
    /// Lattice block of each listed block (its record once cast).
    lattice: Vec<[i32; 2]>,
    key: u32,
}

/// Which blocks of the shadow map this method's listed casts hold.
pub(super) struct CoverKeep {
    /// Per slot block of the texture: the key and lattice block of its last
    /// listed cast (key 0: none).
    slots: Vec<(u32, [i32; 2])>,
    /// The key and camera of the last frame planned, and for how many
    /// frames before it they were the same.
    last: Option<(u32, Camera)>,
    still: u32,
    /// The cover of the still view was found whole: nothing to scan until
    /// the view, the key or the record changes.
    whole: bool,
    /// The key of the last casts recorded: records of any other key are
    /// stale already.
    recorded_key: u32,
}

impl CoverKeep {
    pub(super) fn new() -> Self {
        CoverKeep {
            slots: vec![(0, [0, 0]); (BLOCKS * BLOCKS) as usize],
            last: None,
            still: 0,
            whole: false,
            recorded_key: 0,
        }
    }

    /// This frame's plan for key `key` (0: nothing is kept), `camera` and
    /// its map `frame`: once the view has been still for [`STILL_FRAMES`]
    /// frames, up to `budget` cover blocks not yet cast, and whether the
    /// cover is then whole. Nothing is recorded until [`CoverKeep::cast`]
    /// says the casts were recorded.
    pub(super) fn plan(
        &mut self,
        key: u32,
        camera: &Camera,
        frame: &ShadowFrame,
        budget: u32,
    ) -> CoverPlan {
        if self.last == Some((key, *camera)) {
            self.still = self.still.saturating_add(1);
        } else {
            (self.last, self.still, self.whole) = (Some((key, *camera)), 0, false);
        }
        let mut plan = CoverPlan {
            key,
            ..CoverPlan::default()
        };
        // A moving view casts nothing ahead: the deferred frame casts what
        // its pixels read.
        if key == 0 || budget == 0 || self.still < STILL_FRAMES {
            return plan;
        }
        if self.whole {
            plan.covered = true;
            return plan;
        }
        let mut missing = 0usize;
        for by in 0..BLOCKS {
            for bx in 0..BLOCKS {
                if !block_in_cover(&frame.cover, bx, by) {
                    continue;
                }
                let lb = lattice_block(frame, bx, by);
                if self.slots[slot(lb)] == (key, lb) {
                    continue;
                }
                missing += 1;
                if plan.cast.len() < budget as usize {
                    plan.cast.push(by * BLOCKS + bx);
                    plan.lattice.push(lb);
                }
            }
        }
        plan.covered = missing == plan.cast.len();
        plan
    }

    /// The plan's casts were recorded (the shadow pass runs this frame).
    pub(super) fn cast(&mut self, plan: &CoverPlan) {
        for &lb in &plan.lattice {
            self.slots[slot(lb)] = (plan.key, lb);
        }
        if !plan.lattice.is_empty() {
            self.recorded_key = plan.key;
        }
        self.whole = plan.covered;
    }

    /// The map's slot blocks `slots` may hold something else now (an edit:
    /// `keep.rs`): their records go.
    pub(super) fn drop_slots(&mut self, slots: &[u32]) {
        for &s in slots {
            self.slots[s as usize].0 = 0;
        }
        self.whole &= slots.is_empty();
    }

    /// A deferred frame over map `frame` ran: its march may have cast any
    /// block of its square, so only records of the square's own blocks stay.
    /// (`key`: the frame's; a moving view's frames, whose key is seldom
    /// that of any record, skip the scan.)
    pub(super) fn after_deferred_frame(&mut self, frame: &ShadowFrame, key: u32) {
        self.whole = false;
        if key != self.recorded_key {
            return;
        }
        for by in 0..BLOCKS {
            for bx in 0..BLOCKS {
                let lb = lattice_block(frame, bx, by);
                let s = slot(lb);
                if self.slots[s].1 != lb {
                    self.slots[s].0 = 0;
                }
            }
        }
    }
}

impl super::RayExact {
    /// This frame's plan for key `key` and `camera`, whose map is `fit`
    /// (`prepare`); recorded with the shadow map, if it is cast.
    pub(super) fn plan_cover(&mut self, key: u32, camera: &Camera, fit: ShadowFrame) {
        let plan = if self.shadow.is_some() {
            self.cover
                .get_mut()
                .plan(key, camera, &fit, self.cover_budget)
        } else {
            CoverPlan::default()
        };
        *self.cover_plan.get_mut() = (key != 0).then_some((plan, fit));
    }

    /// The deferred route's shadow map: cast the plan's cover blocks ahead
    /// of the march. Whether the cover is then whole, so that the frame
    /// marches and shades in one pass (else the march lists what else its
    /// pixels read).
    pub(super) fn record_cover_ahead(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        let (plan, map) = match self.cover_plan.borrow_mut().take() {
            Some((plan, map)) => (plan, Some(map)),
            None => (CoverPlan::default(), None),
        };
        if let (Some(shadow), false) = (&self.shadow, plan.cast.is_empty()) {
            let list = bytemuck::cast_slice(&plan.cast);
            shared.queue.write_buffer(&self.marks.list, 0, list);
            shadow.record_blocks(frame, encoder, plan.cast.len() as u32);
        }
        let mut keep = self.cover.borrow_mut();
        if let Some(map) = map {
            keep.cast(&plan);
            if !plan.covered {
                keep.after_deferred_frame(&map, plan.key);
            }
        }
        self.covered.set(plan.covered);
        plan.covered
    }
}

/// Map block (bx, by)'s block of the light's lattice (`shadow_lattice_block`).
fn lattice_block(frame: &ShadowFrame, bx: u32, by: u32) -> [i32; 2] {
    let b = MARK_BLOCK as i32;
    [
        bx as i32 + frame.lattice[0] / b,
        by as i32 + frame.lattice[1] / b,
    ]
}

/// The texture's slot block that holds lattice block `lb` (`shadow_keep_tag`).
fn slot(lb: [i32; 2]) -> usize {
    let mask = BLOCKS as i32 - 1;
    ((lb[1] & mask) * BLOCKS as i32 + (lb[0] & mask)) as usize
}

/// Whether map block (bx, by) may hold a texel of `cover`: no edge of the
/// cover has all the block's texel centres outside (each edge tested at the
/// centre furthest inside it), with [`EDGE_SLACK`].
pub(super) fn block_in_cover(cover: &ShadowCover, bx: u32, by: u32) -> bool {
    let span = (MARK_BLOCK - 1) as f32;
    let lo = [
        (bx * MARK_BLOCK) as f32 + 0.5,
        (by * MARK_BLOCK) as f32 + 0.5,
    ];
    cover.planes[..cover.count as usize]
        .iter()
        .all(|&[nx, ny, d]| {
            let x = if nx > 0.0 { lo[0] } else { lo[0] + span };
            let y = if ny > 0.0 { lo[1] } else { lo[1] + span };
            nx * x + ny * y + d <= EDGE_SLACK
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use strata_camera::Camera;

    fn camera_at(x: f32, yaw: f32, pitch: f32) -> Camera {
        Camera::new(Vec3::new(x, 8000.0, 300.0), yaw, pitch, 320, 200).unwrap()
    }

    fn frame_at(x: f32, yaw: f32, pitch: f32) -> ShadowFrame {
        ShadowFrame::fit(&camera_at(x, yaw, pitch), true)
    }

    #[test]
    fn every_covered_texel_lies_in_a_listed_block() {
        for (yaw, pitch) in [(0.0, 0.0), (37.0, -30.0), (200.0, -90.0), (300.0, -60.0)] {
            let frame = frame_at(1000.0, yaw, pitch);
            let cover = frame.cover;
            let mut blocks = 0;
            for by in 0..BLOCKS {
                for bx in 0..BLOCKS {
                    let listed = block_in_cover(&cover, bx, by);
                    blocks += u32::from(listed);
                    let any = (0..MARK_BLOCK).any(|j| {
                        (0..MARK_BLOCK)
                            .any(|i| cover.covers(bx * MARK_BLOCK + i, by * MARK_BLOCK + j))
                    });
                    assert!(listed || !any, "block ({bx}, {by}) has a covered texel");
                }
            }
            // The block test is not everything: the cover is a part of the map.
            assert!(
                blocks < BLOCKS * BLOCKS,
                "yaw {yaw} pitch {pitch}: every block"
            );
            assert!(blocks > 0);
        }
    }

    #[test]
    fn a_still_view_lists_the_cover_in_budgets_and_then_nothing() {
        let camera = camera_at(1000.0, 37.0, -30.0);
        let frame = ShadowFrame::fit(&camera, true);
        let mut keep = CoverKeep::new();
        // The view's first frames cast nothing ahead.
        for _ in 0..STILL_FRAMES {
            let first = keep.plan(5, &camera, &frame, 1000);
            assert!(first.cast.is_empty() && !first.covered);
        }
        let mut total = 0;
        let mut frames = 0;
        loop {
            let plan = keep.plan(5, &camera, &frame, 1000);
            assert!(plan.cast.len() <= 1000);
            keep.cast(&plan);
            total += plan.cast.len();
            frames += 1;
            if plan.covered {
                break;
            }
            assert!(frames < 100);
        }
        let cover_blocks = (0..BLOCKS * BLOCKS)
            .filter(|b| block_in_cover(&frame.cover, b % BLOCKS, b / BLOCKS))
            .count();
        assert_eq!(total, cover_blocks);
        let again = keep.plan(5, &camera, &frame, 1000);
        assert!(again.covered && again.cast.is_empty());
        keep.cast(&again);
        // A moved camera, then a new key, start over.
        let moved = camera_at(1001.0, 37.0, -30.0);
        assert!(!keep.plan(5, &moved, &frame, 1000).covered);
        for _ in 0..STILL_FRAMES {
            assert!(!keep.plan(6, &camera, &frame, 1000).covered);
        }
        let next = keep.plan(6, &camera, &frame, 100_000);
        assert_eq!(next.cast.len(), cover_blocks);
        assert!(next.covered);
    }

    #[test]
    fn a_deferred_frame_drops_records_of_blocks_outside_its_square() {
        let camera = camera_at(1000.0, 37.0, -30.0);
        let here = ShadowFrame::fit(&camera, true);
        let mut keep = CoverKeep::new();
        for _ in 0..STILL_FRAMES {
            keep.plan(1, &camera, &here, 100_000);
        }
        let plan = keep.plan(1, &camera, &here, 100_000);
        keep.cast(&plan);
        assert!(keep.plan(1, &camera, &here, 100_000).covered);
        // A deferred frame over the same square keeps every record.
        keep.after_deferred_frame(&here, 1);
        assert!(keep.plan(1, &camera, &here, 100_000).covered);
        // One over a square far away (same texel size and plane: same key)
        // may have cast its blocks into every slot.
        let mut away = here;
        away.lattice = [here.lattice[0] + 8 * 300, here.lattice[1] + 8 * 77];
        keep.after_deferred_frame(&away, 1);
        let back = keep.plan(1, &camera, &here, 100_000);
        assert!(!back.cast.is_empty());
    }
}
