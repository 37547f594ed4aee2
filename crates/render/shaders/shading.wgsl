// Shared shading, used by every method: palette colour of the terrain type,
// a normal that knows which interval it is on, diffuse light, 0.25 cave
// ambient below a slab, a PCF-sampled shadow map, and fog over the last
// 50 units before the far plane. Needs frame.wgsl and surface.wgsl.
#include "frame.wgsl"
#include "surface.wgsl"

// Ambient of lit (open-sky) ground: high enough that walls facing away from
// the sun and shadowed ground stay readable, as in the game's screenshots.
const AMBIENT: f32 = 0.45;
const CAVE_AMBIENT: f32 = 0.25;
const FOG_RANGE: f32 = 50.0;

// The shading's terrain fetches (the normal's neighbours) and shadow taps
// one after another rather than all in flight at once (a pipeline constant;
// the same values either way): each fetch's address takes a zero computed
// from the fetch before it (a terrain byte's bit 31; a shadow distance's
// sign bit, never set: every stored distance is positive), which the
// compiler cannot see is zero. Fewer values live at once, so a kernel that
// shades after a march may fit fewer registers (on NVIDIA, 32 a thread
// keeps every warp an SM can hold resident).
override SHADE_FETCH_CHAIN: bool = false;

const SURFACE_FLOOR: u32 = 0u;
const SURFACE_SLAB_TOP: u32 = 1u;
const SURFACE_CEILING: u32 = 2u;

// The palette colour of terrain type `t` lit by `light` in [0, 1]: like the
// original game, each type's begin..end range is a dark-to-light ramp and the
// light picks the entry (so shading stays within the world's own colours).
// The bottom of each ramp is near-black, so light 0 maps to RAMP_FLOOR of the
// way up: every surface keeps its hue and lit ground uses the bright part.
const RAMP_FLOOR: f32 = 0.3;

fn terrain_color(t: u32, light: f32) -> vec3<f32> {
    let r = shading.ranges[t & 7u];
    let k = RAMP_FLOOR + (1.0 - RAMP_FLOOR) * clamp(light, 0.0, 1.0);
    let idx = round(mix(f32(r.x), f32(r.y), k));
    return shading.palette[u32(clamp(idx, 0.0, 255.0))].rgb;
}

// Which interval a point on the surface of column `c` belongs to. `dir_z` is
// the vertical component of the ray that found it (a ray going up that hits
// the lower face of the slab has hit the cave ceiling).
fn surface_kind(c: Column, z: f32, dir_z: f32) -> u32 {
    if (!c.dual || z < 0.5 * (c.low + c.mid)) {
        return SURFACE_FLOOR;
    }
    if (dir_z > 0.0 && z - c.mid < c.high - z) {
        return SURFACE_CEILING;
    }
    return SURFACE_SLAB_TOP;
}

// The altitude field of one interval at texel (x, y); where a neighbour has
// no slab, the slab fields take `fallback` so its edge does not tilt.
fn interval_field(x: i32, y: i32, kind: u32, fallback: f32) -> f32 {
    return interval_field_at(0u, x, y, kind, fallback);
}

fn interval_field_at(level: u32, x: i32, y: i32, kind: u32, fallback: f32) -> f32 {
    return interval_of(decode_column_at(level, x, y), kind, fallback);
}

// `interval_field` of column `c`.
fn interval_of(c: Column, kind: u32, fallback: f32) -> f32 {
    if (kind == SURFACE_FLOOR) {
        return c.low;
    }
    if (!c.dual) {
        return fallback;
    }
    return select(c.high, c.mid, kind == SURFACE_CEILING);
}

// Normal from central height differences of the interval's own field: up for
// floors and slab tops, down for cave ceilings. Steep differences tilt it
// towards horizontal, which is what a wall gets.
fn surface_normal(x: i32, y: i32, kind: u32, here: f32) -> vec3<f32> {
    return surface_normal_at(0u, x, y, kind, here);
}

// `surface_normal` at texel (x, y) of level of detail `level`, whose texels
// are 2^level units apart.
fn surface_normal_at(level: u32, x: i32, y: i32, kind: u32, here: f32) -> vec3<f32> {
    return surface_normal_in(level, x, y, kind, here, terrain_pair_at(level, x, y));
}

// `surface_normal_at` given `pair`, the pair texel holding (x, y): one of
// the row's two neighbours is the other texel of that pair, so the normal
// takes three more fetches, not four.
fn surface_normal_in(level: u32, x: i32, y: i32, kind: u32, here: f32, pair: vec4<u32>) -> vec3<f32> {
    let spacing = f32(1u << level);
    let odd = (x & 1) == 1;
    // The pair holding the neighbour that is not in `pair`.
    let other = terrain_pair_at(level, select(x - 1, x + 1, odd), y);
    let north = terrain_pair_at(level, x, y + 1 + chain_zero(other.x));
    let south = terrain_pair_at(level, x, y - 1 + chain_zero(north.x));
    let east = interval_of(decode_pair(select(pair, other, odd), x + 1), kind, here);
    let west = interval_of(decode_pair(select(other, pair, odd), x - 1), kind, here);
    let gx = 0.5 * (east - west) / spacing;
    let gy = 0.5 * (interval_of(decode_pair(north, x), kind, here) - interval_of(decode_pair(south, x), kind, here)) / spacing;
    if (kind == SURFACE_CEILING) {
        return normalize(vec3<f32>(gx, gy, -1.0));
    }
    return normalize(vec3<f32>(-gx, -gy, 1.0));
}

// 0, from word `w` of a fetch whose bit 31 is never set, as a dependency
// on that fetch where `SHADE_FETCH_CHAIN` (a plain 0 otherwise).
fn chain_zero(w: u32) -> i32 {
    return select(0, i32(w >> 31u), SHADE_FETCH_CHAIN);
}

// One shadow-map test: x 1 lit, 0 shadowed (`t` already includes the
// bias); y `chain_zero` of the distance read (0 where none was).
fn shadow_tap_chained(ij: vec2<i32>, t: f32) -> ShadowTap {
    let side = i32(globals.shadow_u.w);
    if (any(ij < vec2<i32>(0)) || any(ij >= vec2<i32>(side))) {
        return ShadowTap(1.0, 0);
    }
    let blocker = textureLoad(shadow_map, shadow_slot(ij), 0).r;
    return ShadowTap(select(0.0, 1.0, t <= blocker), chain_zero(bitcast<u32>(blocker)));
}

struct ShadowTap {
    lit: f32,
    zero: i32,
}

// 4-tap PCF with bilinear weights over the shadow map. Against acne on the
// stair-stepped height field the point is pushed off the surface along its
// normal by 1.5 shadow texels, and the bias grows with the light's grazing
// angle (a shadow texel spans more depth on surfaces the light skims).
fn shadow_factor(p_surface: vec3<f32>, n: vec3<f32>) -> f32 {
    if (globals.light_dir.w == 0.0) {
        return 1.0;
    }
    let texel = globals.shadow_origin.w;
    let p = p_surface + n * (1.5 * texel);
    let rel = p - globals.shadow_origin.xyz;
    let uv = vec2<f32>(dot(rel, globals.shadow_u.xyz), dot(rel, globals.shadow_v.xyz)) / texel - 0.5;
    let ndl = max(dot(n, -globals.light_dir.xyz), 0.05);
    let slope = min(sqrt(1.0 - ndl * ndl) / ndl, 4.0);
    let t = dot(rel, globals.light_dir.xyz) - globals.shadow_v.w - slope * texel;
    let base = floor(uv);
    let f = uv - base;
    let ij = vec2<i32>(base);
    let s00 = shadow_tap_chained(ij, t);
    let s10 = shadow_tap_chained(ij + vec2<i32>(1 + s00.zero, 0), t);
    let s01 = shadow_tap_chained(ij + vec2<i32>(0, 1 + s10.zero), t);
    let s11 = shadow_tap_chained(ij + vec2<i32>(1, 1 + s01.zero), t);
    return mix(mix(s00.lit, s10.lit, f.x), mix(s01.lit, s11.lit, f.x), f.y);
}

// Fog factor: 0 up to 50 units before the far plane, 1 at it.
fn fog_factor(p: vec3<f32>) -> f32 {
    let view_z = dot(p - globals.eye.xyz, globals.forward.xyz);
    let far = globals.right.w;
    return clamp((view_z - (far - FOG_RANGE)) / FOG_RANGE, 0.0, 1.0);
}

// Shade a surface point `p` found along a ray of direction `dir` (any length).
fn shade_with_normal(p: vec3<f32>, c: Column, kind: u32, n: vec3<f32>) -> vec3<f32> {
    let t = select(c.upper_type, c.lower_type, kind == SURFACE_FLOOR);
    var light: f32;
    if (c.dual && (p.z < c.mid || kind == SURFACE_CEILING)) {
        // Under a slab (and its underside): the cave ambient, in every method.
        light = CAVE_AMBIENT;
    } else {
        let diffuse = max(dot(n, -globals.light_dir.xyz), 0.0);
        light = AMBIENT + (1.0 - AMBIENT) * diffuse * shadow_factor(p, n);
    }
    let color = terrain_color(t, light);
    return mix(color, globals.sky.rgb, fog_factor(p));
}

// Shade with the height-field normal (every method but the mesh, which passes
// its geometric normal to `shade_with_normal`).
fn shade(p: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    return shade_column(p, i32(floor(p.x)), i32(floor(p.y)), dir);
}

// `shade` at a point of column (x, y) named by the caller: an exact march hit
// on a column's side lies on the texel line, where `floor(p)` may name the
// neighbour the ray came from.
fn shade_column(p: vec3<f32>, x: i32, y: i32, dir: vec3<f32>) -> vec3<f32> {
    return shade_column_at(p, 0u, x, y, dir);
}

// `shade_column` for a hit on texel (x, y) of level of detail `level`.
fn shade_column_at(p: vec3<f32>, level: u32, x: i32, y: i32, dir: vec3<f32>) -> vec3<f32> {
    let pair = terrain_pair_at(level, x, y);
    let c = decode_pair(pair, x);
    let kind = surface_kind(c, p.z, dir.z);
    let here = select(c.high, c.mid, kind == SURFACE_CEILING);
    let n = surface_normal_in(level, x, y, kind, here, pair);
    return shade_with_normal(p, c, kind, n);
}
