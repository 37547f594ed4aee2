// `ray`: the paper's height-field march as one full-screen fragment pass.
#include "ray_frag.wgsl"
#include "fullscreen.wgsl"

@fragment
fn fs_ray(@builtin(position) pos: vec4<f32>) -> FragOut {
    return ray_fragment(pos, -3.0e38);
}
