// The occupancy pyramid build on the GPU: the twin of
// `strata_occupancy::build`, bit for bit. Both entry points overwrite every
// word of the tile columns they are dispatched over, so an incremental
// rebuild needs no clearing.
#include "frame.wgsl"
#include "surface.wgsl"

struct BuildParams {
    // level-0 voxel size x, y, z; w unused
    voxel: vec4<u32>,
    // this level: cells x, y, z, first word
    dims: vec4<u32>,
    // this level: tiles x, y, z; w unused
    tiles: vec4<u32>,
    // the child level (reductions): tiles x, y, z, first word
    child: vec4<u32>,
    // this dispatch's tile columns: first x, first y, count in x; w unused
    origin: vec4<u32>,
}

@group(1) @binding(0) var<uniform> bp: BuildParams;
@group(1) @binding(1) var<storage, read_write> occ: array<u32>;

// Voxel-z occupancy of each of the tile column's 64 voxel columns (256 bits each).
var<workgroup> zmask: array<u32, 512>;

fn gather3(m: u32) -> u32 {
    return (m & 1u) | ((m >> 2u) & 2u) | ((m >> 4u) & 4u);
}

// Bits lo..=hi of an 8-word z mask (hi < 256).
fn set_range(masks: ptr<function, array<u32, 8>>, lo: u32, hi: u32) {
    for (var i = 0u; i < 8u; i = i + 1u) {
        let base = i * 32u;
        if (hi < base || lo >= base + 32u) {
            continue;
        }
        let a = max(lo, base) - base;
        let b = min(hi - base, 31u);
        let n = b - a + 1u;
        let bits = select(((1u << n) - 1u) << a, 0xffffffffu, n == 32u);
        (*masks)[i] = (*masks)[i] | bits;
    }
}

// One workgroup per level-0 tile column: each invocation unions the solid
// intervals of its voxel column's texels into a z mask, then the group writes
// the column's words in Morton order.
@compute @workgroup_size(64, 1, 1)
fn cs_leaf(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let tx = bp.origin.x + wg.x;
    let ty = bp.origin.y + wg.y;
    let vx = tx * 8u + (li & 7u);
    let vy = ty * 8u + (li >> 3u);
    let vs = bp.voxel.xyz;
    var m: array<u32, 8>;
    if (vx < bp.dims.x && vy < bp.dims.y) {
        var floor_top = 0u;
        for (var y = vy * vs.y; y < (vy + 1u) * vs.y; y = y + 1u) {
            for (var x = vx * vs.x; x < (vx + 1u) * vs.x; x = x + 1u) {
                let c = decode_column(i32(x), i32(y));
                // Closed voxel ranges [vz z, (vz + 1) z]: the CPU's `column_voxel_ranges`.
                floor_top = max(floor_top, u32(c.low) / vs.z);
                if (c.dual) {
                    let mid = u32(c.mid);
                    let lo = max((mid + vs.z - 1u) / vs.z, 1u) - 1u;
                    set_range(&m, lo, u32(c.high) / vs.z);
                }
            }
        }
        set_range(&m, 0u, floor_top);
    }
    for (var i = 0u; i < 8u; i = i + 1u) {
        zmask[li * 8u + i] = m[i];
    }
    workgroupBarrier();
    let column_words = bp.tiles.z * 16u;
    let base = bp.dims.w + (ty * bp.tiles.x + tx) * column_words;
    // Bounded: `w` rises by 64 to `column_words` (16 words a tile of the
    // column's height: far below u32's end).
    for (var w = li; w < column_words; w = w + 64u) {
        let tz = w >> 4u;
        let wi = w & 15u;
        var bits = 0u;
        for (var b = 0u; b < 32u; b = b + 1u) {
            let mc = wi * 32u + b;
            let col = gather3(mc) + 8u * gather3(mc >> 1u);
            let vz = tz * 8u + gather3(mc >> 2u);
            if (vz < 256u && ((zmask[col * 8u + (vz >> 5u)] >> (vz & 31u)) & 1u) != 0u) {
                bits = bits | (1u << b);
            }
        }
        occ[base + w] = bits;
    }
}

// One invocation per word of a parent tile column: the parent tile's octant
// `w >> 1` is one child tile, each of whose 64 bytes (a 2x2x2 block) becomes
// one parent bit. Dispatch (ceil(column words / 64), tile columns).
@compute @workgroup_size(64, 1, 1)
fn cs_reduce(@builtin(global_invocation_id) id: vec3<u32>) {
    let column_words = bp.tiles.z * 16u;
    if (id.x >= column_words) {
        return;
    }
    let tx = bp.origin.x + id.y % bp.origin.z;
    let ty = bp.origin.y + id.y / bp.origin.z;
    let w = id.x & 15u;
    let tz = id.x >> 4u;
    let oct = w >> 1u;
    let half = w & 1u;
    let c = vec3<u32>(tx * 2u + (oct & 1u), ty * 2u + ((oct >> 1u) & 1u), tz * 2u + (oct >> 2u));
    var bits = 0u;
    if (all(c < bp.child.xyz)) {
        let tile = (c.y * bp.child.x + c.x) * bp.child.z + c.z;
        let cbase = bp.child.w + tile * 16u + half * 8u;
        for (var k = 0u; k < 8u; k = k + 1u) {
            let cw = occ[cbase + k];
            for (var byte = 0u; byte < 4u; byte = byte + 1u) {
                if (((cw >> (byte * 8u)) & 0xffu) != 0u) {
                    bits = bits | (1u << (k * 4u + byte));
                }
            }
        }
    }
    occ[bp.dims.w + (ty * bp.tiles.x + tx) * column_words + id.x] = bits;
}
