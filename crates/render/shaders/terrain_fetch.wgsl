// Where a texel pair comes from: the whole map in the shared terrain texture
// (`terrain.rs`'s layout). A paged shader (`shaders::compose`, prefix
// `paged:`) swaps this module for `paged_fetch.wgsl`, which reads the same pair
// through the page table.
#include "frame.wgsl"

// The pair texel holding texel (x, y), wrapping in both directions.
fn terrain_pair(x: i32, y: i32) -> vec4<u32> {
    // u32(i32) reinterprets the bits, so masking wraps negatives correctly.
    let px = (u32(x) & (globals.level.x - 1u)) >> 1u;
    let yy = u32(y) & (globals.level.y - 1u);
    let shift = globals.level.z;
    let layer = yy >> shift;
    let row = yy & ((1u << shift) - 1u);
    return textureLoad(terrain, vec2<u32>(px, row), layer, 0);
}

// The pair at texel (x, y) of level of detail `level`: the whole map has
// level 0 only (paged terrain has coarser levels: `paged_fetch.wgsl`).
fn terrain_pair_at(level: u32, x: i32, y: i32) -> vec4<u32> {
    return terrain_pair(x, y);
}

// The level `decode_column` reads at: the whole map has its texels only.
fn fetch_level() -> u32 {
    return 0u;
}
