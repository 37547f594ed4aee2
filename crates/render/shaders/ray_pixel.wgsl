// One pixel of `ray` / `ray-compute`: march the camera ray and shade the hit.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"

struct PixelSample {
    color: vec4<f32>,
    depth: f32,
}

// The camera ray o + t d clipped to the near and far planes (view depth is
// t * focal) and to the altitude slab.
fn camera_segment(o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    let focal = globals.eye.w;
    return clip_to_altitudes(o, d, globals.forward.w / focal, globals.right.w / focal);
}

// A camera ray's march result as a pixel: sky at a miss, else the shaded
// hit and its depth (shared by `ray_pixel` and `voxel_pixel`).
fn shade_hit(o: vec3<f32>, d: vec3<f32>, h: MarchHit) -> PixelSample {
    var out: PixelSample;
    if (!h.hit) {
        out.color = vec4<f32>(globals.sky.rgb, 1.0);
        out.depth = 1.0;
        return out;
    }
    let p = o + d * h.t;
    if (h.exact) {
        // On a column's side p lies on the texel line: name the column.
        out.color = vec4<f32>(shade_column(p, h.column.x, h.column.y, d), 1.0);
    } else {
        out.color = vec4<f32>(shade(p, d), 1.0);
    }
    out.depth = view_z_to_depth(h.t * globals.eye.w);
    return out;
}

// March the camera ray of image point (px, py) and shade it.
fn ray_pixel(px: f32, py: f32, steps: u32) -> PixelSample {
    let o = globals.eye.xyz;
    let d = camera_ray(px, py);
    let seg = camera_segment(o, d);
    return shade_hit(o, d, march(o, d, seg.x, seg.y, steps, SEGMENT_STEP_TEST));
}

// `ray_pixel` told where its ray may first be solid (`start`, its tile's
// beam) and the map's highest top (`top`): the same samples, fewer of them
// (`march_from`).
fn ray_pixel_from(px: f32, py: f32, steps: u32, start: f32, top: f32) -> PixelSample {
    let o = globals.eye.xyz;
    let d = camera_ray(px, py);
    let seg = camera_segment(o, d);
    return shade_hit(o, d, march_from(o, d, seg.x, seg.y, steps, start, top));
}
