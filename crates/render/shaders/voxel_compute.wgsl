// `voxel-compute`: the same traversal as `voxel`, one invocation per pixel,
// writing colour and an R32Float depth through storage textures (the core's
// `fs_depth_blit` copies the depth into the shared depth target).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "voxel_occupancy.wgsl"
#include "voxel_core.wgsl"


@group(1) @binding(2) var color_out: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(3) var depth_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_voxel(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let s = voxel_pixel(f32(id.x) + 0.5, f32(id.y) + 0.5);
    textureStore(color_out, id.xy, s.color);
    textureStore(depth_out, id.xy, vec4<f32>(s.depth, 0.0, 0.0, 0.0));
}
