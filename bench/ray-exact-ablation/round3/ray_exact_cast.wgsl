// One texel of the shadow map by the exact march along the light: the
// distance from the map's plane to the first solid point. Shared by the
// shadow pass (`ray_exact_shadow.wgsl`) and the deferred march, which casts
// the 8x8-texel blocks it stamps first (`ray_exact_deferred.wgsl`).
// (Experiment file for fused-shadow.patch; register it in shaders.rs SOURCES.)
#include "frame.wgsl"
#include "ray_exact_core.wgsl"
#include "ray_exact_beam.wgsl"

const SHADOW_MISS: f32 = 1e9;

struct ShadowTexel {
    value: f32,
    iterations: u32,
    capped: bool,
}

fn exact_cast_texel(id: vec2<u32>, start: f32, level: u32) -> ShadowTexel {
    let ray = exact_shadow_ray(id);
    let d = globals.light_dir.xyz;
    let base = exact_base(ray.p.xy);
    let rel = vec3<f32>(ray.p.xy - vec2<f32>(base), ray.p.z);
    page_pixel_begin();
    lod_shadow_rays();
    let h = exact_march_at(rel, base, d, max(start, 0.0), ray.span, level);
    page_shadow_end(page_pixel_missed());
    return ShadowTexel(select(SHADOW_MISS, ray.t_in + h.t, h.hit), h.iterations, h.capped);
}

fn shadow_block_first(block: u32) -> vec2<u32> {
    let across = u32(globals.shadow_u.w) / 8u;
    return vec2<u32>(block % across, block / across) * 8u;
}

fn exact_cast_block_texel(block: u32, local: vec2<u32>, li: u32) -> ShadowTexel {
    let first = shadow_block_first(block);
    let start = exact_shadow_block_start(first, li);
    return exact_cast_texel(first + local, start, exact_tile_level());
}
