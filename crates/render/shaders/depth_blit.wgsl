// Copy an R32Float depth image into the shared depth target (a depth texture
// cannot be a storage texture or a copy destination from a colour texture).
#include "fullscreen.wgsl"

@group(0) @binding(0) var depth_in: texture_2d<f32>;

@fragment
fn fs_depth_blit(@builtin(position) pos: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(depth_in, vec2<i32>(pos.xy), 0).r;
}
