//! Every method, rerun with the same inputs on the same adapter, gives
//! bit-identical colour and depth (issue 20): measured numbers compared
//! across runs and machines rest on it. Small size, one test for all
//! methods, so it stays a few seconds on lavapipe.

mod common;

use strata_camera::Camera;
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 64;
const H: u32 = 40;
/// Frames before the read-back: enough for every incremental build of the
/// 256x256 level (one frame's budget covers it) and a settled history.
const FRAMES: usize = 3;

struct Frame {
    color: Vec<u8>,
    /// Depth as bits: -0.0 vs 0.0 or two NaNs must not pass as equal.
    depth: Vec<u32>,
}

fn frame(r: &mut Renderer, camera: &Camera) -> Frame {
    r.render_frame(camera).unwrap();
    Frame {
        color: r.read_color().unwrap(),
        depth: r
            .read_depth()
            .unwrap()
            .iter()
            .map(|d| d.to_bits())
            .collect(),
    }
}

/// Pixels whose colour or depth differ.
fn differing(a: &Frame, b: &Frame) -> (usize, usize) {
    let color = a
        .color
        .chunks_exact(4)
        .zip(b.color.chunks_exact(4))
        .filter(|(x, y)| x != y)
        .count();
    let depth = a.depth.iter().zip(&b.depth).filter(|(x, y)| x != y).count();
    (color, depth)
}

#[test]
fn every_method_is_bit_identical_when_rerun() {
    let Some(gpu) = common::gpu() else {
        return;
    };
    let level = common::synthetic_level();
    let view = &common::synthetic_views()[4];
    let camera = Camera::from_view(&level, view, W, H).unwrap();
    let colors = TerrainColors::test_ramps();
    let mut problems = Vec::new();
    for method in strata_render::methods::names() {
        if strata_render::methods::check_support(method, &gpu.caps).is_err() {
            eprintln!("{method}: not supported here, skipped");
            continue;
        }
        let build = || {
            Renderer::new(
                &gpu,
                &level,
                &colors,
                method,
                &MethodSettings::default(),
                W,
                H,
            )
            .unwrap()
        };
        let run = |r: &mut Renderer| {
            let frames: Vec<Frame> = (0..FRAMES).map(|_| frame(r, &camera)).collect();
            frames
        };
        let mut first = build();
        let a = run(&mut first);
        let mut second = build();
        let b = run(&mut second);
        let last = FRAMES - 1;
        // A picture, not a blank: terrain at many distances. (Colours are
        // few at this size with the test ramps: terraces are flat.)
        let mut depths = a[last].depth.clone();
        depths.sort_unstable();
        depths.dedup();
        let mut colors: Vec<&[u8]> = a[last].color.chunks_exact(4).collect();
        colors.sort_unstable();
        colors.dedup();
        eprintln!(
            "{method}: {} distinct depths, {} colours; compared {FRAMES} frames x 2 renderers + 1",
            depths.len(),
            colors.len()
        );
        if depths.len() < 50 {
            problems.push(format!("{method}: only {} distinct depths", depths.len()));
        }
        // A fresh renderer gives the same frames, frame for frame.
        for (i, (fa, fb)) in a.iter().zip(&b).enumerate() {
            let (c, d) = differing(fa, fb);
            if c + d > 0 {
                problems.push(format!(
                    "{method}: frame {i} of a fresh renderer differs in {c} colour and {d} depth pixels"
                ));
            }
        }
        // The same renderer, the same camera again: the same picture.
        let again = frame(&mut first, &camera);
        let (c, d) = differing(&a[last], &again);
        if c + d > 0 {
            problems.push(format!(
                "{method}: rendering the same view again differs in {c} colour and {d} depth pixels"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
