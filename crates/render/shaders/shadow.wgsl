// The shared 1024² shadow map, rendered once per frame by the ray-march core:
// for every texel of a plane perpendicular to the light, the distance along the
// light to the first solid point (a large value where the light reaches z = 0
// unblocked is impossible: z = 0 is always solid, so every ray ends there).
// Two entry points over one core: a compute pass writing a storage texture,
// and, where the adapter has no compute (WebGL2), a full-screen fragment pass
// into the same R32Float map as a render target.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_core.wgsl"
#include "fullscreen.wgsl"

// The camera ray's march with the paper's point test
// (`ray_core.wgsl::march_points`), 128 steps.
const SHADOW_STEPS: u32 = 128u;
const SHADOW_MISS: f32 = 1e9;

@group(1) @binding(0) var shadow_out: texture_storage_2d<r32float, write>;

// Distance along the light to the first solid point from the map's texel `id`
// (a miss for texels no visible point samples: `shadow_texel_cast`).
fn shadow_distance(id: vec2<u32>) -> f32 {
    if (!shadow_texel_cast(id)) {
        return SHADOW_MISS;
    }
    let o = shadow_texel_centre(id);
    let d = globals.light_dir.xyz;
    let seg = clip_to_altitudes(o, d, 0.0, 1e6);
    let h = march(o, d, seg.x, seg.y, SHADOW_STEPS, false);
    return select(SHADOW_MISS, h.t, h.hit);
}

@compute @workgroup_size(8, 8, 1)
fn cs_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = u32(globals.shadow_u.w);
    if (id.x >= side || id.y >= side) {
        return;
    }
    textureStore(shadow_out, shadow_slot(vec2<i32>(id.xy)), vec4<f32>(shadow_distance(id.xy), 0.0, 0.0, 0.0));
}

@fragment
fn fs_shadow(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    // The fragment lands on a slot of the texture: cast the texel it holds.
    return vec4<f32>(shadow_distance(shadow_texel_of_slot(vec2<u32>(pos.xy))), 0.0, 0.0, 1.0);
}
