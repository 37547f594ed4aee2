// Plain `sliced`, the gap pass: after the slices (each fragment its point
// test alone, `fs_sliced_steep`), one full-screen triangle over the bands of
// rows whose rays may cross the slices more than GAP_MIN texels apart
// (`methods::sliced::rows`, the scissor). There a thin wall or a peak can
// sit between two slice crossings and the point tests see through it, so
// the pixel walks its ray column by column (the reference's segment test,
// stepping over 8x8 blocks of air) up to the first solid point, and writes
// it where it lies before the slice the depth buffer holds (depth test
// Less): the gaps before every slice point, walked once per pixel rather
// than once per slice fragment (`fs_sliced`, `sliced:N/fragwalk`).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"
#include "fullscreen.wgsl"
#include "sliced_walk.wgsl"

// count.y: slices N.
@group(1) @binding(0) var<uniform> footprint: Footprint;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;
// Twin of `sliced.wgsl`'s GAP_MIN (Rust: `sliced::rows::GAP_MIN`).
const GAP_MIN: f32 = 2.0;
// Most blocks one walk crosses (far 600 crosses at most ~1300 columns).
const GAP_BLOCKS: u32 = 512u;

struct GapOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The first solid point of the pixel's ray from `t_start` on, where its ray
// crosses the slices more than GAP_MIN texels apart; else nothing (discard).
fn walk_pixel(pos: vec4<f32>, t_start: f32) -> GapOut {
    let d = camera_ray(pos.x, pos.y);
    let e = globals.eye.xyz;
    // As `sliced.wgsl::slice_hit`: edge-on rays and steep ones keep the
    // slices' point tests.
    let gap = SLICE_TOP / f32(footprint.count.y) / abs(d.z);
    if (abs(d.z) < 1e-6 * length(d) || gap * length(d.xy) <= GAP_MIN) {
        discard;
    }
    let t_near = globals.forward.w / globals.eye.w;
    let t_far = globals.right.w / globals.eye.w;
    let t0 = max(t_start, t_near);
    if (t0 >= t_far) {
        discard;
    }
    let x = walk_gap(e, d, t0, t_far, GAP_BLOCKS, true);
    if (!x.hit) {
        discard;
    }
    let q = e + d * x.t;
    let clip = globals.view_proj * vec4<f32>(q, 1.0);
    var out: GapOut;
    out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    out.color = vec4<f32>(shade_column(q, x.column.x, x.column.y, q - e), 1.0);
    return out;
}

// From the near plane (adapters without compute or fragment storage).
@fragment
fn fs_sliced_gaps(@builtin(position) pos: vec4<f32>) -> GapOut {
    return walk_pixel(pos, 0.0);
}
