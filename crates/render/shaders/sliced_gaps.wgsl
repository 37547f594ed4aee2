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
#include "sliced_gap_walk.wgsl"

// count.y: slices N.
@group(1) @binding(0) var<uniform> footprint: Footprint;

struct GapOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The first solid point of the pixel's ray from `t_start` on, where its ray
// crosses the slices more than GAP_MIN texels apart; else nothing (discard).
fn walk_pixel(pos: vec4<f32>, t_start: f32) -> GapOut {
    let g = gap_walk(pos.xy, t_start, footprint.count.y);
    if (!g.hit) {
        discard;
    }
    var out: GapOut;
    out.depth = g.depth;
    out.color = vec4<f32>(shade_column(g.q, g.column.x, g.column.y, g.q - globals.eye.xyz), 1.0);
    return out;
}

// From the near plane (adapters without compute or fragment storage).
@fragment
fn fs_sliced_gaps(@builtin(position) pos: vec4<f32>) -> GapOut {
    return walk_pixel(pos, 0.0);
}
