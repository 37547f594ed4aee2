// `ray` with its tiles' beam (`march_beam.wgsl`): each ray marches from the
// last sample before its tile's start (issue 36 item 2).
#include "ray_frag.wgsl"
#include "march_beam.wgsl"
#include "fullscreen.wgsl"

@fragment
fn fs_ray_beam(@builtin(position) pos: vec4<f32>) -> FragOut {
    return ray_fragment(pos, march_tile_start(pos.xy));
}
