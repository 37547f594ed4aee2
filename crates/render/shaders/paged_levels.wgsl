// `maxmip_get` over pages (swapped in for `exact_levels.wgsl`): the 256-texel
// level is the always-resident coarse level (one byte per chunk); finer levels
// live in the resident page's own pyramid, and a missing page reads as its
// chunk's top (a conservative box: see `paged.wgsl`).
//
// Level of detail: where a ray's footprint has grown to 2^k texels
// (`exact_leaf`), the march reads the level-k copy of the map
// (`strata_level::lod`: each texel the highest-topped pair of its 2^k block)
// from that level's pages: a texel's column is its block's (`decode_column`),
// and tile maxima come from those pages' own pyramids, so the march stays
// consistent with the columns it tests. The traversal itself is unchanged.
#include "frame.wgsl"
#include "paged.wgsl"

// A ray's footprint in texels at t: `lod_per_t * t + lod_fixed`, in units of
// the LOD's pixel tolerance (see `lod_camera_rays`, `lod_shadow_rays`).
var<private> lod_per_t: f32 = 0.0;
var<private> lod_fixed: f32 = 0.0;

// Camera rays: a pixel at t spans t texels (`camera_ray`'s length along the
// view axis is the focal length).
fn lod_camera_rays() {
    lod_per_t = paged.lod.x;
    lod_fixed = 0.0;
}

// Shadow rays: one shadow-map texel wide wherever they go.
fn lod_shadow_rays() {
    lod_per_t = 0.0;
    lod_fixed = paged.lod.y * globals.shadow_anchor.w;
}

// The coarsest level whose texels a ray at `t` may take for columns: the
// largest 2^k no wider than its footprint, a multiple of the march's level
// ratio (the page pyramids keep those levels), at most the coarsest kept.
fn exact_leaf(t: f32) -> u32 {
    let f = lod_per_t * t + lod_fixed;
    var k = 0u;
    if (f >= 2.0) {
        let ratio = EXACT_LOG_RATIO;
        k = min(u32(floor(log2(f))), paged.lod_pages[2].w) / ratio * ratio;
    }
    return k;
}

// Each step of the march: columns and tile maxima come from the level of
// detail of its `t` from here on.
fn exact_lod_at(t: f32) -> u32 {
    page_lod = exact_leaf(t);
    return page_lod;
}

// The level a hit at `t` is shaded at (the camera rays' level there).
fn exact_shade_level(t: f32) -> u32 {
    lod_camera_rays();
    return exact_leaf(t);
}

// Pages keep no cave pyramid: no tile is skipped between floors and slabs.
fn cave_clear(k: u32, tx: i32, ty: i32, z_lo: f32, z_hi: f32) -> bool {
    return false;
}

fn cave_word(k: u32, tx: i32, ty: i32) -> u32 {
    return 0u;
}

fn cave_word_clear(v: u32, z_lo: f32, z_hi: f32) -> bool {
    return false;
}

// Pages keep no texel plane (`EXACT_TEXEL_BLOCKS` is off over them): every
// texel reads as one to decode.
fn texel_block_rows(tx: i32, ty: i32) -> vec4<u32> {
    return vec4<u32>(0xffffffffu);
}

// The top of texel (bx, by) of level `level`.
fn paged_texel_top(level: u32, bx: i32, by: i32) -> f32 {
    let c = decode_column_at(level, bx, by);
    return select(c.low, c.high, c.dual);
}

// Max top of tile (tx, ty) of level k: the coarse level (k = 8); at or below
// the march's level of detail `page_lod`, the top of the coarse texel holding
// the tile; above it, the pyramid of the page of that level holding the tile.
// A missing page reads as its chunk's top.
fn maxmip_get(k: u32, tx: i32, ty: i32) -> f32 {
    let ux = u32(tx) & ((globals.level.x >> k) - 1u);
    let uy = u32(ty) & ((globals.level.y >> k) - 1u);
    let chunk = paged_chunk_of(k, ux, uy);
    if (k >= 8u) {
        return f32(paged_chunk_top(chunk));
    }
    let lod = page_lod;
    if (k <= lod) {
        return paged_texel_top(lod, i32(ux >> (lod - k)), i32(uy >> (lod - k)));
    }
    // The tile's first texel of level `lod`, and its page there.
    let j = k - lod;
    let e = paged_slot(paged_page(lod, ux << j, uy << j));
    if (e == 0u) {
        return f32(paged_chunk_top(chunk));
    }
    let side = 256u >> j;
    let local = (ux & (side - 1u)) + (uy & (side - 1u)) * side;
    let offset = paged.offsets[j >> 2u][j & 3u];
    return f32(paged_byte(paged.grid.y + (e - 1u) * paged.grid.z + offset + local));
}
