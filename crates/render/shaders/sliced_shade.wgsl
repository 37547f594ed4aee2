// Plain `sliced`, deferred: the slices wrote no colour, only each pixel's
// nearest kept slice (`fs_slice_mark_steep`: rank + 1 into `slice_marks`,
// 0 = none) and its depth. This pass shades that slice's point once a pixel,
// the point `fs_sliced_steep` would have shaded: the pixel's ray meets the
// slice's plane. The slices' shading ran for every kept fragment the depth
// test let through, before the test could reject it (a shader that discards
// writes depth late), so a pixel was shaded once per solid slice drawn
// before its nearest (H100: the plain slice pass took 7.1-12.2 ms on the
// steep views, its marks alone 3.9-6.5).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"
#include "fullscreen.wgsl"

// count.y: slices N.
@group(1) @binding(0) var<uniform> footprint: Footprint;
@group(1) @binding(4) var slice_marks: texture_2d<u32>;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;

// The colour of the slice `mark` (rank + 1) at pixel centre `pos`, as
// `sliced.wgsl::slice_point` and `slice_colour` compute it. (An edge-on ray,
// parallel to the slices, meets a plane only within a hair of the eye's
// altitude, never in front of the near plane; its mark cannot occur.)
fn marked_colour(pos: vec2<f32>, mark: u32) -> vec3<f32> {
    let altitude = SLICE_TOP - f32(mark) * (SLICE_TOP / f32(footprint.count.y));
    let d = camera_ray(pos.x, pos.y);
    let e = globals.eye.xyz;
    let p = e + d * ((altitude - e.z) / d.z);
    let cell = vec2<i32>(floor(p.xy));
    return shade_column(p, cell.x, cell.y, p - e);
}

// Adapters without compute or storage textures, and frames drawn into a
// caller's colour attachment: a full-screen triangle over the colour the
// pass cleared to sky (depth untouched).
@fragment
fn fs_sliced_shade(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let mark = textureLoad(slice_marks, vec2<i32>(pos.xy), 0).x;
    if (mark == 0u) {
        discard;
    }
    return vec4<f32>(marked_colour(pos.xy, mark), 1.0);
}
