// `ray`: the paper's height-field march as one full-screen fragment pass.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_pixel.wgsl"
#include "fullscreen.wgsl"

struct RayParams {
    // x: forward samples per ray
    steps: vec4<u32>,
}

@group(1) @binding(0) var<uniform> params: RayParams;

struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_ray(@builtin(position) pos: vec4<f32>) -> FragOut {
    let s = ray_pixel(pos.x, pos.y, params.steps.x);
    var out: FragOut;
    out.color = s.color;
    out.depth = s.depth;
    return out;
}
