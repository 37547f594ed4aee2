// `terrain_pair` through the page table (swapped in for `terrain_fetch.wgsl`
// by `shaders::compose("paged:…")`): slot s of the atlas is page
// (s mod across, s / across) of layer s / per-layer, 128 pair texels x 256 rows.
#include "frame.wgsl"
#include "paged.wgsl"

// Meta byte of a missing chunk's box: terrain type 0, single level.
const PAGED_BOX_META: u32 = 0u;

fn terrain_pair(x: i32, y: i32) -> vec4<u32> {
    return terrain_pair_at(0u, x, y);
}

// The pair holding texel (x, y) of level of detail `level` (the map halved
// `level` times; `strata_level::lod`), wrapping. A missing page reads as the
// box of the chunk under the texel.
fn terrain_pair_at(level: u32, x: i32, y: i32) -> vec4<u32> {
    let bx = u32(x) & ((globals.level.x >> level) - 1u);
    let by = u32(y) & ((globals.level.y >> level) - 1u);
    let e = paged_slot(paged_page(level, bx, by));
    if (e == 0u) {
        let h = paged_chunk_top(paged_chunk_of(level, bx, by));
        return vec4<u32>(h, PAGED_BOX_META, h, PAGED_BOX_META);
    }
    let slot = e - 1u;
    let layer = slot >> paged.atlas.y;
    let in_layer = slot & ((1u << paged.atlas.y) - 1u);
    let page = vec2<u32>(in_layer & ((1u << paged.atlas.x) - 1u), in_layer >> paged.atlas.x);
    let local = vec2<u32>((bx & 255u) >> 1u, by & 255u);
    return textureLoad(terrain, page * vec2<u32>(128u, 256u) + local, layer, 0);
}

// The level of detail `decode_column` reads at: the exact march's (see
// `exact_lod_at`; 0 everywhere else).
fn fetch_level() -> u32 {
    return page_lod;
}
