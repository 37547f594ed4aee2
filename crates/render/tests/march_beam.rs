//! Issue 36 item 2: `ray` and `voxel` begin each ray's march at its tile's
//! beam (and `ray` ends a rising ray above the map's highest top), which
//! must change nothing but the work: on the default world's twelve views, a
//! grazing view an eye's height over the ground, a view looking up and one
//! from inside a cave, the images with the beam (`ray:128`,
//! `voxel:4,8,2/100`) equal those without (`/nobeam`) bit for bit, colour
//! and depth. (At 320x200 no `voxel` ray spends its whole step budget; at
//! 1280x800 some do before the beam, and with it reach the ground: see
//! `bench/issue36-frag/README.md`.)

mod common;

use strata_camera::Camera;
use strata_level::{Level, ViewSpec};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 320;
const H: u32 = 200;

/// The first texel, on a coarse grid, under a slab with at least `gap`
/// altitude units of cave between its floor and its ceiling.
fn cave_texel(level: &Level, gap: u8) -> Option<(i64, i64)> {
    (0..level.height() as i64)
        .step_by(7)
        .flat_map(|y| (0..level.width() as i64).step_by(7).map(move |x| (x, y)))
        .find(|&(x, y)| {
            let c = level.column(x, y);
            c.dual && c.mid >= c.low.saturating_add(gap)
        })
}

/// The protocol's views and the hard cases for a late start or an early end.
fn views(world: &strata_level::World) -> Vec<ViewSpec> {
    let mut views = world.views.clone();
    let river = &world.views[0];
    let at = format!("{},{}", river.x, river.y);
    views.push(ViewSpec::parse("grazing", &format!("{at}:{}:2", river.yaw), 0.0).unwrap());
    views.push(ViewSpec::parse("grazing-down", &format!("{at}:{}:3", river.yaw), -5.0).unwrap());
    views.push(ViewSpec::parse("looking-up", &format!("{at}:{}:20", river.yaw), 20.0).unwrap());
    let (x, y) = cave_texel(&world.level, 24).expect("the default world has caves");
    for (name, yaw, pitch) in [("cave", 0.0, 0.0), ("cave-turned", 135.0, -10.0)] {
        views.push(ViewSpec::parse(name, &format!("{x},{y}:{yaw}:6:under"), pitch).unwrap());
    }
    views
}

#[test]
fn the_beam_changes_nothing_but_the_work() {
    for gpu in common::gpus() {
        let world = strata_level::generate::generate(&Default::default()).unwrap();
        let colors = TerrainColors::from_world(&world);
        let views = views(&world);
        let cameras: Vec<Camera> = views
            .iter()
            .map(|v| Camera::from_view(&world.level, v, W, H).unwrap())
            .collect();
        let mut failures = Vec::new();
        for method in ["ray", "voxel"] {
            let mut images = Vec::new();
            for beam in [true, false] {
                let settings = MethodSettings {
                    shadows: false,
                    march_beam: beam,
                    ..Default::default()
                };
                let mut r =
                    Renderer::new(&gpu, &world.level, &colors, method, &settings, W, H).unwrap();
                let started = std::time::Instant::now();
                let per_view: Vec<_> = cameras
                    .iter()
                    .map(|c| {
                        r.render_frame(c).unwrap();
                        (r.read_depth().unwrap(), r.read_color().unwrap())
                    })
                    .collect();
                eprintln!(
                    "{method} beam {beam}: {} views in {:.2} s ({})",
                    views.len(),
                    started.elapsed().as_secs_f64(),
                    gpu.report.backend
                );
                images.push(per_view);
            }
            for (view, (on, off)) in views.iter().zip(images[0].iter().zip(&images[1])) {
                let depth = on.0.iter().zip(&off.0).filter(|(a, b)| a != b).count();
                let color =
                    on.1.chunks_exact(4)
                        .zip(off.1.chunks_exact(4))
                        .filter(|(a, b)| a != b)
                        .count();
                eprintln!(
                    "{method:6} {:13} pitch {:5}: {depth} depths, {color} colours differ",
                    view.name, view.pitch
                );
                if depth != 0 || color != 0 {
                    failures.push(format!(
                        "{method} {}: {depth} depths and {color} colours differ with the beam",
                        view.name
                    ));
                }
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}
