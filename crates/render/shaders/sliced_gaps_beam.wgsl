// The gap pass (`sliced_gaps.wgsl`) from each 8x8-pixel tile's beam start
// (`march_beam.wgsl`): no ray of the tile meets a solid point before it,
// so the walk skips the air the beam search already crossed.
#include "sliced_gaps.wgsl"
#include "march_beam.wgsl"

@fragment
fn fs_sliced_gaps_beam(@builtin(position) pos: vec4<f32>) -> GapOut {
    return walk_pixel(pos, march_tile_start(pos.xy));
}
