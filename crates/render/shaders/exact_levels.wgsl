// The max-height pyramid the exact march reads (`ray_exact_core.wgsl`): the
// whole map's, built by `ray_exact_build.wgsl` and laid out by `xparams.levels`
// (`strata_maxmip::Layout`). A paged shader swaps this module for
// `paged_levels.wgsl`, whose levels below the 256-texel tile live per page.

@group(1) @binding(1) var<storage, read> maxmip: array<u32>;

// Max top of tile (tx, ty) of level k, wrapping around the map.
fn maxmip_get(k: u32, tx: i32, ty: i32) -> f32 {
    let l = xparams.levels[k];
    let i = l.x + (u32(tx) & l.z) + ((u32(ty) & l.w) << l.y);
    return f32((maxmip[i >> 2u] >> ((i & 3u) << 3u)) & 0xffu);
}

// Whether a segment whose altitudes over tile (tx, ty) of level k lie in
// [z_lo, z_hi] passes between its floors and its slabs: above the highest
// floor top and below the lowest slab bottom of its columns (the cave
// pyramid after the maxima, from byte `xparams.config.w`; 16 bits a tile:
// `strata_maxmip::CavePyramid`), by `CAVE_MARGIN` at least on each side.
// Then nothing in the tile is solid along it, though its maximum (a slab's
// top) is above it.
fn cave_clear(k: u32, tx: i32, ty: i32, z_lo: f32, z_hi: f32) -> bool {
    return cave_word_clear(cave_word(k, tx, ty), z_lo, z_hi);
}

// Tile (tx, ty)'s cave word of level k: its highest floor top in the low
// byte, its lowest slab bottom in the next.
fn cave_word(k: u32, tx: i32, ty: i32) -> u32 {
    let l = xparams.levels[k];
    let i = l.x + (u32(tx) & l.z) + ((u32(ty) & l.w) << l.y);
    return maxmip[(xparams.config.w >> 2u) + (i >> 1u)] >> ((i & 1u) << 4u);
}

// `cave_clear` of a tile whose `cave_word` is `v`.
fn cave_word_clear(v: u32, z_lo: f32, z_hi: f32) -> bool {
    return z_lo > f32(v & 0xffu) + CAVE_MARGIN && z_hi < f32((v >> 8u) & 0xffu) - CAVE_MARGIN;
}

// The texel plane's bytes of the 4x4 texels of level-2 tile (tx, ty)
// (`strata_maxmip::TexelTops`, after the pyramids; laid out by
// `xparams.levels[0]`: x first byte, y log2 words across, z words across -
// 1, w rows - 1): row r's four in word r, texel x = 4 tx + i in byte i. A
// byte is the column's top where it is a single floor, `TEXEL_DECODE`
// where the column must be decoded. Four loads side by side.
fn texel_block_rows(tx: i32, ty: i32) -> vec4<u32> {
    let l = xparams.levels[0];
    let first = (l.x >> 2u) + (u32(tx) & l.z);
    let y = u32(ty) << 2u;
    return vec4<u32>(
        maxmip[first + ((y & l.w) << l.y)],
        maxmip[first + (((y + 1u) & l.w) << l.y)],
        maxmip[first + (((y + 2u) & l.w) << l.y)],
        maxmip[first + (((y + 3u) & l.w) << l.y)],
    );
}

// Hooks for the paged variant, which counts pixels drawn from pages not yet
// resident: the whole map is always resident.
fn page_pixel_begin() {}

fn page_pixel_missed() -> bool {
    return false;
}

// Count the pixel as pending (paged only).
fn page_pixel_end(missed: bool) {}

// Count a shadow texel cast through a missing page (paged only).
fn page_shadow_end(missed: bool) {}

// Level of detail (paged only): the whole map is marched and shaded at its
// texels.
fn lod_camera_rays() {}

fn lod_shadow_rays() {}

// Called at each step of the march at ray parameter `t`: the level of
// detail there.
fn exact_lod_at(t: f32) -> u32 {
    return 0u;
}

// The level a hit at `t` is shaded at.
fn exact_shade_level(t: f32) -> u32 {
    return 0u;
}
