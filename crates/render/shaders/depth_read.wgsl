// Depth read-back where depth textures cannot be copied to buffers (GL,
// WebGL2): copy the depth target, texel for texel, into an R32Uint colour
// target as the f32's bits (exact), which can be copied to a buffer. Depth is
// bound as texture_2d<f32>: naga's GLSL backend cannot load a texture_depth_2d.
#include "fullscreen.wgsl"

@group(0) @binding(0) var depth_in: texture_2d<f32>;

@fragment
fn fs_depth_read(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<u32> {
    let d = textureLoad(depth_in, vec2<i32>(pos.xy), 0).r;
    return vec4<u32>(bitcast<u32>(d), 0u, 0u, 0u);
}
