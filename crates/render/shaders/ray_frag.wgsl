// `ray`'s fragment: its uniform and one pixel of the march (`ray.wgsl`
// without a beam, `ray_beam.wgsl` with its tile's start).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_pixel.wgsl"

struct RayParams {
    // x: forward samples per ray; y: the map's highest top (255: none
    // known, the march as the paper's)
    steps: vec4<u32>,
}

@group(1) @binding(0) var<uniform> params: RayParams;

struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The pixel at `pos` whose ray is empty before `start`.
fn ray_fragment(pos: vec4<f32>, start: f32) -> FragOut {
    let s = ray_pixel_from(pos.x, pos.y, params.steps.x, start, f32(params.steps.y));
    var out: FragOut;
    out.color = s.color;
    out.depth = s.depth;
    return out;
}
