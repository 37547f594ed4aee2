// `terrain_pair` through the page table, writing no feedback (swapped in for
// `terrain_fetch.wgsl` by `shaders::compose("paged-read:…")`): for stages that
// cannot write storage (a vertex stage) and draws the CPU placed over resident
// pages only (the paged mesh asks for its pages itself). A missing chunk reads
// as its coarse box, as in `paged_fetch.wgsl`, whose atlas addressing this is.
#include "frame.wgsl"
#include "paged.wgsl"

// The last chunk looked up and its table entry (a fragment's colour window
// reads one chunk many times in a row).
var<private> page_read_chunk: u32 = 0xffffffffu;
var<private> page_read_entry: u32 = 0u;

fn terrain_pair(x: i32, y: i32) -> vec4<u32> {
    let chunk = paged_chunk(x, y);
    if (chunk != page_read_chunk) {
        page_read_chunk = chunk;
        page_read_entry = page_table[chunk];
    }
    let e = page_read_entry;
    if (e == 0u) {
        let h = paged_chunk_top(chunk);
        return vec4<u32>(h, 0u, h, 0u);
    }
    let slot = e - 1u;
    let layer = slot >> paged.atlas.y;
    let in_layer = slot & ((1u << paged.atlas.y) - 1u);
    let page = vec2<u32>(in_layer & ((1u << paged.atlas.x) - 1u), in_layer >> paged.atlas.x);
    let local = vec2<u32>((u32(x) & 255u) >> 1u, u32(y) & 255u);
    return textureLoad(terrain, page * vec2<u32>(128u, 256u) + local, layer, 0);
}
