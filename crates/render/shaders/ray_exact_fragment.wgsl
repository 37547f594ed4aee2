// `ray-exact-fragment`: the same exact march and shading as `ray-exact`, as
// one full-screen fragment pass writing colour and depth.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_exact_core.wgsl"
#include "ray_exact_pixel.wgsl"
#include "fullscreen.wgsl"

struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_ray_exact(@builtin(position) pos: vec4<f32>) -> FragOut {
    page_pixel_begin();
    let s = exact_pixel(pos.x, pos.y);
    page_pixel_end(page_pixel_missed());
    if (s.capped) {
        atomicAdd(&xstats[0], 1u);
    }
    var out: FragOut;
    out.color = s.color;
    out.depth = s.depth;
    return out;
}
