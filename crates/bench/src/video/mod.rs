//! `strata video`: a camera path rendered by one or more methods side by
//! side, each frame's tiles labelled with the method and its frame time,
//! with the temporal metric measured on the way (the same loop serves
//! `compare --temporal`, which writes no frames).

pub mod encode;
pub mod path;
pub mod temporal;
pub mod tiles;

use crate::methods::{describe, settings_for};
use crate::plan::MethodChoice;
use crate::session::color_image;
use crate::stats::mean;
use crate::warm::{build_frames, ms, warm_up};
use anyhow::Context;
use encode::FrameSink;
use indicatif::ProgressBar;
use path::CameraPath;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use strata_camera::Camera;
use strata_level::source::ColumnSource;
use strata_level::{DirtyRect, EditSite, Level, World};
use strata_reference::{ReferenceSettings, Tracer};
use strata_render::{Gpu, Renderer, TerrainColors};
use temporal::{Flicker, FlickerTracker, flicker_percent};

/// Seconds the "crater dug" note stays on screen after the dig.
const DIG_NOTE_SECONDS: f32 = 1.5;

#[derive(Clone, Debug)]
pub struct VideoOptions {
    pub methods: Vec<MethodChoice>,
    /// Each method renders at this size.
    pub tile: (u32, u32),
    /// The composed frame's size; `None` renders without composing (the
    /// temporal metric alone).
    pub frame: Option<(u32, u32)>,
    pub fps: u32,
    pub shadows: bool,
    /// Trace the CPU reference every frame and measure flicker.
    pub temporal: bool,
    /// Trace the reference while the methods render (`None`: when the
    /// adapter is not a CPU rasteriser, whose frame times it would inflate).
    pub overlap: Option<bool>,
    /// `--gpu-budget`: the paged methods (`strata_render::paged::PAGED_METHODS`)
    /// draw through pages streamed as the camera flies (converged at the
    /// first pose); the others keep the whole-world path.
    pub paging: Option<strata_render::paged::PagedOptions>,
}

/// A world drawn only through pages (a store past the whole-world limit):
/// its map is never in memory whole. Every lane draws `pages`; eye heights
/// and the CPU reference read `columns` (the ground as the pages show it,
/// the dig included); the dig goes into the pages' edit layer, never into
/// the store on disk.
pub struct PagedTerrain {
    pub pages: std::sync::Arc<dyn strata_render::paged::PageSource>,
    pub columns: std::sync::Arc<dyn ColumnSource + Send + Sync>,
    /// Cut the crater into the pages; the chunks it touched (grid row-major).
    pub dig: Box<Dig>,
}

/// Cuts a crater into pages; answers the chunks it touched.
pub type Dig = dyn Fn(&EditSite) -> anyhow::Result<Vec<u32>> + Send + Sync;

/// Where a recording's terrain is: a level in memory, or pages.
enum Ground<'a> {
    Whole(&'a Level),
    Paged(&'a PagedTerrain),
}

impl Ground<'_> {
    fn columns(&self) -> &dyn ColumnSource {
        match self {
            Ground::Whole(level) => *level,
            Ground::Paged(t) => &*t.columns,
        }
    }
}

/// What the dig frame applies before it draws.
enum Edit<'a> {
    /// The edited level and its dirty rectangles (a world in memory).
    Level(&'a (Level, Vec<DirtyRect>)),
    /// The chunks a dig into the pages touched.
    Chunks(&'a [u32]),
}

/// Pages of a world in memory whose level an edit replaces (the dig frame
/// swaps in the edited level, then refreshes the touched pages).
struct SwappedPages {
    level: std::sync::RwLock<std::sync::Arc<Level>>,
}

impl SwappedPages {
    fn pages(&self) -> Result<strata_render::paged::LevelPages, String> {
        let level = self.level.read().expect("pages lock").clone();
        strata_render::paged::LevelPages::new(level).map_err(|e| format!("{e:#}"))
    }
}

impl strata_render::paged::PageSource for SwappedPages {
    fn size(&self) -> (u32, u32) {
        let level = self.level.read().expect("pages lock");
        (level.width(), level.height())
    }

    fn mid_rule(&self) -> strata_level::MidRule {
        self.level.read().expect("pages lock").mid_rule
    }

    fn chunk_tops(&self) -> Result<Vec<u8>, String> {
        self.pages()?.chunk_tops()
    }

    fn read_page(
        &self,
        cx: u32,
        cy: u32,
        step: u32,
    ) -> Result<strata_render::paged::PageData, String> {
        self.pages()?.read_page(cx, cy, step)
    }
}

/// The chunks (grid row-major) that `rects` touch on a map `width` wide.
fn touched_chunks(rects: &[DirtyRect], width: u32) -> Vec<u32> {
    let page = strata_render::paged::PAGE;
    let mut chunks: Vec<u32> = rects
        .iter()
        .filter(|r| r.width > 0 && r.height > 0)
        .flat_map(|r| {
            (r.y / page..=(r.y + r.height - 1) / page).flat_map(move |cy| {
                (r.x / page..=(r.x + r.width - 1) / page).map(move |cx| cy * (width / page) + cx)
            })
        })
        .collect();
    chunks.sort_unstable();
    chunks.dedup();
    chunks
}

/// The video's JSON sidecar (`<out>.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Recording {
    pub level: String,
    pub adapter: String,
    pub backend: String,
    pub timestamps: bool,
    pub frame_width: u32,
    pub frame_height: u32,
    pub tile_width: u32,
    pub tile_height: u32,
    pub fps: u32,
    pub frames: u32,
    /// The path as played, in the path-file format.
    pub path: String,
    /// The first frame drawn after the crater was dug.
    pub dig_frame: Option<u32>,
    pub methods: Vec<MethodTrack>,
    /// Wall-clock seconds of the frame loop (render, read back, reference,
    /// compose, encode), and frames per second of output it achieved.
    pub wall_seconds: f64,
    pub output_fps: f64,
    /// Mean ms to trace one reference frame (with `temporal`).
    pub reference_ms_mean: Option<f64>,
    /// Where the frames went.
    pub output: String,
}

/// One method along the path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodTrack {
    pub method: String,
    pub settings: String,
    pub setup_ms: f64,
    /// Frame time (GPU when timed, else CPU submit-and-wait), ms.
    pub frame_ms_mean: f64,
    pub frame_ms_max: f64,
    pub gpu_timed: bool,
    /// Applying the edit plus the first frame after it (wall clock), ms.
    pub first_post_edit_ms: Option<f64>,
    /// Flicker beyond the reference's; `None` without `temporal`.
    pub flicker: Option<Flicker>,
    /// Why the method is missing from the video, when it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// A method's renderer and what it measured so far.
struct Lane {
    choice: MethodChoice,
    renderer: Renderer,
    frame_ms: Vec<f64>,
    gpu_timed: bool,
    first_post_edit_ms: Option<f64>,
    flicker: FlickerTracker,
    previous: Option<Vec<f32>>,
    setup_ms: f64,
    settings: String,
    /// The pages a paged lane draws (an edit swaps their level).
    pages: Option<std::sync::Arc<SwappedPages>>,
}

/// Render `path` with every method, feeding composed frames to `sink` when
/// given. A method that cannot be built is left out (its track says why).
pub fn record(
    gpu: &Gpu,
    world: &World,
    path: &CameraPath,
    opts: &VideoOptions,
    sink: Option<&mut dyn FrameSink>,
    bar: &ProgressBar,
) -> anyhow::Result<Recording> {
    record_over(
        gpu,
        world,
        Ground::Whole(&world.level),
        path,
        opts,
        sink,
        bar,
    )
}

/// [`record`] over a world drawn only through pages: `world` holds
/// everything but its map (a store's shell), `terrain` the map. Every
/// method must be paged (`strata_render::paged::PAGED_METHODS`); another
/// is left out, its track saying why.
pub fn record_paged(
    gpu: &Gpu,
    world: &World,
    terrain: &PagedTerrain,
    path: &CameraPath,
    opts: &VideoOptions,
    sink: Option<&mut dyn FrameSink>,
    bar: &ProgressBar,
) -> anyhow::Result<Recording> {
    record_over(gpu, world, Ground::Paged(terrain), path, opts, sink, bar)
}

fn record_over(
    gpu: &Gpu,
    world: &World,
    ground: Ground<'_>,
    path: &CameraPath,
    opts: &VideoOptions,
    mut sink: Option<&mut dyn FrameSink>,
    bar: &ProgressBar,
) -> anyhow::Result<Recording> {
    let columns = ground.columns();
    let flight = path.resolve(columns).context("the camera path")?;
    let frames = frame_count(flight.duration(), opts.fps);
    let (tw, th) = opts.tile;
    let colors = TerrainColors::from_world(world);
    let first = flight.camera(columns, flight.start(), tw, th)?;

    bar.set_length(u64::from(frames));
    let (mut lanes, tracks_failed) = build_lanes(gpu, &ground, &colors, opts, &first, bar);
    if lanes.is_empty() {
        anyhow::bail!("no method could be built (see the messages above)");
    }
    let site = dig_site(world, path, bar);
    let edited = match &ground {
        Ground::Whole(level) => site.map(|site| {
            let mut level = (*level).clone();
            let rects = strata_level::edit::crater(&mut level, site);
            (level, rects)
        }),
        Ground::Paged(_) => None,
    };
    let before = match opts.temporal {
        true => Some(Tracer::over(columns).context("the CPU reference over the world")?),
        false => None,
    };
    let mut after = match (&edited, opts.temporal) {
        (Some((l, _)), true) => Some(Tracer::new(l)),
        _ => None,
    };
    let overlap = opts.overlap.unwrap_or(gpu.report.device_type != "Cpu");
    let mut dig_frame = None;
    let mut reference_ms = Vec::new();
    let mut previous_reference: Option<Vec<f32>> = None;
    let start = Instant::now();
    for f in 0..frames {
        let t = flight.start() + f as f32 / opts.fps as f32;
        let dig_now = dig_frame.is_none() && site.is_some() && path.dig_at.is_some_and(|d| t >= d);
        // A dig into pages is cut now (and timed with the frame after it).
        let (mut dug, mut dig_ms) = (Vec::new(), 0.0);
        if let (true, Ground::Paged(terrain), Some(site)) = (dig_now, &ground, site) {
            let start = Instant::now();
            dug = (terrain.dig)(site).context("digging the crater into the pages")?;
            dig_ms = ms(start);
            if opts.temporal {
                after =
                    Some(Tracer::over(columns).context("the CPU reference over the dug world")?);
            }
        }
        let current: &dyn ColumnSource = match (&edited, dig_frame.is_some() || dig_now) {
            (Some((l, _)), true) => l,
            _ => columns,
        };
        let camera = flight.camera(current, t, tw, th)?;
        bar.set_message(format!(
            "path {t:.1} s{}",
            if dig_now { ", digging" } else { "" }
        ));
        let edit = match (&edited, dig_now) {
            (_, false) => None,
            (Some(e), true) => Some(Edit::Level(e)),
            (None, true) => Some(Edit::Chunks(&dug)),
        };
        let tracer = if dig_frame.is_some() || dig_now {
            after.as_ref()
        } else {
            before.as_ref()
        };
        let trace = || {
            tracer.map(|tr| {
                let start = Instant::now();
                let r = tr.render(&camera, &ReferenceSettings::default());
                (r.distance, ms(start))
            })
        };
        // A GPU leaves the CPU free: trace the reference while the methods
        // render. A CPU rasteriser would share its cores with the trace and
        // time its frames slower, so there the two take turns.
        let (reference, rendered) = if overlap {
            rayon::join(trace, || render_lanes(&mut lanes, &camera, edit.as_ref()))
        } else {
            let rendered = render_lanes(&mut lanes, &camera, edit.as_ref());
            (trace(), rendered)
        };
        rendered?;
        if dig_now {
            dig_frame = Some(f);
            for lane in &mut lanes {
                if let Some(e) = &mut lane.first_post_edit_ms {
                    *e += dig_ms;
                }
            }
        }
        let reference = reference.map(|(distance, ms)| {
            reference_ms.push(ms);
            distance
        });
        for lane in &mut lanes {
            if let Some(reference) = &reference {
                let depth = lane.renderer.read_depth()?;
                let distance = strata_reference::distance_from_depth(&camera, &depth);
                if let (Some(prev), Some(prev_ref)) = (&lane.previous, &previous_reference) {
                    let p = flicker_percent((prev, &distance), (prev_ref, reference));
                    lane.flicker.add(f, p);
                }
                lane.previous = Some(distance);
            }
        }
        previous_reference = reference;
        if let (Some(sink), Some((w, h))) = (sink.as_deref_mut(), opts.frame) {
            let note = dig_frame
                .filter(|&d| (f - d) as f32 <= DIG_NOTE_SECONDS * opts.fps as f32)
                .map(|_| "crater dug");
            let frame = compose(&lanes, &camera, (w, h), note)?;
            sink.write(&frame)?;
        }
        bar.inc(1);
    }
    let wall = start.elapsed().as_secs_f64();
    let mut methods: Vec<MethodTrack> = lanes
        .into_iter()
        .map(|lane| track(lane, opts.temporal))
        .collect();
    methods.extend(tracks_failed);
    let (fw, fh) = opts.frame.unwrap_or((tw, th));
    Ok(Recording {
        level: world.name.clone(),
        adapter: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        timestamps: gpu.report.timestamps,
        frame_width: fw,
        frame_height: fh,
        tile_width: tw,
        tile_height: th,
        fps: opts.fps,
        frames,
        path: path.to_text(),
        dig_frame,
        methods,
        wall_seconds: wall,
        output_fps: f64::from(frames) / wall.max(1e-9),
        reference_ms_mean: mean(&reference_ms),
        output: String::new(),
    })
}

/// Draw one frame with every method, applying `edit` first when given (the
/// dig frame: the edit and that frame are timed together).
fn render_lanes(
    lanes: &mut [Lane],
    camera: &Camera,
    edit: Option<&Edit<'_>>,
) -> anyhow::Result<()> {
    for lane in lanes {
        let start = Instant::now();
        match edit {
            Some(Edit::Level((level, rects))) => match &lane.pages {
                Some(pages) => {
                    *pages.level.write().expect("pages lock") = std::sync::Arc::new(level.clone());
                    lane.renderer
                        .refresh_pages(&touched_chunks(rects, level.width()))?;
                }
                None => lane.renderer.apply_edit(level, rects)?,
            },
            Some(Edit::Chunks(chunks)) => lane.renderer.refresh_pages(chunks)?,
            None => {}
        }
        let timing = lane.renderer.render_frame(camera)?;
        if edit.is_some() {
            lane.first_post_edit_ms = Some(ms(start));
        }
        lane.gpu_timed = timing.gpu_ms.is_some();
        lane.frame_ms.push(timing.gpu_ms.unwrap_or(timing.cpu_ms));
    }
    Ok(())
}

/// Every method's lane; the tracks of those that could not be built.
fn build_lanes(
    gpu: &Gpu,
    ground: &Ground<'_>,
    colors: &TerrainColors,
    opts: &VideoOptions,
    first: &Camera,
    bar: &ProgressBar,
) -> (Vec<Lane>, Vec<MethodTrack>) {
    let (mut lanes, mut failed) = (Vec::new(), Vec::new());
    for choice in &opts.methods {
        bar.set_message(format!("{}: setup", choice.label()));
        match build_lane(gpu, ground, colors, choice, opts, first) {
            Ok(lane) => lanes.push(lane),
            Err(e) => {
                bar.println(format!("{}: left out: {e:#}", choice.label()));
                failed.push(failed_track(choice, &e));
            }
        }
    }
    (lanes, failed)
}

/// Where the path digs its crater; `None` when it does not dig (or the
/// level has no edit site: a note says so).
fn dig_site<'w>(world: &'w World, path: &CameraPath, bar: &ProgressBar) -> Option<&'w EditSite> {
    path.dig_at?;
    if world.edit.is_none() {
        bar.println(format!(
            "note: the path digs, but level `{}` has no edit site: no dig",
            world.name
        ));
    }
    world.edit.as_ref()
}

/// Frames in `seconds` at `fps`, the last keyframe included.
pub fn frame_count(seconds: f32, fps: u32) -> u32 {
    (seconds * fps as f32).floor() as u32 + 1
}

fn build_lane(
    gpu: &Gpu,
    ground: &Ground<'_>,
    colors: &TerrainColors,
    choice: &MethodChoice,
    opts: &VideoOptions,
    first: &Camera,
) -> anyhow::Result<Lane> {
    let settings = settings_for(choice, opts.shadows)?;
    let start = Instant::now();
    let pageable = strata_render::paged::PAGED_METHODS.contains(&choice.method.name);
    // The pages a paged lane draws, the level an edit swaps in them (a
    // world in memory), and how to page them.
    type Paging = (
        std::sync::Arc<dyn strata_render::paged::PageSource>,
        Option<std::sync::Arc<SwappedPages>>,
        strata_render::paged::PagedOptions,
    );
    let paging: Option<Paging> = match ground {
        Ground::Paged(terrain) if pageable => Some((
            terrain.pages.clone(),
            None,
            opts.paging.clone().unwrap_or_default(),
        )),
        Ground::Paged(_) => anyhow::bail!(
            "`{}` draws whole worlds only; {} draw this one through pages",
            choice.method.name,
            strata_render::paged::PAGED_METHODS.join(", ")
        ),
        Ground::Whole(level) => opts.paging.clone().filter(|_| pageable).map(|options| {
            let pages = std::sync::Arc::new(SwappedPages {
                level: std::sync::RwLock::new(std::sync::Arc::new((*level).clone())),
            });
            (pages.clone() as _, Some(pages), options)
        }),
    };
    let (mut renderer, pages) = match (paging, ground) {
        (Some((source, pages, options)), _) => {
            let mut renderer = Renderer::new_paged(
                gpu,
                source,
                colors,
                choice.method,
                &settings,
                opts.tile.0,
                opts.tile.1,
                options,
            )?;
            // The first pose with every page it reads (a loading screen).
            renderer.converge(first, 600)?;
            (renderer, pages)
        }
        (None, Ground::Whole(level)) => (
            Renderer::new(
                gpu,
                level,
                colors,
                choice.method,
                &settings,
                opts.tile.0,
                opts.tile.1,
            )?,
            None,
        ),
        (None, Ground::Paged(_)) => anyhow::bail!("a paged world draws through pages only"),
    };
    let setup_ms = ms(start);
    // Settle incremental builds before the first frame (as compare's first
    // view does), so the video shows the edit's catch-up, not the initial build.
    let cap = match ground {
        Ground::Whole(level) => build_frames(level),
        // Paged lanes build nothing incrementally over the whole map.
        Ground::Paged(_) => 0,
    };
    warm_up(&mut renderer, first, 1, cap + 1, gpu.report.timestamps)?;
    Ok(Lane {
        choice: choice.clone(),
        renderer,
        frame_ms: Vec::new(),
        gpu_timed: false,
        first_post_edit_ms: None,
        flicker: FlickerTracker::default(),
        previous: None,
        setup_ms,
        settings: describe(choice.method, &settings),
        pages,
    })
}

fn compose(
    lanes: &[Lane],
    camera: &Camera,
    (w, h): (u32, u32),
    note: Option<&str>,
) -> anyhow::Result<image::RgbaImage> {
    let images = lanes
        .iter()
        .map(|lane| color_image(camera.width, camera.height, lane.renderer.read_color()?))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let tiles: Vec<tiles::Tile<'_>> = lanes
        .iter()
        .zip(&images)
        .map(|(lane, image)| tiles::Tile {
            image,
            label: format!(
                "{} {:.1} ms",
                lane.choice.label(),
                lane.frame_ms.last().copied().unwrap_or(f64::NAN)
            ),
        })
        .collect();
    Ok(tiles::compose(w, h, &tiles, note))
}

fn track(lane: Lane, temporal: bool) -> MethodTrack {
    MethodTrack {
        method: lane.choice.label(),
        settings: lane.settings,
        setup_ms: lane.setup_ms,
        frame_ms_mean: mean(&lane.frame_ms).unwrap_or(f64::NAN),
        frame_ms_max: lane.frame_ms.iter().copied().fold(f64::NAN, f64::max),
        gpu_timed: lane.gpu_timed,
        first_post_edit_ms: lane.first_post_edit_ms,
        flicker: temporal.then(|| lane.flicker.result()),
        error: None,
    }
}

fn failed_track(choice: &MethodChoice, e: &anyhow::Error) -> MethodTrack {
    MethodTrack {
        method: choice.label(),
        settings: String::new(),
        setup_ms: 0.0,
        frame_ms_mean: 0.0,
        frame_ms_max: 0.0,
        gpu_timed: false,
        first_post_edit_ms: None,
        flicker: None,
        error: Some(format!("{e:#}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edit_touches_the_chunks_its_rectangles_cover() {
        let rect = |x, y, width, height| DirtyRect {
            x,
            y,
            width,
            height,
        };
        // A 1024-wide map: 4 chunks across.
        assert_eq!(touched_chunks(&[rect(10, 10, 20, 20)], 1024), [0]);
        assert_eq!(
            touched_chunks(&[rect(250, 250, 10, 10)], 1024),
            [0, 1, 4, 5]
        );
        // Two rectangles of one wrapped crater, and an empty one.
        assert_eq!(
            touched_chunks(
                &[rect(1020, 0, 4, 8), rect(0, 0, 6, 8), rect(5, 5, 0, 3)],
                1024
            ),
            [0, 3]
        );
        assert_eq!(touched_chunks(&[rect(0, 256, 256, 1)], 1024), [4]);
    }
}
