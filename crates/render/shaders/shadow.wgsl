// The shared 1024² shadow map, rendered once per frame: for every texel of a
// plane perpendicular to the light, the distance along the light to the first
// solid point (z = 0 is always solid, so every ray ends at or above it).
//
// Cost: a plain 128-step march from z = 255 made this ~1 s a frame on
// lavapipe. Instead the ray is clipped to the level's highest altitude and
// skips empty space with a conservative max-height pyramid (shadow.rs,
// `SkipPyramid`); near terrain it steps with the old march's spacing and
// bisects 4 times, so the result is at least as fine as before.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_core.wgsl"

// The old uniform march's sample count over the full [0, 255] band: the fine
// step keeps that spacing.
const SHADOW_STEPS: f32 = 128.0;
// Enough for every fine step of the band plus the skips between them.
const SHADOW_MAX_ITERS: u32 = 512u;
const SHADOW_MISS: f32 = 1e9;

struct ShadowParams {
    // finest block side in texels, pyramid levels, the level's highest altitude, unused
    block: u32,
    levels: u32,
    max_height: u32,
    pad: u32,
}

@group(1) @binding(0) var shadow_out: texture_storage_2d<r32float, write>;
// Level k, cell (i, j): the highest solid altitude in that block and its 8
// neighbours (blocks of `block << k` texels, wrapping like the level).
@group(1) @binding(1) var skip_max: texture_2d<u32>;
@group(1) @binding(2) var<uniform> params: ShadowParams;

fn block_max(p: vec3<f32>, k: u32) -> f32 {
    let side = params.block << k;
    // u32(i32) reinterprets the bits, so masking wraps negatives like the level.
    let x = (u32(i32(floor(p.x))) & (globals.level.x - 1u)) / side;
    let y = (u32(i32(floor(p.y))) & (globals.level.y - 1u)) / side;
    return f32(textureLoad(skip_max, vec2<u32>(x, y), i32(k)).r);
}

// How far along the light the ray at `p` may go without meeting terrain: the
// largest safe advance over the pyramid levels whose (dilated) max it is
// above, or 0 when it is not above even the finest one.
fn safe_advance(p: vec3<f32>, d: vec3<f32>) -> f32 {
    let down = max(-d.z, 1e-6);
    let across = max(max(abs(d.x), abs(d.y)), 1e-6);
    var best = 0.0;
    for (var k = 0u; k < params.levels; k = k + 1u) {
        let m = block_max(p, k);
        if (p.z <= m) {
            break;
        }
        // Stay within one block horizontally (the dilation's reach; a hair
        // less against rounding) and above the max vertically.
        let side = f32(params.block << k) - 0.01;
        best = max(best, min((p.z - m) / down, side / across));
    }
    return best;
}

@compute @workgroup_size(8, 8, 1)
fn cs_shadow(@builtin(global_invocation_id) id: vec3<u32>) {
    let side = u32(globals.shadow_u.w);
    if (id.x >= side || id.y >= side) {
        return;
    }
    let texel = globals.shadow_origin.w;
    let o = globals.shadow_origin.xyz
        + globals.shadow_u.xyz * ((f32(id.x) + 0.5) * texel)
        + globals.shadow_v.xyz * ((f32(id.y) + 0.5) * texel);
    let d = globals.light_dir.xyz;
    // Nothing is solid above the level's highest altitude.
    let seg = clip_to_altitudes(o, d, 0.0, 1e6);
    let top_t = (f32(params.max_height) - o.z) / d.z;
    let t_end = seg.y;
    var t = max(seg.x, min(top_t, t_end));
    let fine = MAX_ALTITUDE / max(-d.z, 1e-6) / SHADOW_STEPS;

    var hit = false;
    // `a` is the last parameter known to be empty; `skipped` says whether
    // [a, t) was certified empty by the pyramid (then t is the exact first
    // solid point) or is a fine step (then bisect).
    var a = t;
    var skipped = true;
    for (var i = 0u; i < SHADOW_MAX_ITERS && t <= t_end; i = i + 1u) {
        let p = o + d * t;
        let adv = safe_advance(p, d);
        if (adv > 0.0) {
            a = t;
            skipped = true;
            t = t + adv;
        } else {
            if (is_solid(p)) {
                hit = true;
                break;
            }
            a = t;
            skipped = false;
            t = t + fine;
        }
        if (t > t_end && a < t_end) {
            // The band's end (z = 0) is always sampled.
            t = t_end;
        }
    }
    if (hit && !skipped) {
        var b = t;
        for (var i = 0u; i < BISECTIONS; i = i + 1u) {
            let c = 0.5 * (a + b);
            if (is_solid(o + d * c)) {
                b = c;
            } else {
                a = c;
            }
        }
        t = b;
    }
    textureStore(shadow_out, id.xy, vec4<f32>(select(SHADOW_MISS, t, hit), 0.0, 0.0, 0.0));
}
