//! Warming a renderer up before it is timed: frames until its incremental
//! builds have settled, and the clock the harness reads. Shared by the
//! comparison ([`crate::run`]), the edit protocol ([`crate::edits`]), the
//! video ([`crate::video`]) and tuning.

use std::time::Instant;
use strata_camera::Camera;
use strata_level::Level;
use strata_render::Renderer;

/// Texels the incremental voxel build processes per frame
/// (`voxel_build::DEFAULT_BUDGET_TEXELS`): the first view's warm-up covers a
/// whole-level build at this budget, so no method is timed mid-build.
pub const INCREMENTAL_BUDGET_TEXELS: u64 = 1 << 20;

/// Frames an incremental build of the whole of `level` takes at
/// [`INCREMENTAL_BUDGET_TEXELS`] a frame.
pub fn build_frames(level: &Level) -> u32 {
    let texels = u64::from(level.width()) * u64::from(level.height());
    u32::try_from(texels.div_ceil(INCREMENTAL_BUDGET_TEXELS)).unwrap_or(u32::MAX)
}

/// What warming a renderer up at one view cost.
pub struct WarmUp {
    /// The first frame (lazy builds land here).
    pub first_ms: f64,
    /// Every pre-timing frame, the first included.
    pub total_ms: f64,
    pub frames: u32,
}

/// Does a frame carry derived-data work (an incremental build or update)?
/// Methods label such passes `… update` / `… build` / `… bake`.
fn building(t: &strata_render::FrameTimings) -> bool {
    t.passes.iter().any(|(label, _)| {
        ["update", "build", "bake"]
            .iter()
            .any(|w| label.contains(w))
    })
}

/// Render `min` frames (at least one), then go on while the last frame still
/// did incremental build work, up to `cap`. Without timestamps the passes are
/// not reported, so the cap (enough for a whole-level build) is always used.
pub fn warm_up(
    renderer: &mut Renderer,
    camera: &Camera,
    min: u32,
    cap: u32,
    timestamps: bool,
) -> anyhow::Result<WarmUp> {
    let start = Instant::now();
    let mut last = renderer.render_frame(camera)?;
    let first_ms = ms(start);
    let mut frames = 1;
    let min = min.max(1);
    let cap = cap.max(min);
    while frames < cap && (frames < min || !timestamps || building(&last)) {
        last = renderer.render_frame(camera)?;
        frames += 1;
    }
    Ok(WarmUp {
        first_ms,
        total_ms: ms(start),
        frames,
    })
}

/// Milliseconds since `since`.
pub fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}
