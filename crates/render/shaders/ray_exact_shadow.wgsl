// The shared shadow map by the exact march: for every texel of the plane
// perpendicular to the light, the distance along the light to the first solid
// point (the same map `shadow.wgsl` fills by the 128-step march, exact here).
// The ray is rebased where it comes down to altitude 255.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_exact_core.wgsl"

const SHADOW_MISS: f32 = 1e9;

@group(1) @binding(3) var shadow_out: texture_storage_2d<r32float, write>;

var<workgroup> group_most: atomic<u32>;

@compute @workgroup_size(8, 8, 1)
fn cs_exact_shadow(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let side = u32(globals.shadow_u.w);
    if (id.x < side && id.y < side && !shadow_texel_cast(id.xy)) {
        // No visible point samples this texel this frame.
        textureStore(shadow_out, id.xy, vec4<f32>(SHADOW_MISS, 0.0, 0.0, 0.0));
    } else if (id.x < side && id.y < side) {
        let texel = globals.shadow_origin.w;
        let o = globals.shadow_origin.xyz
            + globals.shadow_u.xyz * ((f32(id.x) + 0.5) * texel)
            + globals.shadow_v.xyz * ((f32(id.y) + 0.5) * texel);
        let d = globals.light_dir.xyz;
        // The light travels down: from altitude 255 to below 0, where every
        // column is solid.
        let t_in = (MAX_ALTITUDE - o.z) / d.z;
        let t_out = (-1.0 - o.z) / d.z;
        let p = o + d * t_in;
        let base = exact_base(p.xy);
        let rel = vec3<f32>(p.xy - vec2<f32>(base), p.z);
        let h = exact_march(rel, base, d, 0.0, t_out - t_in);
        textureStore(shadow_out, id.xy, vec4<f32>(select(SHADOW_MISS, t_in + h.t, h.hit), 0.0, 0.0, 0.0));
        if (h.capped) {
            atomicAdd(&xstats[2], 1u);
        }
        atomicMax(&group_most, h.iterations);
    }
    workgroupBarrier();
    if (li == 0u) {
        atomicMax(&xstats[3], atomicLoad(&group_most));
    }
}
