// The slices' walks along a pixel's ray, shared by `sliced.wgsl` (a slice
// fragment's gap walk) and `sliced_refine.wgsl` (the refine pass's search):
// the culling tiles' parameters and the block maxima (group 1, bindings 1
// and 3 in both), and `walk_gap`.
#include "column_segment.wgsl"

// Twin of `methods::slice_tiles::SliceTileParams`.
struct SliceTiles {
    // x, y: the footprint's first tile (unwrapped); z, w: tiles across and
    // down (z 0: no culling, each slice one quad over the whole footprint)
    grid: vec4<i32>,
    // x: log2 of the tile side; y, z: the map's tiles across and down - 1;
    // w: log2 of the block side
    tiles: vec4<u32>,
}

@group(1) @binding(1) var<uniform> slice_tiles: SliceTiles;
// The highest solid top over each block of side 2^tiles.w
// (`tiles::BLOCK_LOG2`) of the map and a one-texel margin.
@group(1) @binding(3) var block_max: texture_2d<u32>;

// `first_entry` (the first solid point of e + t d, t in [t0, t1]) block by
// block of the block maxima: a block whose highest top (margin included) is
// below the segment's lowest point in it is stepped over whole; at most
// `blocks` blocks, each walked whole (a segment crosses at most 2 side + 1
// columns of one).
// Not `exact`: a block the segment comes down to counts as a hit at its
// entry (the refine pass's marks: it searches the exact crossing itself).
fn walk_gap(e: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, blocks: u32, exact: bool) -> SegmentHit {
    var r: SegmentHit;
    r.hit = false;
    r.t = t1;
    let k = slice_tiles.tiles.w;
    let side = f32(1u << k);
    // The map's blocks across and down - 1, from its tiles'.
    let mask = ((slice_tiles.tiles.yz + vec2<u32>(1u)) << vec2<u32>(slice_tiles.tiles.x - k)) - vec2<u32>(1u);
    let pos = d.xy > vec2<f32>(0.0);
    // vec2<i32>(bool) rather than select: GLSL ES 3.00 (WebGL2) has no
    // mix() on ints.
    let step = 2 * vec2<i32>(pos) - vec2<i32>(1);
    let still = d.xy == vec2<f32>(0.0);
    let inv = select(vec2<f32>(1.0) / d.xy, vec2<f32>(0.0), still);
    var block = vec2<i32>(floor((e.xy + d.xy * t0) / side));
    var t = t0;
    for (var i = 0u; i < blocks; i = i + 1u) {
        let edge = vec2<f32>(block + vec2<i32>(pos)) * side;
        let tb = select((edge - e.xy) * inv, vec2<f32>(3.0e38), still);
        let t_out = max(min(min(tb.x, tb.y), t1), t);
        let z_min = min(e.z + d.z * t, e.z + d.z * t_out);
        if (z_min <= f32(textureLoad(block_max, vec2<u32>(block) & mask, 0).r)) {
            if (!exact) {
                r.hit = true;
                r.t = t;
                return r;
            }
            let h = first_entry(e, d, t, t_out, (2u << k) + 2u);
            if (h.hit) {
                return h;
            }
        }
        if (t_out >= t1) {
            break;
        }
        t = t_out;
        if (tb.x <= tb.y) {
            block.x = block.x + step.x;
        } else {
            block.y = block.y + step.y;
        }
    }
    return r;
}
