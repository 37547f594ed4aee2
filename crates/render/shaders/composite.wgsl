// Embedding (`embed.rs`): copy Strata's frame, colour and depth, into the
// caller's own targets in one full-screen pass. Both inputs are sampled,
// nearest, at texel centres (as `depth_read.wgsl` does, for WebGL2) and bound
// as unfilterable float (depth too: naga's GLSL cannot load a depth texture).
#include "fullscreen.wgsl"

@group(0) @binding(0) var color_in: texture_2d<f32>;
@group(0) @binding(1) var depth_in: texture_2d<f32>;
@group(0) @binding(2) var nearest: sampler;

struct Composite {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

fn texel(pos: vec4<f32>) -> vec2<f32> {
    return pos.xy / vec2<f32>(textureDimensions(color_in));
}

// The bytes Strata's Rgba8Unorm target holds, as they are (a UNORM target).
@fragment
fn fs_composite(@builtin(position) pos: vec4<f32>) -> Composite {
    let uv = texel(pos);
    let c = textureSampleLevel(color_in, nearest, uv, 0.0);
    return Composite(c, textureSampleLevel(depth_in, nearest, uv, 0.0).r);
}

// Strata's colours are sRGB-encoded: decode them for a target that encodes
// on write (*Srgb, so it stores the same bytes) or holds linear light (float).
@fragment
fn fs_composite_linear(@builtin(position) pos: vec4<f32>) -> Composite {
    let uv = texel(pos);
    let c = textureSampleLevel(color_in, nearest, uv, 0.0);
    let lo = c.rgb / 12.92;
    let hi = pow((c.rgb + 0.055) / 1.055, vec3<f32>(2.4));
    let linear = select(hi, lo, c.rgb <= vec3<f32>(0.04045));
    return Composite(vec4<f32>(linear, c.a), textureSampleLevel(depth_in, nearest, uv, 0.0).r);
}
