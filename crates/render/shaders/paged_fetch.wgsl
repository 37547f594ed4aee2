// `terrain_pair` through the page table (swapped in for `terrain_fetch.wgsl`
// by `shaders::compose("paged:…")`), asking for missing pages; the atlas is
// addressed by `paged_atlas_texel` (`paged.wgsl`).
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
    return paged_atlas_texel(e - 1u, bx, by);
}

// The level of detail `decode_column` reads at: the exact march's (see
// `exact_lod_at`; 0 everywhere else).
fn fetch_level() -> u32 {
    return page_lod;
}
