// `terrain_pair` through the page table, writing no feedback (swapped in for
// `terrain_fetch.wgsl` by `shaders::compose("paged-read:…")`): for stages that
// cannot write storage (a vertex stage) and draws the CPU placed over resident
// pages only (the paged mesh asks for its pages itself). A missing chunk reads
// as its coarse box, as in `paged_fetch.wgsl`; both address the atlas with
// `paged_atlas_texel` (`paged.wgsl`).
#include "frame.wgsl"
#include "paged.wgsl"

// The last page looked up and its table entry (a fragment's colour window
// reads one page many times in a row).
var<private> page_read_chunk: u32 = 0xffffffffu;
var<private> page_read_entry: u32 = 0u;

fn terrain_pair(x: i32, y: i32) -> vec4<u32> {
    return terrain_pair_at(0u, x, y);
}

// The pair at texel (x, y) of level of detail `level` (the paged mesh reads
// level 0 only).
fn terrain_pair_at(level: u32, x: i32, y: i32) -> vec4<u32> {
    let bx = u32(x) & ((globals.level.x >> level) - 1u);
    let by = u32(y) & ((globals.level.y >> level) - 1u);
    let id = paged_page(level, bx, by);
    if (id != page_read_chunk) {
        page_read_chunk = id;
        page_read_entry = page_table[id];
    }
    let e = page_read_entry;
    if (e == 0u) {
        let h = paged_chunk_top(paged_chunk_of(level, bx, by));
        return vec4<u32>(h, 0u, h, 0u);
    }
    return paged_atlas_texel(e - 1u, bx, by);
}

// The level `decode_column` reads at: always the map's texels here.
fn fetch_level() -> u32 {
    return 0u;
}
