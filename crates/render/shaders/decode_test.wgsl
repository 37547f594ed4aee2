// Test only: decode the columns at a list of texels, packed as
// low | mid << 8 | high << 16 | dual << 24 | lower_type << 25 | upper_type << 28.
#include "frame.wgsl"
#include "surface.wgsl"

@group(1) @binding(0) var<storage, read> positions: array<vec2<i32>>;
@group(1) @binding(1) var<storage, read_write> decoded: array<u32>;

@compute @workgroup_size(64, 1, 1)
fn cs_decode(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&positions)) {
        return;
    }
    let p = positions[id.x];
    let c = decode_column(p.x, p.y);
    decoded[id.x] = u32(c.low) | (u32(c.mid) << 8u) | (u32(c.high) << 16u)
        | (select(0u, 1u, c.dual) << 24u) | (c.lower_type << 25u) | (c.upper_type << 28u);
}
