// Embedding (`embed.rs`): copy Strata's frame, colour and depth, into the
// caller's own targets in one full-screen pass. Both inputs are sampled,
// nearest, at texel centres (as `depth_read.wgsl` does, for WebGL2) and bound
// as unfilterable float (depth too: naga's GLSL cannot load a depth texture).
#include "fullscreen.wgsl"

@group(0) @binding(0) var color_in: texture_2d<f32>;
@group(0) @binding(1) var depth_in: texture_2d<f32>;
@group(0) @binding(2) var nearest: sampler;
// sRGB byte k -> linear, at [k / 4][k % 4]: a table, because pow() per pixel
// cost a CPU rasteriser (lavapipe) 40 ms more per 1280x800 frame.
@group(0) @binding(3) var<uniform> srgb_to_linear: array<vec4<f32>, 64>;

struct Composite {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

fn texel(pos: vec4<f32>) -> vec2<f32> {
    return pos.xy / vec2<f32>(textureDimensions(color_in));
}

fn depth_at(pos: vec4<f32>) -> f32 {
    return textureSampleLevel(depth_in, nearest, texel(pos), 0.0).r;
}

// The bytes Strata's Rgba8Unorm target holds, as they are (a UNORM target).
fn color_at(pos: vec4<f32>) -> vec4<f32> {
    return textureSampleLevel(color_in, nearest, texel(pos), 0.0);
}

// Strata's colours are sRGB-encoded: decoded for a target that encodes on
// write (*Srgb, so it stores the same bytes) or holds linear light (float).
fn linear_color_at(pos: vec4<f32>) -> vec4<f32> {
    let c = color_at(pos);
    let k = vec3<u32>(round(c.rgb * 255.0));
    let linear = vec3<f32>(
        srgb_to_linear[k.r >> 2u][k.r & 3u],
        srgb_to_linear[k.g >> 2u][k.g & 3u],
        srgb_to_linear[k.b >> 2u][k.b & 3u],
    );
    return vec4<f32>(linear, c.a);
}

@fragment
fn fs_composite(@builtin(position) pos: vec4<f32>) -> Composite {
    return Composite(color_at(pos), depth_at(pos));
}

@fragment
fn fs_composite_linear(@builtin(position) pos: vec4<f32>) -> Composite {
    return Composite(linear_color_at(pos), depth_at(pos));
}

// The colour alone (`ColorRoute::Pass`: the frame drew its depth straight
// into the caller's depth texture).
@fragment
fn fs_composite_color(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return color_at(pos);
}

@fragment
fn fs_composite_color_linear(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return linear_color_at(pos);
}
