// `voxel` with its tiles' beam (`march_beam.wgsl`): each ray's traversal
// begins at the leaf that holds its tile's start (issue 36 item 2).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "voxel_occupancy.wgsl"
#include "voxel_core.wgsl"
#include "march_beam.wgsl"
#include "fullscreen.wgsl"


struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_voxel_beam(@builtin(position) pos: vec4<f32>) -> FragOut {
    let s = voxel_pixel_from(pos.x, pos.y, march_tile_start(pos.xy));
    var out: FragOut;
    out.color = s.color;
    out.depth = s.depth;
    return out;
}
