// Depth read-back where depth textures cannot be copied to buffers (GL,
// WebGL2): copy the depth target, texel for texel, into an Rgba8Unorm colour
// target holding the f32's four bytes (exact: each byte k is written as
// k / 255, which the target stores back as k). RGBA8 is the one format every
// GL, WebGL2 included, reads back; an R32Uint target read back as zeros on
// Chromium's WebGL2 (it reads integer targets as RGBA_INTEGER only). Depth is
// bound as texture_2d<f32>: naga's GLSL backend cannot load a texture_depth_2d.
// It is sampled, nearest, at texel centres rather than loaded: WebGL2 counts
// a 32-bit float depth texture without a nearest sampler as incomplete (it
// cannot be filtered), and an incomplete texture reads as zeros.
#include "fullscreen.wgsl"

@group(0) @binding(0) var depth_in: texture_2d<f32>;
@group(0) @binding(1) var nearest: sampler;

@fragment
fn fs_depth_read(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<f32>(textureDimensions(depth_in));
    let d = textureSampleLevel(depth_in, nearest, pos.xy / size, 0.0).r;
    let bits = bitcast<u32>(d);
    // Little-endian: red holds the lowest byte, as the f32 sits in memory.
    let bytes = vec4<u32>(bits, bits >> 8u, bits >> 16u, bits >> 24u) & vec4<u32>(255u);
    return vec4<f32>(bytes) / 255.0;
}
