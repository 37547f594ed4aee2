// `mesh`'s deferred colour pass: after the raster pass has written depth and
// each covered pixel's two words (`fs_mesh_gbuffer`), one invocation per
// pixel runs the colour step (`mesh_pixel_colour`, the fragment path's) and
// writes the shared colour target; uncovered pixels take the sky. The
// fragment path ran the step per fragment on the graphics path (overdraw
// included), which on the H100 uses a few of its SMs.
#include "frame.wgsl"
#include "mesh_colour.wgsl"

@group(1) @binding(3) var gbuffer: texture_2d<u32>;
@group(1) @binding(4) var color_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_mesh_colour(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let g = textureLoad(gbuffer, id.xy, 0).xy;
    var colour = globals.sky.rgb;
    if (g.x != 0u) {
        colour = mesh_pixel_colour(vec2<f32>(id.xy) + vec2<f32>(0.5), g);
    }
    textureStore(color_out, id.xy, vec4<f32>(colour, 1.0));
}
