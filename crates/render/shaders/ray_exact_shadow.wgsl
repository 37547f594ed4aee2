// The shared shadow map by the exact march: for every texel of the plane
// perpendicular to the light, the distance along the light to the first solid
// point (the same map `shadow.wgsl` fills by the 128-step march, exact here).
// The ray is rebased where it comes down to altitude 255.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_exact_core.wgsl"

const SHADOW_MISS: f32 = 1e9;

@group(1) @binding(3) var shadow_out: texture_storage_2d<r32float, write>;
// The 8x8-texel blocks the deferred frame's pixels sample, listed by its
// march (`ray_exact_deferred.wgsl`): `cs_exact_shadow_blocks` casts one per
// workgroup, dispatched indirectly by their count.
@group(1) @binding(4) var<storage, read> shadow_blocks: array<u32>;

var<workgroup> group_most: atomic<u32>;

// Cast texel `id`: the distance along the light to its first solid point.
fn cast_texel(id: vec2<u32>) {
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
    page_pixel_begin();
    lod_shadow_rays();
    let h = exact_march(rel, base, d, 0.0, t_out - t_in);
    page_shadow_end(page_pixel_missed());
    textureStore(shadow_out, id, vec4<f32>(select(SHADOW_MISS, t_in + h.t, h.hit), 0.0, 0.0, 0.0));
    if (h.capped) {
        atomicAdd(&xstats[2], 1u);
    }
    atomicMax(&group_most, h.iterations);
}

// Every texel of the view's cover (`shadow_texel_cast`); a miss elsewhere.
@compute @workgroup_size(8, 8, 1)
fn cs_exact_shadow(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let side = u32(globals.shadow_u.w);
    if (id.x < side && id.y < side) {
        if (shadow_texel_cast(id.xy)) {
            cast_texel(id.xy);
        } else {
            // No visible point samples this texel this frame.
            textureStore(shadow_out, id.xy, vec4<f32>(SHADOW_MISS, 0.0, 0.0, 0.0));
        }
    }
    workgroupBarrier();
    if (li == 0u) {
        atomicMax(&xstats[3], atomicLoad(&group_most));
    }
}

// The deferred frame: workgroup k casts listed block `shadow_blocks[k]`. The
// other texels keep what they held: this map is the method's own (never
// reused, `shadow_map_is_partial`) and no pixel of the frame reads them.
@compute @workgroup_size(8, 8, 1)
fn cs_exact_shadow_blocks(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let across = u32(globals.shadow_u.w) / 8u;
    let block = shadow_blocks[group.x];
    cast_texel(vec2<u32>(block % across, block / across) * 8u + local.xy);
    workgroupBarrier();
    if (li == 0u) {
        atomicMax(&xstats[3], atomicLoad(&group_most));
    }
}
