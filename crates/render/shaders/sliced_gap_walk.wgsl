// Plain `sliced`'s walk of one pixel's ray where it crosses the slices more
// than GAP_MIN texels apart (a thin wall or a peak can sit between two
// crossings): column by column to the first solid point. Shared by the gap
// pass's fragments (`sliced_gaps.wgsl`) and the deferred shading's compute
// pass (`sliced_shade_walk.wgsl`), so both find the same point and depth.
#include "frame.wgsl"
#include "sliced_walk.wgsl"

// Top of the sliced range (Rust: `forward::Z_MAX`).
const GAP_SLICE_TOP: f32 = 256.0;
// Twin of `sliced.wgsl`'s GAP_MIN (Rust: `sliced::rows::GAP_MIN`).
const GAP_MIN: f32 = 2.0;
// Most blocks one walk crosses (far 600 crosses at most ~1300 columns).
const GAP_BLOCKS: u32 = 512u;

struct GapHit {
    // whether the ray walks and found a solid point
    hit: bool,
    // the point, its column, and its depth-buffer value
    q: vec3<f32>,
    column: vec2<i32>,
    depth: f32,
}

// The first solid point of the ray through pixel centre `pos` from
// `t_start` on, at `slices` slices; no hit where the ray crosses them at most
// GAP_MIN texels apart (the slices' point tests cover it) or is edge-on.
fn gap_walk(pos: vec2<f32>, t_start: f32, slices: u32) -> GapHit {
    var g: GapHit;
    g.hit = false;
    let d = camera_ray(pos.x, pos.y);
    let e = globals.eye.xyz;
    // As `sliced.wgsl::slice_hit`: edge-on rays and steep ones keep the
    // slices' point tests.
    let gap = GAP_SLICE_TOP / f32(slices) / abs(d.z);
    if (abs(d.z) < 1e-6 * length(d) || gap * length(d.xy) <= GAP_MIN) {
        return g;
    }
    let t_near = globals.forward.w / globals.eye.w;
    let t_far = globals.right.w / globals.eye.w;
    let t0 = max(t_start, t_near);
    if (t0 >= t_far) {
        return g;
    }
    let x = walk_gap(e, d, t0, t_far, GAP_BLOCKS, true);
    if (!x.hit) {
        return g;
    }
    g.hit = true;
    g.q = e + d * x.t;
    g.column = x.column;
    let clip = globals.view_proj * vec4<f32>(g.q, 1.0);
    g.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    return g;
}
