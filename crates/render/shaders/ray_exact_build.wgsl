// The max-height pyramid build on the GPU: the twin of `strata_maxmip`, bit
// for bit. One invocation per u32 word (4 tiles of a row) of the dispatched
// rectangle of one level. The layout keeps every s-th level (s = 1 or 2):
// level s from the terrain texture, level k from level k - s. Every word it
// is dispatched over is overwritten whole.
#include "frame.wgsl"
#include "surface.wgsl"

// Twin of `methods::ray_exact_build::BuildParams`.
struct BuildParams {
    // x first byte of this level, y log2 tiles across, z tiles down, w level k
    level: vec4<u32>,
    // x first byte of level k - s, y its log2 tiles across, z the step s
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

// The highest top of the pair holding texel x = 2 px in row y.
fn pair_top(px: u32, y: u32) -> u32 {
    let p = terrain_pair(i32(px * 2u), i32(y));
    if ((p.y & p.w & META_DOUBLE_LEVEL) != 0u) {
        return p.z;
    }
    return max(p.x, p.z);
}

@compute @workgroup_size(64, 1, 1)
fn cs_maxmip(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= bp.rect.z || id.y >= bp.rect.w) {
        return;
    }
    let log2w = bp.level.y;
    let first = ((bp.rect.y + id.y) << log2w) + (bp.rect.x + id.x) * 4u;
    var word = 0u;
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
        if (bp.level.w == s) {
            for (var r = 0u; r < n; r = r + 1u) {
                for (var p = 0u; p < n / 2u; p = p + 1u) {
                    m = max(m, pair_top(x * (n / 2u) + p, n * y + r));
                }
            }
        } else {
            for (var r = 0u; r < n; r = r + 1u) {
                let row = bp.child.x + ((n * y + r) << bp.child.y) + n * x;
                for (var c = 0u; c < n; c = c + 1u) {
                    m = max(m, child_byte(row + c));
                }
            }
        }
        word = word | (m << (b * 8u));
    }
    pyramid[(bp.level.x + first) >> 2u] = word;
}
