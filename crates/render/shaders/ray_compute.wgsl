// `ray-compute`: the same march as `ray`, one invocation per pixel, writing
// colour straight into the shared colour target and depth into an R32Float
// storage texture; `fs_depth_blit` then copies that into the shared depth target.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_pixel.wgsl"
#include "fullscreen.wgsl"

struct RayParams {
    steps: vec4<u32>,
}

@group(1) @binding(0) var<uniform> params: RayParams;
@group(1) @binding(1) var color_out: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(2) var depth_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_ray(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let s = ray_pixel(f32(id.x) + 0.5, f32(id.y) + 0.5, params.steps.x);
    textureStore(color_out, id.xy, s.color);
    textureStore(depth_out, id.xy, vec4<f32>(s.depth, 0.0, 0.0, 0.0));
}
