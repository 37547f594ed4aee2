// The shared shadow map's march (`shadow.wgsl`) over paged terrain, composed
// `paged:`: the paged mesh fills the map itself. A texel whose march read a
// missing chunk (its coarse box) counts as pending, and the chunk is asked for.
#include "shadow.wgsl"
#include "paged_stamp.wgsl"

@compute @workgroup_size(8, 8, 1)
fn cs_shadow_paged(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = u32(globals.shadow_u.w);
    if (id.x >= side || id.y >= side) {
        return;
    }
    page_pixel_begin();
    let d = shadow_distance(id.xy);
    page_shadow_end(page_pixel_missed());
    textureStore(shadow_out, shadow_slot(vec2<i32>(id.xy)), vec4<f32>(d, 0.0, 0.0, 0.0));
}
