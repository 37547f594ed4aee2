// One pixel of `ray-exact` / `ray-exact-fragment`: the exact march of the
// camera ray, relative to the eye's 256-texel tile, shaded with the shared
// `shade_column` at the column the march found (a wall hit lies exactly on the
// column's side, where `floor(p)` could name the neighbour).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_exact_core.wgsl"

struct ExactPixel {
    color: vec4<f32>,
    depth: f32,
    iterations: u32,
    capped: bool,
}

fn exact_pixel(px: f32, py: f32) -> ExactPixel {
    let eye = globals.eye.xyz;
    let d = camera_ray(px, py);
    let focal = globals.eye.w;
    let seg = exact_clip(eye, d, globals.forward.w / focal, globals.right.w / focal);
    let base = exact_base(eye.xy);
    let o = vec3<f32>(eye.xy - vec2<f32>(base), eye.z);
    let h = exact_march(o, base, d, seg.x, seg.y);
    var out: ExactPixel;
    out.iterations = h.iterations;
    out.capped = h.capped;
    if (!h.hit) {
        out.color = vec4<f32>(globals.sky.rgb, 1.0);
        out.depth = 1.0;
        return out;
    }
    let p = eye + d * h.t;
    out.color = vec4<f32>(shade_column(p, h.column.x, h.column.y, d), 1.0);
    out.depth = view_z_to_depth(h.t * focal);
    return out;
}
