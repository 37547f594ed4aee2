// `sliced_shade.wgsl` as a compute pass (one invocation a pixel, the whole
// chip rather than the graphics path's few SMs): every pixel's colour, the
// sky where no slice was kept.
#include "sliced_shade.wgsl"

@group(1) @binding(5) var color_out: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_sliced_shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let mark = textureLoad(slice_marks, id.xy, 0).x;
    var colour = globals.sky.rgb;
    if (mark != 0u) {
        colour = marked_colour(vec2<f32>(id.xy) + vec2<f32>(0.5), mark);
    }
    textureStore(color_out, id.xy, vec4<f32>(colour, 1.0));
}
