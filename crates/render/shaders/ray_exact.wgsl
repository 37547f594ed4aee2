// `ray-exact`: the exact march (`ray_exact_core.wgsl`), one invocation per
// pixel, colour straight into the shared colour target and depth into an
// R32Float image that a depth pass moves into the shared depth target.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_exact_core.wgsl"
#include "ray_exact_pixel.wgsl"
#include "ray_exact_beam.wgsl"

@group(1) @binding(3) var color_out: texture_storage_2d<rgba8unorm, write>;
@group(1) @binding(4) var depth_out: texture_storage_2d<r32float, write>;

var<workgroup> group_most: atomic<u32>;

@compute @workgroup_size(8, 8, 1)
fn cs_ray_exact(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let size = vec2<u32>(globals.screen.xy);
    // The tile's beam (every invocation: the wide search is the workgroup's).
    let start = exact_group_start(group.xy, li);
    if (all(id.xy < size)) {
        page_pixel_begin();
        let s = exact_pixel_from(f32(id.x) + 0.5, f32(id.y) + 0.5, start, exact_tile_level());
        page_pixel_end(page_pixel_missed());
        textureStore(color_out, id.xy, s.color);
        textureStore(depth_out, id.xy, vec4<f32>(s.depth, 0.0, 0.0, 0.0));
        if (s.capped) {
            atomicAdd(&xstats[0], 1u);
        }
        if (EXACT_ITERATION_STATS) {
            atomicMax(&group_most, s.iterations);
        }
    }
    if (EXACT_ITERATION_STATS) {
        workgroupBarrier();
        if (li == 0u) {
            atomicMax(&xstats[1], atomicLoad(&group_most));
        }
    }
}
