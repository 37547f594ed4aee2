//! `compare --gameplay [K]` (issue 35): a game edits the terrain all the
//! time. K small edits a frame along the video's default camera path —
//! vehicles' tracks of radius 2–6 texels ahead of the camera, a crater now
//! and then, a slab carved away or built, the edits of an older frame
//! undone — deterministic from a seed. Each frame's edits go to every
//! method through its own update path ([`Renderer::apply_edit`]: texture
//! sub-uploads, pyramid and occupancy updates, mesh refit), timed, then the
//! frame, then the same camera again with no edit (the frame alone). At
//! sampled frames and at the end the edited renderer is checked against a
//! renderer built fresh from the edited level, as the single-crater
//! protocol checks it ([`crate::edits`]). The terrain collider follows the
//! same edits on the CPU ([`follow_collider`]).

use crate::edits::{self, FreshBuild};
use crate::results::gameplay::{GameplayCheck, GameplayRow, Spread};
use crate::video::path::{Flight, default_path};
use crate::warm::ms;
use anyhow::Context;
use std::time::Instant;
use strata_camera::Camera;
use strata_level::edit::{EditRect, Snapshot, crater, edit_columns};
use strata_level::{Column, DirtyRect, EditSite, Level, World};
use strata_render::{MethodSettings, Renderer};

/// K when `--gameplay` is given without a number.
pub const DEFAULT_EDITS_PER_FRAME: u32 = 64;
/// The most small edits a frame `--gameplay` takes.
pub const MAX_EDITS_PER_FRAME: u32 = 4096;
/// A check also needs at most this percent of pixels to differ from the
/// fresh build ([`edits::differing_pixels`]): the protocol's p95 alone does
/// not see track stamps that cover a few percent of the image.
pub const MAX_DIFFERING_PIXELS: f64 = crate::results::EDIT_MAX_CLASS_MISMATCH;
/// Frames a game runs at, for the camera path's speed.
const FPS: f32 = 60.0;

/// The workload's size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GameplaySpec {
    /// K: track stamps a frame.
    pub edits_per_frame: u32,
    /// Frames of edits.
    pub frames: u32,
    /// Check against a fresh build after every this many frames (and after the last).
    pub check_every: u32,
    pub seed: u64,
}

impl GameplaySpec {
    /// The workload: 600 frames (10 s of the path at 60 fps), a
    /// check every 100.
    pub fn full(edits_per_frame: u32) -> Self {
        GameplaySpec {
            edits_per_frame,
            frames: 600,
            check_every: 100,
            seed: 35,
        }
    }

    /// `--quick`: 24 frames, checked at frame 12 and at the end.
    pub fn quick(edits_per_frame: u32) -> Self {
        GameplaySpec {
            frames: 24,
            check_every: 12,
            ..Self::full(edits_per_frame)
        }
    }

    /// Refuse sizes that make no workload.
    pub fn check(&self) -> anyhow::Result<()> {
        if !(1..=MAX_EDITS_PER_FRAME).contains(&self.edits_per_frame) {
            anyhow::bail!(
                "--gameplay {}: the edits per frame must be in 1..={MAX_EDITS_PER_FRAME}",
                self.edits_per_frame
            );
        }
        if self.frames == 0 || self.check_every == 0 {
            anyhow::bail!("the gameplay workload needs at least one frame and one check");
        }
        Ok(())
    }

    /// Whether frame `f` (0-based) is followed by a check.
    pub fn checks_after(&self, f: u32) -> bool {
        (f + 1).is_multiple_of(self.check_every) || f + 1 == self.frames
    }

    /// Every how many frames a crater, a slab and an undo come.
    fn periods(&self) -> (u32, u32, u32) {
        let n = self.frames;
        ((n / 6).max(1), (n / 8).max(1), (n / 12).max(1))
    }
}

/// One edit of the workload, in unwrapped texel coordinates (the map wraps).
#[derive(Clone, Debug, PartialEq)]
pub enum GameEdit {
    /// A vehicle's track: the floor lowered by up to `depth` within
    /// `radius` (profile `1 - d²/r²`); slabs over it stay.
    Track {
        x: i64,
        y: i64,
        radius: u32,
        depth: f32,
    },
    /// The paper's crater (the upper layer removed inside).
    Crater(EditSite),
    /// The upper layer removed over a rectangle (dual columns become single
    /// at their floor).
    CarveSlab(EditRect),
    /// A slab built over a rectangle: its bottom `gap` over the floor, `thickness` thick.
    BuildSlab {
        rect: EditRect,
        gap: u8,
        thickness: u8,
    },
    /// Every edit of workload frame `frame` undone: its texels restored as
    /// they were before it (changes a later edit made there go too).
    Undo { frame: u32 },
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0 .. 1`.
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn below(&mut self, n: u32) -> u32 {
        (self.next() % u64::from(n.max(1))) as u32
    }
}

/// The workload on one world: its camera path and its edits, frame by frame.
pub struct Workload {
    spec: GameplaySpec,
    flight: Flight,
    start: f32,
    seconds: f32,
    /// Per frame, where each vehicle is (unwrapped texels).
    vehicles: Vec<[(f32, f32); VEHICLES.len()]>,
}

/// Vehicles laying tracks where the camera looks: the ground seen through
/// these image points (fractions of the width and height, from the top
/// left) on the level before any edit.
const VEHICLES: [(f32, f32); 4] = [(0.3, 0.7), (0.45, 0.8), (0.6, 0.65), (0.72, 0.85)];

impl Workload {
    /// The video's default path over `world` played at 60 fps for the
    /// spec's frames, for images of `width` x `height` (where the
    /// vehicles are seen depends on the image's shape).
    pub fn new(world: &World, spec: GameplaySpec, width: u32, height: u32) -> anyhow::Result<Self> {
        spec.check()?;
        let seconds = spec.frames as f32 / FPS;
        let flight = default_path(world)
            .retimed(seconds)
            .resolve(&world.level)
            .context("the gameplay workload's camera path")?;
        let mut w = Workload {
            spec,
            start: flight.start(),
            flight,
            seconds,
            vehicles: Vec::new(),
        };
        let tracer = strata_reference::Tracer::unaccelerated(&world.level);
        let settings = strata_reference::ReferenceSettings::default();
        for f in 0..spec.frames {
            let cam = w.camera(&world.level, f, width, height)?;
            let origin = cam.position.as_dvec3();
            let forward = (cam.image_direction(0.5 * width as f32, 0.5 * height as f32))
                .normalize()
                .as_dvec3();
            w.vehicles.push(std::array::from_fn(|v| {
                let (u, t) = VEHICLES[v];
                let dir = cam
                    .image_direction(u * width as f32, t * height as f32)
                    .normalize()
                    .as_dvec3();
                let hit = tracer.trace(origin, dir, f64::from(cam.far), &settings);
                // Sky there: a point ahead, on the camera's heading.
                let p = match hit {
                    Some(h) => origin + dir * h.distance,
                    None => origin + forward * 80.0,
                };
                (p.x as f32, p.y as f32)
            }));
        }
        Ok(w)
    }

    pub fn spec(&self) -> &GameplaySpec {
        &self.spec
    }

    fn time(&self, f: u32) -> f32 {
        self.start + self.seconds * f as f32 / self.spec.frames.max(2).saturating_sub(1) as f32
    }

    /// The camera of frame `f` over `level` (the edited level: the camera
    /// is lifted out of terrain where the path cuts it).
    pub fn camera(&self, level: &Level, f: u32, width: u32, height: u32) -> anyhow::Result<Camera> {
        self.flight.camera(level, self.time(f), width, height)
    }

    /// Where vehicle `v` is at frame `f` (unwrapped texels), with a slow
    /// weave so tracks are not straight lines.
    fn vehicle(&self, v: usize, f: u32) -> (f32, f32) {
        let (x, y) = self.vehicles[f as usize][v];
        let phase = f as f32 * 0.07 + v as f32;
        (x + 4.0 * phase.sin(), y + 4.0 * phase.cos())
    }

    /// The edits of frame `f`, in order.
    pub fn edits(&self, f: u32) -> Vec<GameEdit> {
        let spec = &self.spec;
        let mut rng = Rng(spec.seed ^ u64::from(f).wrapping_mul(0xA076_1D64_78BD_642F));
        let mut out = Vec::new();
        let k = spec.edits_per_frame as usize;
        let n = VEHICLES.len();
        for v in 0..n {
            let stamps = k / n + usize::from(v < k % n);
            let (x0, y0) = self.vehicle(v, f.saturating_sub(1));
            let (x1, y1) = self.vehicle(v, f);
            for j in 0..stamps {
                let s = (j + 1) as f32 / stamps as f32;
                let jitter = |rng: &mut Rng| (rng.unit() - 0.5) * 2.0;
                out.push(GameEdit::Track {
                    x: (x0 + (x1 - x0) * s + jitter(&mut rng)).floor() as i64,
                    y: (y0 + (y1 - y0) * s + jitter(&mut rng)).floor() as i64,
                    radius: 2 + rng.below(5),
                    depth: 1.0 + 2.0 * rng.unit(),
                });
            }
        }
        let (crater_every, slab_every, undo_every) = spec.periods();
        let (ax, ay) = self.vehicle(1, f);
        if f % crater_every == crater_every / 2 {
            let radius = 8 + rng.below(9);
            out.push(GameEdit::Crater(EditSite {
                centre_x: ax.floor() as i64,
                centre_y: ay.floor() as i64,
                radius,
                depth: 10.0 + 20.0 * rng.unit(),
                ..EditSite::fostral()
            }));
        }
        if f % slab_every == slab_every - 1 {
            let side = 8 + rng.below(17);
            let (sx, sy) = self.vehicle(3, f);
            let rect = EditRect {
                x: sx.floor() as i64 - i64::from(side / 2),
                y: sy.floor() as i64 - i64::from(side / 2),
                width: side,
                height: side,
            };
            out.push(if (f / slab_every).is_multiple_of(2) {
                GameEdit::BuildSlab {
                    rect,
                    gap: 12 + rng.below(12) as u8,
                    thickness: 4 + rng.below(8) as u8,
                }
            } else {
                GameEdit::CarveSlab(rect)
            });
        }
        if f > 0 && f.is_multiple_of(undo_every) && f >= 2 * undo_every {
            out.push(GameEdit::Undo {
                frame: f - 2 * undo_every,
            });
        }
        out
    }
}

/// A vehicle's track stamp (see [`GameEdit::Track`]).
fn track(level: &mut Level, (cx, cy): (i64, i64), radius: u32, depth: f32) -> Vec<DirtyRect> {
    let r = i64::from(radius);
    let r2 = (radius as f32).powi(2);
    let rect = EditRect {
        x: cx - r,
        y: cy - r,
        width: 2 * radius + 1,
        height: 2 * radius + 1,
    };
    edit_columns(level, rect, |x, y, c| {
        let (dx, dy) = ((x - cx) as f32, (y - cy) as f32);
        let d2 = dx * dx + dy * dy;
        if d2 >= r2 {
            return c;
        }
        let low = (f32::from(c.low) - depth * (1.0 - d2 / r2))
            .round()
            .clamp(0.0, 255.0) as u8;
        match c.dual {
            true => Column { low, ..c },
            false => Column {
                low,
                mid: low,
                high: low,
                ..c
            },
        }
    })
}

/// The rectangle a [`GameEdit`] may touch (`None` for an undo).
fn rect_of(edit: &GameEdit) -> Option<EditRect> {
    match edit {
        GameEdit::Track { x, y, radius, .. } => {
            let r = i64::from(*radius);
            Some(EditRect {
                x: x - r,
                y: y - r,
                width: 2 * radius + 1,
                height: 2 * radius + 1,
            })
        }
        GameEdit::Crater(site) => Some(strata_level::edit::crater_rect(site)),
        GameEdit::CarveSlab(rect) | GameEdit::BuildSlab { rect, .. } => Some(*rect),
        GameEdit::Undo { .. } => None,
    }
}

/// The level as the workload edits it, with the undo snapshots.
pub struct Replay {
    level: Level,
    /// Per workload frame, the snapshots of its edits in order.
    undo: Vec<Vec<Snapshot>>,
    /// Edits applied so far.
    pub edits: u64,
}

impl Replay {
    pub fn new(level: Level) -> Self {
        Replay {
            level,
            undo: Vec::new(),
            edits: 0,
        }
    }

    pub fn level(&self) -> &Level {
        &self.level
    }

    /// Apply frame `f`'s edits; returns the dirty rectangles (one list for
    /// the frame, as a game hands a frame's edits over).
    pub fn apply(&mut self, f: u32, edits: &[GameEdit]) -> Vec<DirtyRect> {
        let f = f as usize;
        if self.undo.len() <= f {
            self.undo.resize_with(f + 1, Vec::new);
        }
        let mut dirty = Vec::new();
        for e in edits {
            self.edits += 1;
            if let Some(rect) = rect_of(e) {
                let snapshot = Snapshot::take(&self.level, rect);
                self.undo[f].push(snapshot);
            }
            let level = &mut self.level;
            dirty.extend(match e {
                GameEdit::Track {
                    x,
                    y,
                    radius,
                    depth,
                } => track(level, (*x, *y), *radius, *depth),
                GameEdit::Crater(site) => crater(level, site),
                GameEdit::CarveSlab(rect) => edit_columns(level, *rect, |_, _, c| match c.dual {
                    true => Column {
                        mid: c.low,
                        high: c.low,
                        dual: false,
                        upper_type: c.lower_type,
                        ..c
                    },
                    false => c,
                }),
                GameEdit::BuildSlab {
                    rect,
                    gap,
                    thickness,
                } => edit_columns(level, *rect, |_, _, c| {
                    let mid = c.low.saturating_add(*gap);
                    let high = mid.saturating_add(*thickness);
                    if high == u8::MAX {
                        return c;
                    }
                    Column {
                        mid,
                        high,
                        dual: true,
                        upper_type: 3,
                        ..c
                    }
                }),
                GameEdit::Undo { frame } => {
                    let snapshots = self
                        .undo
                        .get_mut(*frame as usize)
                        .map(std::mem::take)
                        .unwrap_or_default();
                    snapshots
                        .iter()
                        .rev()
                        .flat_map(|s| s.restore(level))
                        .collect()
                }
            });
        }
        dirty
    }
}

/// Texels the rectangles cover (overlaps counted again).
pub fn texels(rects: &[DirtyRect]) -> u64 {
    rects
        .iter()
        .map(|r| u64::from(r.width) * u64::from(r.height))
        .sum()
}

/// The passes of a frame that bring derived data up to date after an edit.
fn update_ms(t: &strata_render::FrameTimings) -> f64 {
    // fold from +0: an empty f64 sum is -0.
    t.passes
        .iter()
        .filter(|(label, _)| label.ends_with("update"))
        .fold(0.0, |sum, (_, ms)| sum + ms)
}

/// What [`method_row`] needs besides the workload and the method.
pub struct GameplayInput<'a> {
    pub world: &'a World,
    /// Fresh builds for the checks (its camera is replaced per check).
    pub fresh: FreshBuild<'a>,
    pub width: u32,
    pub height: u32,
}

/// One method through the whole workload.
pub fn method_row(
    input: &GameplayInput<'_>,
    workload: &Workload,
    label: &str,
    name: &str,
    settings: &MethodSettings,
) -> anyhow::Result<GameplayRow> {
    let spec = workload.spec();
    let (w, h) = (input.width, input.height);
    let mut replay = Replay::new(input.world.level.clone());
    let cam0 = workload.camera(replay.level(), 0, w, h)?;
    let mut r = edits::build(
        &FreshBuild {
            camera: &cam0,
            ..input.fresh
        },
        replay.level(),
        name,
        settings,
    )?;
    let timestamps = input.fresh.timestamps;
    let n = spec.frames as usize;
    let (mut edit_cpu, mut edit_gpu) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut with_cpu, mut with_gpu) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut alone_cpu, mut alone_gpu) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut checks = Vec::new();
    let mut lag = EditLag::default();
    for f in 0..spec.frames {
        let rects = replay.apply(f, &workload.edits(f));
        let cam = workload.camera(replay.level(), f, w, h)?;
        let start = Instant::now();
        r.apply_edit(replay.level(), &rects)
            .with_context(|| format!("frame {f}: applying the edits"))?;
        edit_cpu.push(ms(start));
        lag.applied();
        let t = r.render_frame(&cam)?;
        with_cpu.push(ms(start));
        lag.drawn(&r);
        if let Some(g) = t.gpu_ms {
            with_gpu.push(g);
            edit_gpu.push(update_ms(&t));
        }
        if spec.checks_after(f) {
            lag.settling();
            checks.push(check(
                input,
                &mut r,
                replay.level(),
                &cam,
                f,
                name,
                settings,
            )?);
            // The check's fresh build keeps the CPU busy for up to seconds
            // (`mesh` fits the whole level) while the GPU idles and drops
            // its clock: bring it back to its busy clock, untimed, so the
            // frames after a check are timed as the others are.
            let hold = input.fresh.hold_busy_ms;
            if hold > 0 {
                r.hold_busy(&cam, std::time::Duration::from_millis(u64::from(hold)))?;
            }
        }
        let start = Instant::now();
        let t = r.render_frame(&cam)?;
        alone_cpu.push(ms(start));
        lag.drawn(&r);
        alone_gpu.extend(t.gpu_ms);
    }
    let timed = |g: &[f64]| {
        (timestamps && g.len() == n)
            .then(|| Spread::of(g))
            .flatten()
    };
    let spread = |c: &[f64]| Spread::of(c).context("no frames");
    Ok(GameplayRow {
        method: label.to_string(),
        edit_cpu_ms: spread(&edit_cpu)?,
        edit_gpu_ms: timed(&edit_gpu),
        with_edits_cpu_ms: spread(&with_cpu)?,
        with_edits_gpu_ms: timed(&with_gpu),
        alone_cpu_ms: spread(&alone_cpu)?,
        alone_gpu_ms: timed(&alone_gpu),
        consistent: checks.iter().all(|c| c.consistent_after_frames.is_some()),
        edit_lag_frames: Spread::of(&lag.frames),
        checks,
        edit_cpu_samples: edit_cpu,
        with_edits_cpu_samples: with_cpu,
        with_edits_gpu_samples: if timestamps { with_gpu } else { Vec::new() },
    })
}

/// How many frames each frame's edits take to be drawn in full
/// ([`Renderer::pending_edits`]): 0 when the first frame drawn after
/// `apply_edit` shows them (every method but `mesh`, whose refits run off
/// the frame). Every frame drawn counts (the workload draws each camera
/// twice: with its edits, then alone); batches a check settles are left out.
#[derive(Default)]
struct EditLag {
    /// Frames drawn so far.
    drawn: u64,
    /// Per batch handed over: frames drawn before it.
    applied_at: Vec<u64>,
    /// Batches shown (or left out) so far.
    shown: usize,
    /// Per batch shown: its lag in frames.
    frames: Vec<f64>,
}

impl EditLag {
    fn applied(&mut self) {
        self.applied_at.push(self.drawn);
    }

    fn drawn(&mut self, r: &Renderer) {
        self.drawn += 1;
        let pending = usize::try_from(r.pending_edits()).unwrap_or(usize::MAX);
        let shown = self.applied_at.len().saturating_sub(pending);
        for &at in &self.applied_at[self.shown.min(shown)..shown] {
            self.frames.push((self.drawn - at - 1) as f64);
        }
        self.shown = self.shown.max(shown);
    }

    /// A check settles every batch handed over: leave those not yet shown out.
    fn settling(&mut self) {
        self.shown = self.applied_at.len();
    }
}

/// The edited renderer against one built fresh from the edited level,
/// once the work its edits left in flight is done (`mesh`'s refits;
/// untimed).
fn check(
    input: &GameplayInput<'_>,
    r: &mut Renderer,
    level: &Level,
    cam: &Camera,
    frame: u32,
    name: &str,
    settings: &MethodSettings,
) -> anyhow::Result<GameplayCheck> {
    let fresh_input = FreshBuild {
        camera: cam,
        hold_busy_ms: 0,
        ..input.fresh
    };
    edits::settle(r, cam).with_context(|| format!("frame {frame}: settling the edits"))?;
    let fresh = edits::build(&fresh_input, level, name, settings)
        .with_context(|| format!("frame {frame}: the fresh build"))?;
    let target = edits::distance(&fresh, cam)?;
    drop(fresh);
    let mut differing = 0.0;
    let found = edits::checks_until(r, cam, &target, 1, |seen| {
        differing = edits::differing_pixels(seen, &target);
        differing <= MAX_DIFFERING_PIXELS
    })?;
    let last = found.last().context("no check made")?;
    Ok(GameplayCheck {
        frame,
        consistent_after_frames: edits::consistent_after(&found).map(|n| n - 1),
        class_mismatch: last.class_mismatch,
        depth_p95: last.depth_p95,
        differing_pixels: differing,
    })
}

/// The workload on the CPU alone: the level edits' cost per frame, the
/// edits and dirty texels, and the terrain collider following them (its
/// refit per frame, and whether it equals a fresh build at every check).
pub struct CpuFollow {
    pub level_edit_ms: Vec<f64>,
    pub edits: u64,
    pub dirty_texels: u64,
    pub collider: Option<(Vec<f64>, bool)>,
}

/// Replay the workload on the CPU (see [`CpuFollow`]).
pub fn follow_collider(world: &World, workload: &Workload) -> CpuFollow {
    let spec = workload.spec();
    let mut replay = Replay::new(world.level.clone());
    let mut level_ms = Vec::new();
    let mut dirty_texels = 0;
    #[cfg(not(target_arch = "wasm32"))]
    let mut collider = strata_collide::TerrainCollider::new(replay.level());
    #[cfg(not(target_arch = "wasm32"))]
    let (mut refit, mut same) = (Vec::new(), true);
    for f in 0..spec.frames {
        let edits = workload.edits(f);
        let start = Instant::now();
        let rects = replay.apply(f, &edits);
        level_ms.push(ms(start));
        dirty_texels += texels(&rects);
        #[cfg(not(target_arch = "wasm32"))]
        {
            let start = Instant::now();
            collider.apply_edit(replay.level(), &rects);
            refit.push(ms(start));
            if spec.checks_after(f) {
                same &= collider == strata_collide::TerrainCollider::new(replay.level());
            }
        }
    }
    #[cfg(not(target_arch = "wasm32"))]
    let collider = Some((refit, same));
    #[cfg(target_arch = "wasm32")]
    let collider = None;
    CpuFollow {
        level_edit_ms: level_ms,
        edits: replay.edits,
        dirty_texels,
        collider,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::generate::{GenerateParams, generate};

    fn world() -> World {
        generate(&GenerateParams {
            seed: 7,
            width: 256,
            height: 1024,
        })
        .unwrap()
    }

    fn spec(edits_per_frame: u32, frames: u32, check_every: u32, seed: u64) -> GameplaySpec {
        GameplaySpec {
            edits_per_frame,
            frames,
            check_every,
            seed,
        }
    }

    #[test]
    fn the_workload_is_deterministic_and_has_every_kind_of_edit() {
        let world = world();
        let spec = spec(6, 24, 12, 3);
        let a = Workload::new(&world, spec, 64, 40).unwrap();
        let b = Workload::new(&world, spec, 64, 40).unwrap();
        let all: Vec<GameEdit> = (0..spec.frames).flat_map(|f| a.edits(f)).collect();
        assert_eq!(
            all,
            (0..spec.frames)
                .flat_map(|f| b.edits(f))
                .collect::<Vec<_>>()
        );
        let count = |p: fn(&GameEdit) -> bool| all.iter().filter(|e| p(e)).count();
        assert_eq!(count(|e| matches!(e, GameEdit::Track { .. })), 6 * 24);
        assert!(count(|e| matches!(e, GameEdit::Crater(_))) >= 3);
        assert!(count(|e| matches!(e, GameEdit::BuildSlab { .. })) >= 1);
        assert!(count(|e| matches!(e, GameEdit::CarveSlab(_))) >= 1);
        assert!(count(|e| matches!(e, GameEdit::Undo { .. })) >= 1);
        for e in &all {
            if let GameEdit::Track { radius, depth, .. } = e {
                assert!((2..=6).contains(radius) && (1.0..=3.0).contains(depth));
            }
        }
        // Another seed, other edits.
        let c = Workload::new(&world, GameplaySpec { seed: 4, ..spec }, 64, 40).unwrap();
        assert_ne!(a.edits(5), c.edits(5));
    }

    #[test]
    fn replays_agree_and_undo_restores_the_texels() {
        let world = world();
        let spec = spec(8, 30, 10, 9);
        let w = Workload::new(&world, spec, 64, 40).unwrap();
        let (mut a, mut b) = (
            Replay::new(world.level.clone()),
            Replay::new(world.level.clone()),
        );
        let mut changed = 0;
        for f in 0..spec.frames {
            let edits = w.edits(f);
            let ra = a.apply(f, &edits);
            assert_eq!(ra, b.apply(f, &edits));
            changed += texels(&ra);
        }
        assert!(changed > 0, "the workload changed nothing");
        assert_eq!(a.level().content_hash(), b.level().content_hash());
        assert_ne!(a.level().content_hash(), world.level.content_hash());

        // Undoing a frame right after it restores every byte.
        let mut r = Replay::new(world.level.clone());
        r.apply(0, &w.edits(0));
        r.apply(1, &[GameEdit::Undo { frame: 0 }]);
        assert_eq!(r.level().content_hash(), world.level.content_hash());
    }

    #[test]
    fn the_collider_follows_the_workload() {
        let world = world();
        let spec = spec(16, 12, 6, 1);
        let w = Workload::new(&world, spec, 64, 40).unwrap();
        let follow = follow_collider(&world, &w);
        let (refit, same) = follow.collider.unwrap();
        assert_eq!(refit.len(), 12);
        assert!(same, "the followed collider differs from a fresh build");
        assert!(follow.edits >= 16 * 12 && follow.dirty_texels > 0);
    }

    #[test]
    fn bad_specs_are_refused() {
        for bad in [0, MAX_EDITS_PER_FRAME + 1] {
            assert!(GameplaySpec::full(bad).check().is_err());
        }
        let s = GameplaySpec::quick(4);
        assert!(s.check().is_ok());
        assert!(s.checks_after(11) && s.checks_after(23) && !s.checks_after(12));
    }
}
