//! The dynamic-edit protocol (paper §Dynamic-edit protocol): per method, the
//! median of independent first post-edit frames, the steady frame of a
//! renderer built fresh from the edited level, and after how many post-edit
//! frames the edited renderer agrees with that fresh build.

use crate::results::{
    EDIT_CHECK_FRAMES, EDIT_MAX_CLASS_MISMATCH, EDIT_MAX_DEPTH_P95, EditCheck, EditRow,
};
use crate::stats::{median, percentile};
use crate::warm::{ms, warm_up};
use std::time::Instant;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

/// Independent first post-edit frames per method.
pub const FIRST_FRAME_SAMPLES: usize = 5;

pub struct EditInput<'a> {
    pub gpu: &'a Gpu,
    pub original: &'a Level,
    pub edited: &'a Level,
    pub rects: &'a [DirtyRect],
    pub colors: &'a TerrainColors,
    pub camera: &'a Camera,
    /// Most frames before the edit (and before the fresh build is sampled):
    /// one frame, continued while an incremental build is in flight, so the
    /// edit meets a settled renderer.
    pub warmup_cap: u32,
    /// Ms of untimed frames back to back after that warm-up, so the edit
    /// frame is timed at the GPU's busy clock (see `Options::hold_busy_ms`).
    pub hold_busy_ms: u32,
    pub timestamps: bool,
    /// Frames of the fresh edited build whose median is the steady time.
    pub steady_frames: u32,
}

/// Percent of pixels where exactly one image has terrain, and the 95th
/// percentile of |a - b| where both do (0 when none do).
pub fn disagreement(a: &[f32], b: &[f32]) -> (f64, f64) {
    let n = a.len().min(b.len()).max(1);
    let mut mismatch = 0usize;
    let mut diffs = Vec::new();
    for (x, y) in a.iter().zip(b) {
        match (x.is_finite(), y.is_finite()) {
            (true, true) => diffs.push(f64::from((x - y).abs())),
            (false, false) => {}
            _ => mismatch += 1,
        }
    }
    (
        100.0 * mismatch as f64 / n as f64,
        percentile(&diffs, 0.95).unwrap_or(0.0),
    )
}

/// Percent of pixels where the images differ by more than the protocol
/// allows anywhere: one has terrain and the other sky, or both hit and the
/// distances differ by more than [`EDIT_MAX_DEPTH_P95`]. Stricter than
/// [`disagreement`]'s p95 for edits that cover a small part of the image
/// (a track stamp), which a p95 over all pixels does not see.
pub fn differing_pixels(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    let differ = a
        .iter()
        .zip(b)
        .filter(|(x, y)| match (x.is_finite(), y.is_finite()) {
            (true, true) => f64::from((*x - *y).abs()) > EDIT_MAX_DEPTH_P95,
            (false, false) => false,
            _ => true,
        })
        .count();
    100.0 * differ as f64 / n as f64
}

/// The first checked frame count at which the images agree, if any.
pub fn consistent_after(checks: &[EditCheck]) -> Option<u32> {
    checks.iter().find(|c| c.consistent).map(|c| c.frames)
}

/// What a renderer built fresh for a check needs besides its level and method.
#[derive(Clone, Copy)]
pub struct FreshBuild<'a> {
    pub gpu: &'a Gpu,
    pub colors: &'a TerrainColors,
    pub camera: &'a Camera,
    /// See [`EditInput::warmup_cap`].
    pub warmup_cap: u32,
    /// See [`EditInput::hold_busy_ms`] (0: none).
    pub hold_busy_ms: u32,
    pub timestamps: bool,
}

impl EditInput<'_> {
    fn fresh(&self) -> FreshBuild<'_> {
        FreshBuild {
            gpu: self.gpu,
            colors: self.colors,
            camera: self.camera,
            warmup_cap: self.warmup_cap,
            hold_busy_ms: self.hold_busy_ms,
            timestamps: self.timestamps,
        }
    }
}

/// `name` built on `level` and warmed up at the camera: one frame, continued
/// while an incremental build is in flight (then held busy, if asked).
pub fn build(
    input: &FreshBuild<'_>,
    level: &Level,
    name: &str,
    settings: &MethodSettings,
) -> anyhow::Result<Renderer> {
    let mut r = Renderer::new(
        input.gpu,
        level,
        input.colors,
        name,
        settings,
        input.camera.width,
        input.camera.height,
    )?;
    warm_up(&mut r, input.camera, 1, input.warmup_cap, input.timestamps)?;
    if input.hold_busy_ms > 0 {
        r.hold_busy(
            input.camera,
            // Four holds: it follows the renderer's setup (see `Plan::cell`).
            std::time::Duration::from_millis(4 * u64::from(input.hold_busy_ms)),
        )?;
    }
    Ok(r)
}

/// Distance along each pixel's ray of the renderer's last frame.
pub fn distance(r: &Renderer, camera: &Camera) -> anyhow::Result<Vec<f32>> {
    Ok(strata_reference::distance_from_depth(
        camera,
        &r.read_depth()?,
    ))
}

/// Finish the work the edits left in flight (`mesh`'s refits), untimed, so
/// that a check compares the settled state; where the last frame did not
/// show every edit yet, draw it again (it then counts as the first post-edit
/// frame). Methods whose next frame shows their edits draw nothing more.
pub fn settle(r: &mut Renderer, cam: &Camera) -> anyhow::Result<()> {
    let late = r.pending_edits() > 0;
    r.settle_edits()?;
    if late {
        r.render_frame(cam)?;
    }
    Ok(())
}

/// Compare an edited renderer that has drawn `drawn` frames since its edit
/// with `target` (a fresh build's distances) after each of
/// [`EDIT_CHECK_FRAMES`] post-edit frames, drawing the frames between, up
/// to the first consistent check.
pub fn checks_until_consistent(
    r: &mut Renderer,
    cam: &Camera,
    target: &[f32],
    drawn: u32,
) -> anyhow::Result<Vec<EditCheck>> {
    checks_until(r, cam, target, drawn, |_| true)
}

/// [`checks_until_consistent`] where a check is consistent only if `also`
/// accepts the edited renderer's distances too.
pub fn checks_until(
    r: &mut Renderer,
    cam: &Camera,
    target: &[f32],
    drawn: u32,
    mut also: impl FnMut(&[f32]) -> bool,
) -> anyhow::Result<Vec<EditCheck>> {
    let mut checks = Vec::new();
    let mut done = drawn;
    for frames in EDIT_CHECK_FRAMES.into_iter().filter(|&f| f >= drawn) {
        while done < frames {
            r.render_frame(cam)?;
            done += 1;
        }
        let seen = distance(r, cam)?;
        let (class_mismatch, depth_p95) = disagreement(&seen, target);
        let consistent = class_mismatch <= EDIT_MAX_CLASS_MISMATCH
            && depth_p95 <= EDIT_MAX_DEPTH_P95
            && also(&seen);
        checks.push(EditCheck {
            frames,
            class_mismatch,
            depth_p95,
            consistent,
        });
        // The answer is the first consistent count; later frames cannot change it.
        if consistent {
            break;
        }
    }
    Ok(checks)
}

/// The edit camera's colour (RGBA8) just before the edit and on the first
/// post-edit frame, from the protocol's first sample: the edit figure.
pub struct EditPictures {
    pub before: Vec<u8>,
    pub after: Vec<u8>,
}

/// Run the protocol for one method.
pub fn edit_row(
    input: &EditInput<'_>,
    name: &str,
    settings: &MethodSettings,
) -> anyhow::Result<(EditRow, EditPictures)> {
    let cam = input.camera;
    // The fresh build of the already-edited level: steady time and the target image.
    let mut fresh = build(&input.fresh(), input.edited, name, settings)?;
    let (mut steady_cpu, mut steady_gpu) = (Vec::new(), Vec::new());
    for _ in 0..input.steady_frames.max(1) {
        let t = fresh.render_frame(cam)?;
        steady_cpu.push(t.cpu_ms);
        steady_gpu.extend(t.gpu_ms);
    }
    let target = distance(&fresh, cam)?;
    drop(fresh);

    let (mut first_cpu, mut first_gpu) = (Vec::new(), Vec::new());
    let mut checks = Vec::new();
    let mut pictures = EditPictures {
        before: Vec::new(),
        after: Vec::new(),
    };
    for sample in 0..FIRST_FRAME_SAMPLES {
        let mut r = build(&input.fresh(), input.original, name, settings)?;
        if sample == 0 {
            // Read before the clock starts: the picture costs the edit nothing.
            pictures.before = r.read_color()?;
        }
        // The latency a player waits: upload + any rebuild + the frame + round trip.
        let start = Instant::now();
        r.apply_edit(input.edited, input.rects)?;
        let t = r.render_frame(cam)?;
        first_cpu.push(ms(start));
        first_gpu.extend(t.gpu_ms);
        if sample == 0 {
            pictures.after = r.read_color()?;
            settle(&mut r, cam)?;
            checks = checks_until_consistent(&mut r, cam, &target, 1)?;
        }
    }
    let all_timed = |g: &Vec<f64>, c: &Vec<f64>| if g.len() == c.len() { median(g) } else { None };
    let row = EditRow {
        method: name.to_string(),
        first_frame_cpu_ms: median(&first_cpu).unwrap_or(f64::NAN),
        first_frame_gpu_ms: all_timed(&first_gpu, &first_cpu),
        steady_cpu_ms: median(&steady_cpu).unwrap_or(f64::NAN),
        steady_gpu_ms: all_timed(&steady_gpu, &steady_cpu),
        first_frame_cpu_samples: first_cpu,
        first_frame_gpu_samples: first_gpu,
        consistent_after_frames: consistent_after(&checks),
        checks,
    };
    Ok((row, pictures))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disagreement_counts_class_flips_and_depth() {
        let inf = f32::INFINITY;
        let a = [1.0, 2.0, inf, inf, 10.0];
        let b = [1.0, 2.5, inf, 3.0, 10.0];
        let (mismatch, p95) = disagreement(&a, &b);
        assert!((mismatch - 20.0).abs() < 1e-9);
        assert_eq!(p95, 0.5);
        assert_eq!(disagreement(&[inf], &[inf]), (0.0, 0.0));
    }

    #[test]
    fn first_consistent_check_wins() {
        let c = |frames, consistent| EditCheck {
            frames,
            class_mismatch: 0.0,
            depth_p95: 0.0,
            consistent,
        };
        assert_eq!(
            consistent_after(&[c(1, false), c(2, true), c(4, true)]),
            Some(2)
        );
        assert_eq!(consistent_after(&[c(1, false), c(16, false)]), None);
    }
}
