// `sliced_shade_compute.wgsl` on frames whose rows walk, with the gap pass
// folded in: each pixel whose ray crosses the slices more than GAP_MIN
// texels apart walks it from its tile's beam start (`sliced_gap_walk.wgsl`,
// the gap pass's walk) and keeps the point it finds where it lies before the
// slice the depth buffer holds, as the gap pass's depth test (Less) keeps
// it. The walks run on the whole chip instead of the graphics path (H100:
// the gap pass took 0.9-1.8 ms on the views that walk). A compute pass
// cannot write the depth target: it writes every pixel's depth into
// `depth_out`, which a full-screen pass copies there (`depth_blit.wgsl`).
#include "sliced_shade_compute.wgsl"
#include "sliced_gap_walk.wgsl"
#include "march_beam.wgsl"

// The slices' depth (the shared depth target, read here, written after).
@group(1) @binding(6) var slice_depth: texture_depth_2d;
@group(1) @binding(7) var depth_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8, 1)
fn cs_sliced_shade_walk(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let pos = vec2<f32>(id.xy) + vec2<f32>(0.5);
    var depth = textureLoad(slice_depth, id.xy, 0);
    let g = gap_walk(pos, march_tile_start(pos), footprint.count.y);
    var colour = globals.sky.rgb;
    if (g.hit && g.depth < depth) {
        depth = g.depth;
        colour = shade_column(g.q, g.column.x, g.column.y, g.q - globals.eye.xyz);
    } else {
        let mark = textureLoad(slice_marks, id.xy, 0).x;
        if (mark != 0u) {
            colour = marked_colour(pos, mark);
        }
    }
    textureStore(color_out, id.xy, vec4<f32>(colour, 1.0));
    textureStore(depth_out, id.xy, vec4<f32>(depth, 0.0, 0.0, 0.0));
}
