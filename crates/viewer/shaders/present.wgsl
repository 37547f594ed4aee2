// The viewer's last two passes. `fs_compose` puts the rendered picture (or
// two, side by side for A/B) into the window image, scaled to fit with bars;
// `fs_present` copies the window image (picture + overlay) to the swapchain.

struct Params {
    // Where the picture lies in the output, pixels: x, y, width, height.
    viewport: vec4<f32>,
    // x: the A/B split as a fraction of the picture's width (>= 1: none);
    // y: 1 when the output encodes to sRGB itself (decode ours first).
    options: vec4<f32>,
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var left_image: texture_2d<f32>;
@group(0) @binding(2) var right_image: texture_2d<f32>;
@group(0) @binding(3) var image_sampler: sampler;

const BARS: vec3<f32> = vec3<f32>(0.08, 0.08, 0.09);
const DIVIDER: vec3<f32> = vec3<f32>(1.0, 0.85, 0.2);

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the screen.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_compose(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = (pos.xy - params.viewport.xy) / params.viewport.zw;
    if any(p < vec2<f32>(0.0)) || any(p > vec2<f32>(1.0)) {
        return vec4<f32>(BARS, 1.0);
    }
    let split = params.options.x;
    if split < 1.0 && abs(p.x - split) * params.viewport.z < 1.0 {
        return vec4<f32>(DIVIDER, 1.0);
    }
    var colour: vec4<f32>;
    if p.x < split {
        colour = textureSampleLevel(left_image, image_sampler, p, 0.0);
    } else {
        colour = textureSampleLevel(right_image, image_sampler, p, 0.0);
    }
    return vec4<f32>(colour.rgb, 1.0);
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

@fragment
fn fs_present(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(left_image, vec2<i32>(pos.xy), 0).rgb;
    if params.options.y > 0.5 {
        return vec4<f32>(srgb_to_linear(c), 1.0);
    }
    return vec4<f32>(c, 1.0);
}
