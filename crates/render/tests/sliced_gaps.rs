//! Issue 36 item 4: grazing rays cross the slices several texels apart.
//! Plain `sliced` walks their gaps once per pixel after the slices, over the
//! rows where they lie (`methods::sliced::gaps`); `sliced:512/fragwalk`
//! walks each slice fragment's own gap, as before. The refined slicer's
//! marks use a shader without the walk on frames with no such rows.
//!
//! On a generated world's twelve views and grazing ones (where the walking
//! rows sit mid-image):
//! - plain: against the CPU reference, see-through and covers-sky no worse
//!   than `/fragwalk`'s (the pass walks every gap whole, long ones too);
//! - refined: the images equal `/fragwalk`'s (the walking marks shader on
//!   every frame) bit for bit, colour and depth;
//! - plain, shaded once a pixel after the slices: the images equal
//!   `/forward`'s (every kept fragment shaded in the slice pass) bit for bit.

mod common;

use strata_camera::Camera;
use strata_level::ViewSpec;
use strata_reference::metrics::Metrics;
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 320;
const H: u32 = 200;

fn views(world: &strata_level::World) -> Vec<ViewSpec> {
    let mut views = world.views.clone();
    let river = &world.views[0];
    let at = format!("{},{}", river.x, river.y);
    for (name, height, pitch) in [
        ("grazing", 2, 0.0),
        ("grazing-down", 3, -12.0),
        ("down-20", 30, -20.0),
        ("up", 20, 15.0),
    ] {
        let spec = format!("{at}:{}:{height}", river.yaw);
        views.push(ViewSpec::parse(name, &spec, pitch).unwrap());
    }
    views
}

fn settings(refine: bool, fragment_walk: bool) -> MethodSettings {
    MethodSettings {
        sliced_refine: refine,
        sliced_fragment_walk: fragment_walk,
        ..Default::default()
    }
}

/// The views' cameras at the tests' size.
fn cameras_of(world: &strata_level::World, views: &[ViewSpec]) -> Vec<Camera> {
    views
        .iter()
        .map(|v| Camera::from_view(&world.level, v, W, H).unwrap())
        .collect()
}

/// Pixels whose RGBA colours differ.
fn colours_differ(a: &[u8], b: &[u8]) -> usize {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count()
}

/// `sliced` with `settings` over `cameras`: each view's distances along the
/// pixels' rays (infinite: sky) and colours.
fn draw_views(
    gpu: &strata_render::Gpu,
    (world, colors): (&strata_level::World, &TerrainColors),
    settings: &MethodSettings,
    cameras: &[Camera],
) -> Vec<(Vec<f32>, Vec<u8>)> {
    let mut r = Renderer::new(gpu, &world.level, colors, "sliced", settings, W, H).unwrap();
    cameras
        .iter()
        .map(|c| {
            r.render_frame(c).unwrap();
            let depth = r.read_depth().unwrap();
            let distance = strata_reference::metrics::distance_from_depth(c, &depth);
            (distance, r.read_color().unwrap())
        })
        .collect()
}

#[test]
fn the_gap_pass_sees_through_no_more_than_fragment_walks() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let views = views(&world);
        let mut worst: Vec<Metrics> = Vec::new();
        for fragment_walk in [false, true] {
            let label = if fragment_walk {
                "fragwalk"
            } else {
                "gap pass"
            };
            let mut r = Renderer::new(
                &gpu,
                &world.level,
                &colors,
                "sliced",
                &settings(false, fragment_walk),
                W,
                H,
            )
            .unwrap();
            let m = common::worst_over_views(
                &mut r,
                &world.level,
                &views,
                (W, H),
                label,
                |_, _, _, _| {},
            );
            eprintln!("{label} worst ({}): {m:?}", gpu.report.backend);
            worst.push(m);
        }
        let (pass, walks) = (&worst[0], &worst[1]);
        assert!(
            pass.see_through <= walks.see_through + 0.01,
            "{pass:?} vs {walks:?}"
        );
        assert!(
            pass.covers_sky <= walks.covers_sky + 0.01,
            "{pass:?} vs {walks:?}"
        );
        assert!(pass.see_through <= 0.5, "{pass:?}");
        gpu.errors.check().unwrap();
    }
}

#[test]
fn refined_marks_without_the_walk_change_nothing_but_the_work() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let views = views(&world);
        let cameras = cameras_of(&world, &views);
        let images: Vec<_> = [false, true]
            .into_iter()
            .map(|walk| draw_views(&gpu, (&world, &colors), &settings(true, walk), &cameras))
            .collect();
        let mut failures = Vec::new();
        for (view, (steep, walks)) in views.iter().zip(images[0].iter().zip(&images[1])) {
            let depth = steep.0.iter().zip(&walks.0).filter(|(a, b)| a != b).count();
            let color = colours_differ(&steep.1, &walks.1);
            eprintln!(
                "refined {:13} pitch {:5}: {depth} depths, {color} colours differ ({})",
                view.name, view.pitch, gpu.report.backend
            );
            if depth != 0 || color != 0 {
                failures.push(format!(
                    "refined {}: {depth} depths and {color} colours differ from /fragwalk",
                    view.name
                ));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        gpu.errors.check().unwrap();
    }
}

/// Plain `sliced` shades each pixel's nearest kept slice once, after the
/// slices (`methods::sliced::shade`); `/forward` shades every kept slice
/// fragment in the slice pass. The slice point is the same, so are the
/// images: colour and depth bit for bit on every view, the grazing ones
/// (where the gap pass draws over the shading) included. Fails if the
/// deferred pass shades another point, misses the sky, or loses the gaps.
#[test]
fn deferred_shading_draws_what_forward_shading_draws() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let views = views(&world);
        let cameras = cameras_of(&world, &views);
        let images: Vec<_> = [false, true]
            .into_iter()
            .map(|forward| {
                let settings = MethodSettings {
                    sliced_forward_shading: forward,
                    ..settings(false, false)
                };
                draw_views(&gpu, (&world, &colors), &settings, &cameras)
            })
            .collect();
        let mut failures = Vec::new();
        let mut shades = std::collections::HashSet::new();
        for (view, (deferred, forward)) in views.iter().zip(images[0].iter().zip(&images[1])) {
            let depth = deferred
                .0
                .iter()
                .zip(&forward.0)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            let color = colours_differ(&deferred.1, &forward.1);
            shades.extend(deferred.1.chunks_exact(4));
            eprintln!(
                "plain {:13} pitch {:5}: {depth} depths, {color} colours differ from /forward ({})",
                view.name, view.pitch, gpu.report.backend
            );
            if depth != 0 || color != 0 {
                failures.push(format!(
                    "{}: {depth} depths and {color} colours differ",
                    view.name
                ));
            }
        }
        // Not two blank pictures alike.
        assert!(
            shades.len() >= 20,
            "{} colours in all the views",
            shades.len()
        );
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        gpu.errors.check().unwrap();
    }
}

/// The gap pass's beam pyramid follows an edit made while the frames had no
/// walking rows (its queued update runs with the next frame that walks): a
/// wall raised ahead of a grazing view, the view drawn after a steep frame,
/// equals a fresh renderer's. Fails when the steep frame drops the queued
/// update (the beam then starts past the new wall).
#[test]
fn an_edit_made_on_a_steep_frame_reaches_the_gap_pass() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let mut level = world.level.clone();
        let river = &world.views[0];
        let grazing = ViewSpec::parse(
            "grazing",
            &format!("{},{}:{}:3", river.x, river.y, river.yaw),
            0.0,
        )
        .unwrap();
        let steep = ViewSpec {
            pitch: -80.0,
            ..grazing.clone()
        };
        let grazing = Camera::from_view(&level, &grazing, W, H).unwrap();
        let steep = Camera::from_view(&level, &steep, W, H).unwrap();
        let settings = settings(false, false);
        let mut r = Renderer::new(&gpu, &level, &colors, "sliced", &settings, W, H).unwrap();
        r.render_frame(&grazing).unwrap();
        // A wall 40 units ahead, across the view.
        let yaw = grazing.yaw_deg.to_radians();
        let ahead = grazing.position.truncate() + 40.0 * glam::Vec2::new(yaw.sin(), yaw.cos());
        let rect = strata_level::edit::EditRect {
            x: ahead.x as i64 - 12,
            y: ahead.y as i64 - 12,
            width: 24,
            height: 24,
        };
        let rects = strata_level::edit::fill_single(&mut level, rect, 250, 3);
        r.apply_edit(&level, &rects).unwrap();
        r.render_frame(&steep).unwrap();
        r.render_frame(&grazing).unwrap();
        let (depth, color) = (r.read_depth().unwrap(), r.read_color().unwrap());
        let mut fresh = Renderer::new(&gpu, &level, &colors, "sliced", &settings, W, H).unwrap();
        fresh.render_frame(&grazing).unwrap();
        let (want_depth, want_color) = (fresh.read_depth().unwrap(), fresh.read_color().unwrap());
        let depths = depth
            .iter()
            .zip(&want_depth)
            .filter(|(a, b)| a != b)
            .count();
        let colors_differ = colours_differ(&color, &want_color);
        eprintln!(
            "wall after a steep frame ({}): {depths} depths, {colors_differ} colours differ from a fresh renderer",
            gpu.report.backend
        );
        assert_eq!((depths, colors_differ), (0, 0));
        gpu.errors.check().unwrap();
    }
}

/// The per-pixel walks (plain `sliced`'s gap pass, the refined slicer's
/// refine pass) begin at their tile's beam start, which must change nothing
/// but the work: against the walks from the near plane (`/nobeam`), on the
/// views above, the same pixels hit, at most 0.01 % of them (6 pixels) at
/// distances more than 1e-4 relative apart, and at most 0.01 % of colours
/// differ. Measured on lavapipe and llvmpipe: at most one pixel a view over
/// 1e-4 (up to 3.2e-2, a silhouette pixel whose walk from another start
/// rounds into the neighbouring texel), at most one colour; the rest within
/// 8e-5.
#[test]
fn the_beam_start_changes_nothing_but_the_work() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let views = views(&world);
        let cameras = cameras_of(&world, &views);
        let mut failures = Vec::new();
        for refine in [false, true] {
            let images: Vec<_> = [true, false]
                .into_iter()
                .map(|beam| {
                    let settings = MethodSettings {
                        march_beam: beam,
                        ..settings(refine, false)
                    };
                    draw_views(&gpu, (&world, &colors), &settings, &cameras)
                })
                .collect();
            let label = if refine { "refined" } else { "plain" };
            for (view, (on, off)) in views.iter().zip(images[0].iter().zip(&images[1])) {
                let class =
                    on.0.iter()
                        .zip(&off.0)
                        .filter(|(a, b)| a.is_finite() != b.is_finite())
                        .count();
                let rels: Vec<f64> =
                    on.0.iter()
                        .zip(&off.0)
                        .filter(|(a, b)| a.is_finite() && b.is_finite())
                        .map(|(a, b)| f64::from((a - b).abs() / b.abs().max(1.0)))
                        .collect();
                let rel = rels.iter().copied().fold(0.0, f64::max);
                let far = rels.iter().filter(|&&r| r > 1e-4).count();
                let far_pct = 100.0 * far as f64 / f64::from(W * H);
                let color = colours_differ(&on.1, &off.1);
                let color_pct = 100.0 * color as f64 / f64::from(W * H);
                eprintln!(
                    "{label:7} {:13} pitch {:5}: {class} hit/miss differ, distance {rel:.2e} relative at most, {far} over 1e-4, {color_pct:.4} % colours ({})",
                    view.name, view.pitch, gpu.report.backend
                );
                if class != 0 || far_pct > 0.01 || color_pct > 0.01 {
                    failures.push(format!(
                        "{label} {}: {class} hit/miss, {far} distances over 1e-4 relative, colours {color_pct:.4} % differ with the beam",
                        view.name
                    ));
                }
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        gpu.errors.check().unwrap();
    }
}
