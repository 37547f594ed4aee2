// `voxel`: the voxel-accelerated ray march as one full-screen fragment pass.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "voxel_occupancy.wgsl"
#include "voxel_core.wgsl"
#include "fullscreen.wgsl"


struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_voxel(@builtin(position) pos: vec4<f32>) -> FragOut {
    let s = voxel_pixel(pos.x, pos.y);
    var out: FragOut;
    out.color = s.color;
    out.depth = s.depth;
    return out;
}
