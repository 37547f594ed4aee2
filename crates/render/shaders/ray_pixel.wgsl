// One pixel of `ray` / `ray-compute`: march the camera ray and shade the hit.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"

struct PixelSample {
    color: vec4<f32>,
    depth: f32,
}

// March the camera ray of image point (px, py) and shade it.
fn ray_pixel(px: f32, py: f32, steps: u32) -> PixelSample {
    let o = globals.eye.xyz;
    let d = camera_ray(px, py);
    let focal = globals.eye.w;
    // View depth is t * focal: the segment runs from the near to the far plane.
    let seg = clip_to_altitudes(o, d, globals.forward.w / focal, globals.right.w / focal);
    let h = march(o, d, seg.x, seg.y, steps);
    var out: PixelSample;
    if (!h.hit) {
        out.color = vec4<f32>(globals.sky.rgb, 1.0);
        out.depth = 1.0;
        return out;
    }
    let p = o + d * h.t;
    out.color = vec4<f32>(shade(p, d), 1.0);
    out.depth = view_z_to_depth(h.t * focal);
    return out;
}
