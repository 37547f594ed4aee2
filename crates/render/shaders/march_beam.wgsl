// The tiles' starts `ray` and `voxel` read (issue 36 item 2): one f32 per
// 8x8-pixel tile, the least ray parameter t at which any camera ray of the
// tile may meet a solid point, written each frame by `ray-exact`'s beam
// pre-pass (`cs_exact_beam` in `ray_exact_beam.wgsl`, whose argument shows
// it never passes a hit) over a max-height pyramid the method keeps
// (`methods::march_beam`). Binding 2 of the fragment's group 1.
#include "frame.wgsl"

@group(1) @binding(2) var<storage, read> march_starts: array<f32>;

// Twin of `BEAM_TILE` (`ray_exact_beam.wgsl`).
const MARCH_BEAM_TILE: u32 = 8u;

// The start of the tile holding the pixel whose centre is `pos`.
fn march_tile_start(pos: vec2<f32>) -> f32 {
    let tile = vec2<u32>(pos) / MARCH_BEAM_TILE;
    let across = (u32(globals.screen.x) + MARCH_BEAM_TILE - 1u) / MARCH_BEAM_TILE;
    return march_starts[tile.y * across + tile.x];
}
