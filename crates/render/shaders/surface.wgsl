// Surface decode: the GPU twin of `strata_level::model::decode_column`.
// Needs frame.wgsl (globals.level, terrain).
#include "frame.wgsl"
#include "terrain_fetch.wgsl"

const META_DOUBLE_LEVEL: u32 = 0x40u;
const MAX_ALTITUDE: f32 = 255.0;

struct Column {
    low: f32,
    mid: f32,
    high: f32,
    dual: bool,
    lower_type: u32,
    upper_type: u32,
}

// The column at texel (x, y). Paged terrain's exact march may read it from
// a coarser copy of the map (`fetch_level`): the column of the block of
// 2^level texels holding (x, y).
fn decode_column(x: i32, y: i32) -> Column {
    let level = fetch_level();
    return decode_column_at(level, x >> level, y >> level);
}

// The column at texel (x, y) of level of detail `level` (0: the map).
fn decode_column_at(level: u32, x: i32, y: i32) -> Column {
    return decode_pair(terrain_pair_at(level, x, y), x);
}

// The column of texel x (its row is the pair's) of pair texel `p`
// (`terrain_pair`): both texels of a pair decode from the one fetch.
fn decode_pair(p: vec4<u32>, x: i32) -> Column {
    var c: Column;
    // The one pair rule: dual iff both texels carry the flag.
    if ((p.y & p.w & META_DOUBLE_LEVEL) != 0u) {
        let code = ((p.y & 3u) << 2u) | (p.w & 3u);
        c.low = f32(p.x);
        c.high = f32(p.z);
        c.mid = f32(min(p.x + ((code + globals.level.w) << 3u), p.z));
        c.dual = true;
        c.lower_type = (p.y >> 3u) & 7u;
        c.upper_type = (p.w >> 3u) & 7u;
    } else {
        let odd = (x & 1) == 1;
        let h = select(p.x, p.z, odd);
        let m = select(p.y, p.w, odd);
        c.low = f32(h);
        c.mid = c.low;
        c.high = c.low;
        c.dual = false;
        c.lower_type = (m >> 3u) & 7u;
        c.upper_type = c.lower_type;
    }
    return c;
}

// Height 0 is a real height: a texel of height 0 is solid at z = 0.
fn column_is_solid(c: Column, z: f32) -> bool {
    return z <= c.low || (c.dual && c.mid <= z && z <= c.high);
}

fn is_solid(p: vec3<f32>) -> bool {
    let c = decode_column(i32(floor(p.x)), i32(floor(p.y)));
    return column_is_solid(c, p.z);
}
