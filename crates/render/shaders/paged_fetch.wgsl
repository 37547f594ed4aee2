// `terrain_pair` through the page table (swapped in for `terrain_fetch.wgsl`
// by `shaders::compose("paged:…")`): slot s of the atlas is page
// (s mod across, s / across) of layer s / per-layer, 128 pair texels x 256 rows.
#include "frame.wgsl"
#include "paged.wgsl"

// Meta byte of a missing chunk's box: terrain type 0, single level.
const PAGED_BOX_META: u32 = 0u;

fn terrain_pair(x: i32, y: i32) -> vec4<u32> {
    let chunk = paged_chunk(x, y);
    let e = paged_slot(chunk);
    if (e == 0u) {
        let h = paged_chunk_top(chunk);
        return vec4<u32>(h, PAGED_BOX_META, h, PAGED_BOX_META);
    }
    let slot = e - 1u;
    let layer = slot >> paged.atlas.y;
    let in_layer = slot & ((1u << paged.atlas.y) - 1u);
    let page = vec2<u32>(in_layer & ((1u << paged.atlas.x) - 1u), in_layer >> paged.atlas.x);
    let local = vec2<u32>((u32(x) & 255u) >> 1u, u32(y) & 255u);
    return textureLoad(terrain, page * vec2<u32>(128u, 256u) + local, layer, 0);
}
