// `scattered` resolve: one full-screen pass that turns the packed screen
// buffer ((24-bit depth << 8) | (surface kind << 3) | terrain type) back into
// a world position along the pixel's ray and shades it with the shared
// shading; sky where the buffer is still cleared.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "fullscreen.wgsl"

@group(1) @binding(0) var<storage, read> screen_buf: array<u32>;

struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// `shade`, but the kind and terrain type come from the sample that won the
// pixel (the pixel-centre ray may reconstruct a point in a neighbour column).
fn shade_sample(p: vec3<f32>, dir: vec3<f32>, info: u32) -> vec3<f32> {
    let x = i32(floor(p.x));
    let y = i32(floor(p.y));
    var c = decode_column(x, y);
    var kind = (info >> 3u) & 3u;
    if (kind > SURFACE_CEILING || (kind != SURFACE_FLOOR && !c.dual)) {
        kind = surface_kind(c, p.z, dir.z);
    }
    c.lower_type = info & 7u;
    c.upper_type = info & 7u;
    let here = select(c.high, c.mid, kind == SURFACE_CEILING);
    let n = surface_normal(x, y, kind, here);
    return shade_with_normal(p, c, kind, n);
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> FragOut {
    let ij = vec2<u32>(pos.xy);
    let packed = screen_buf[ij.y * u32(globals.screen.x) + ij.x];
    var out: FragOut;
    if (packed == 0xFFFFFFFFu) {
        out.color = vec4<f32>(globals.sky.rgb, 1.0);
        out.depth = 1.0;
        return out;
    }
    let depth = f32(packed >> 8u) / 16777215.0;
    let near = globals.forward.w;
    let far = globals.right.w;
    let view_z = near * far / (far - depth * (far - near));
    let d = camera_ray(pos.x, pos.y);
    let p = globals.eye.xyz + d * (view_z / globals.eye.w);
    out.color = vec4<f32>(shade_sample(p, d, packed & 0xFFu), 1.0);
    out.depth = depth;
    return out;
}
