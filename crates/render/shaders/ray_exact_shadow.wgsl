// The shared shadow map by the exact march: for every texel of the plane
// perpendicular to the light, the distance along the light to the first solid
// point (the same map `shadow.wgsl` fills by the 128-step march, exact here).
// The ray is rebased where it comes down to altitude 255.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_exact_core.wgsl"
#include "ray_exact_beam.wgsl"
#include "shadow_keep.wgsl"

const SHADOW_MISS: f32 = 1e9;

@group(1) @binding(3) var shadow_out: texture_storage_2d<r32float, write>;
// The 8x8-texel blocks the deferred frame's pixels sample, listed by its
// march (`ray_exact_deferred.wgsl`): `cs_exact_shadow_blocks` casts one per
// workgroup, dispatched indirectly by their count.
// Then the kept blocks' tags: the pass tags each block it casts
// (`shadow_keep.wgsl`).
@group(1) @binding(4) var<storage, read_write> shadow_blocks: array<u32>;

var<workgroup> group_most: atomic<u32>;

// Cast texel `id`: the distance along the light to its first solid point.
fn cast_texel(id: vec2<u32>) {
    cast_texel_from(id, 0.0, EXACT_START_LEVEL);
}

// `cast_texel` from no earlier than `start` (its block's beam,
// `exact_shadow_block_start`) and pyramid level `level`.
fn cast_texel_from(id: vec2<u32>, start: f32, level: u32) {
    let ray = exact_shadow_ray(id);
    let d = globals.light_dir.xyz;
    let base = exact_base(ray.p.xy);
    let rel = vec3<f32>(ray.p.xy - vec2<f32>(base), ray.p.z);
    page_pixel_begin();
    lod_shadow_rays();
    let h = exact_march_at(rel, base, d, max(start, 0.0), ray.span, level);
    page_shadow_end(page_pixel_missed());
    textureStore(shadow_out, shadow_slot(vec2<i32>(id)), vec4<f32>(select(SHADOW_MISS, ray.t_in + h.t, h.hit), 0.0, 0.0, 0.0));
    if (h.capped) {
        atomicAdd(&xstats[2], 1u);
    }
    if (EXACT_ITERATION_STATS) {
        atomicMax(&group_most, h.iterations);
    }
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
            textureStore(shadow_out, shadow_slot(vec2<i32>(id.xy)), vec4<f32>(SHADOW_MISS, 0.0, 0.0, 0.0));
        }
    }
    if (EXACT_ITERATION_STATS) {
        workgroupBarrier();
        if (li == 0u) {
            atomicMax(&xstats[3], atomicLoad(&group_most));
        }
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
    let first = vec2<u32>(block % across, block / across) * 8u;
    // The block's rays start at its beam, searched by the 64 invocations
    // at once (`ray_exact_beam.wgsl`).
    let start = exact_shadow_block_start(first, li);
    cast_texel_from(first + local.xy, start, exact_tile_level());
    if (li == 0u) {
        // Read by later frames' marches only, after this pass.
        shadow_block_keep(first / 8u);
    }
    if (EXACT_ITERATION_STATS) {
        workgroupBarrier();
        if (li == 0u) {
            atomicMax(&xstats[3], atomicLoad(&group_most));
        }
    }
}
