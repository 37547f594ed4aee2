//! Issue 36 item 4: `sliced` draws the rows where no ray can walk a slice
//! gap with a shader without the walk (`methods::sliced::rows`), which must
//! change nothing but the work: on a generated world's twelve views and
//! grazing ones (where the band of walking rows sits mid-image), the
//! images of plain and refined `sliced:512` equal those with every row on
//! the walking shader (`/allrows`) bit for bit, colour and depth. A band
//! too narrow fails it (tried: `GAP_MIN` 2.5 in `rows.rs` alone: the
//! grazing-down and up views differ on lavapipe).

mod common;

use strata_camera::Camera;
use strata_level::ViewSpec;
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 320;
const H: u32 = 200;

#[test]
fn steep_rows_change_nothing_but_the_work() {
    for gpu in common::gpus() {
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let mut views = world.views.clone();
        let river = &world.views[0];
        let at = format!("{},{}", river.x, river.y);
        for (name, height, pitch) in [
            ("grazing", 2, 0.0),
            ("grazing-down", 3, -12.0),
            ("up", 20, 15.0),
        ] {
            let spec = format!("{at}:{}:{height}", river.yaw);
            views.push(ViewSpec::parse(name, &spec, pitch).unwrap());
        }
        let cameras: Vec<Camera> = views
            .iter()
            .map(|v| Camera::from_view(&world.level, v, W, H).unwrap())
            .collect();
        let mut failures = Vec::new();
        for refine in [false, true] {
            let mut images = Vec::new();
            for all_rows in [false, true] {
                let settings = MethodSettings {
                    sliced_refine: refine,
                    sliced_all_rows: all_rows,
                    ..Default::default()
                };
                let mut r =
                    Renderer::new(&gpu, &world.level, &colors, "sliced", &settings, W, H).unwrap();
                let per_view: Vec<_> = cameras
                    .iter()
                    .map(|c| {
                        r.render_frame(c).unwrap();
                        (r.read_depth().unwrap(), r.read_color().unwrap())
                    })
                    .collect();
                images.push(per_view);
            }
            let label = if refine { "refined" } else { "plain" };
            for (view, (split, whole)) in views.iter().zip(images[0].iter().zip(&images[1])) {
                let depth = split.0.iter().zip(&whole.0).filter(|(a, b)| a != b).count();
                let color = split
                    .1
                    .chunks_exact(4)
                    .zip(whole.1.chunks_exact(4))
                    .filter(|(a, b)| a != b)
                    .count();
                eprintln!(
                    "{label:7} {:13} pitch {:5}: {depth} depths, {color} colours differ ({})",
                    view.name, view.pitch, gpu.report.backend
                );
                if depth != 0 || color != 0 {
                    failures.push(format!(
                        "{label} {}: {depth} depths and {color} colours differ from /allrows",
                        view.name
                    ));
                }
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        gpu.errors.check().unwrap();
    }
}
