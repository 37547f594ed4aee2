// The max-height pyramid build on the GPU: the twin of `strata_maxmip`, bit
// for bit. One invocation per u32 word (4 tiles of a row) of the dispatched
// rectangle of one level. The layout keeps every s-th level (s = 1 or 2):
// level s from the terrain texture, level k from level k - s. Every word it
// is dispatched over is overwritten whole. The same invocation writes its
// four tiles' cave bounds (`strata_maxmip::CavePyramid`: the highest floor
// top and the lowest slab bottom, 16 bits a tile, two words) into the cave
// region that follows the maxima in the same buffer.
#include "frame.wgsl"
#include "surface.wgsl"

// Twin of `methods::ray_exact_build::BuildParams`.
struct BuildParams {
    // x first byte of this level, y log2 tiles across, z tiles down, w level k
    // (0: the texel plane, `strata_maxmip::TexelTops`, one byte per texel)
    level: vec4<u32>,
    // x first byte of level k - s, y its log2 tiles across, z the step s,
    // w the cave region's first byte (tile i's bounds: its u16 i there), or
    // NO_CAVES for a buffer without one
    child: vec4<u32>,
    // x first word column, y first row, z word columns, w rows
    // (levels under 4 tiles across: all their words as one row from 0)
    rect: vec4<u32>,
}

@group(1) @binding(0) var<uniform> bp: BuildParams;
@group(1) @binding(1) var<storage, read_write> pyramid: array<u32>;

fn child_byte(i: u32) -> u32 {
    return (pyramid[i >> 2u] >> ((i & 3u) << 3u)) & 0xffu;
}

// A tile's cave bounds when it has no slab (`strata_maxmip::NO_SLAB`).
const NO_SLAB: u32 = 255u;
// `bp.child.w` of a pyramid without cave bounds (the fragment methods' beams).
const NO_CAVES: u32 = 0xffffffffu;

// Tile i's cave bounds (x the highest floor top, y the lowest slab bottom).
fn child_cave(i: u32) -> vec2<u32> {
    let v = (pyramid[(bp.child.w >> 2u) + (i >> 1u)] >> ((i & 1u) << 4u)) & 0xffffu;
    return vec2<u32>(v & 0xffu, v >> 8u);
}

// The cave bounds of the pair holding texel x = 2 px in row y (as
// `decode_column` reads it): a dual pair's floor and slab bottom, else the
// higher of the two texels and no slab.
fn pair_cave(px: u32, y: u32) -> vec2<u32> {
    let p = terrain_pair(i32(px * 2u), i32(y));
    if ((p.y & p.w & META_DOUBLE_LEVEL) != 0u) {
        let code = ((p.y & 3u) << 2u) | (p.w & 3u);
        return vec2<u32>(p.x, min(p.x + ((code + globals.level.w) << 3u), p.z));
    }
    return vec2<u32>(max(p.x, p.z), NO_SLAB);
}

// The highest top of the pair holding texel x = 2 px in row y.
fn pair_top(px: u32, y: u32) -> u32 {
    let p = terrain_pair(i32(px * 2u), i32(y));
    if ((p.y & p.w & META_DOUBLE_LEVEL) != 0u) {
        return p.z;
    }
    return max(p.x, p.z);
}

// The texel plane's bytes of the pair `p` (`terrain_pair`), in the low 16
// bits: each texel's height where the pair is single floors, 255
// (`strata_maxmip::TEXEL_DECODE`: decode the column) for both where it is a
// slab pair. A single floor of 255 is 255 either way.
fn pair_texel_bytes(p: vec4<u32>) -> u32 {
    if ((p.y & p.w & META_DOUBLE_LEVEL) != 0u) {
        return 0xffffu;
    }
    return p.x | (p.z << 8u);
}

@compute @workgroup_size(64, 1, 1)
fn cs_maxmip(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= bp.rect.z || id.y >= bp.rect.w) {
        return;
    }
    let log2w = bp.level.y;
    let first = ((bp.rect.y + id.y) << log2w) + (bp.rect.x + id.x) * 4u;
    if (bp.level.w == 0u) {
        // The texel plane: this word's four texels, two pairs of one row.
        let x = first & ((1u << log2w) - 1u);
        let y = first >> log2w;
        let a = pair_texel_bytes(terrain_pair(i32(x), i32(y)));
        let b = pair_texel_bytes(terrain_pair(i32(x + 2u), i32(y)));
        pyramid[(bp.level.x + first) >> 2u] = a | (b << 16u);
        return;
    }
    var word = 0u;
    var caves = array<u32, 4>(NO_SLAB << 8u, NO_SLAB << 8u, NO_SLAB << 8u, NO_SLAB << 8u);
    for (var b = 0u; b < 4u; b = b + 1u) {
        let i = first + b;
        let x = i & ((1u << log2w) - 1u);
        let y = i >> log2w;
        if (y >= bp.level.z) {
            continue;
        }
        // The tile is n x n tiles of the level s below (texels at level s).
        let s = bp.child.z;
        let n = 1u << s;
        var m = 0u;
        var cave = vec2<u32>(0u, NO_SLAB);
        if (bp.level.w == s) {
            for (var r = 0u; r < n; r = r + 1u) {
                for (var p = 0u; p < n / 2u; p = p + 1u) {
                    m = max(m, pair_top(x * (n / 2u) + p, n * y + r));
                    let c = pair_cave(x * (n / 2u) + p, n * y + r);
                    cave = vec2<u32>(max(cave.x, c.x), min(cave.y, c.y));
                }
            }
        } else {
            for (var r = 0u; r < n; r = r + 1u) {
                let row = bp.child.x + ((n * y + r) << bp.child.y) + n * x;
                for (var c = 0u; c < n; c = c + 1u) {
                    m = max(m, child_byte(row + c));
                    let k = child_cave(row + c);
                    cave = vec2<u32>(max(cave.x, k.x), min(cave.y, k.y));
                }
            }
        }
        word = word | (m << (b * 8u));
        caves[b] = cave.x | (cave.y << 8u);
    }
    pyramid[(bp.level.x + first) >> 2u] = word;
    if (bp.child.w == NO_CAVES) {
        return;
    }
    let cave_word = (bp.child.w >> 2u) + ((bp.level.x + first) >> 1u);
    pyramid[cave_word] = caves[0] | (caves[1] << 16u);
    pyramid[cave_word + 1u] = caves[2] | (caves[3] << 16u);
}
