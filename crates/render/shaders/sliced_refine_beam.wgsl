// The refine pass (`sliced_refine.wgsl`) from each 8x8-pixel tile's beam
// start (`march_beam.wgsl`): no ray of the tile meets a solid point before
// it, so the search skips the air the beam search already crossed.
#include "sliced_refine.wgsl"
#include "march_beam.wgsl"

@fragment
fn fs_sliced_refine_beam(@builtin(position) pos: vec4<f32>) -> RefinedOut {
    return refine_pixel(pos, march_tile_start(pos.xy));
}
