// One pixel of `ray-exact` / `ray-exact-fragment`: the exact march of the
// camera ray, relative to the eye's 256-texel tile, shaded with the shared
// `shade_column` at the column the march found (a wall hit lies exactly on the
// column's side, where `floor(p)` could name the neighbour). The march and the
// shading are separate functions so the deferred frame
// (`ray_exact_deferred.wgsl`) can run them in two passes with the shadow map
// cast in between, and get the same colour bit for bit.
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

// The march of pixel (px, py): the hit (its `t` along `camera_ray`, column
// absolute) or a miss.
fn exact_pixel_hit(px: f32, py: f32) -> ExactHit {
    return exact_pixel_hit_from(px, py, -EXACT_BIG, EXACT_START_LEVEL);
}

// The march of pixel (px, py) from no earlier than `start` (its tile's beam,
// `ray_exact_beam.wgsl`: no ray of the tile is solid before it), from
// pyramid level `level`.
fn exact_pixel_hit_from(px: f32, py: f32, start: f32, level: u32) -> ExactHit {
    lod_camera_rays();
    let eye = globals.eye.xyz;
    let d = camera_ray(px, py);
    let focal = globals.eye.w;
    let seg = exact_clip(eye, d, globals.forward.w / focal, globals.right.w / focal);
    let base = exact_base(eye.xy);
    let o = vec3<f32>(eye.xy - vec2<f32>(base), eye.z);
    return exact_march_at(o, base, d, max(seg.x, start), seg.y, level);
}

// Colour and depth of pixel (px, py) whose ray hit column `column` at `t`.
fn exact_pixel_shade(px: f32, py: f32, t: f32, column: vec2<i32>) -> ExactPixel {
    let d = camera_ray(px, py);
    let p = globals.eye.xyz + d * t;
    var out: ExactPixel;
    // Paged terrain shades far hits from the coarse copy the march read there.
    let level = exact_shade_level(t);
    let block = column >> vec2<u32>(level);
    out.color = vec4<f32>(shade_column_at(p, level, block.x, block.y, d), 1.0);
    out.depth = view_z_to_depth(t * globals.eye.w);
    return out;
}

// The sky's colour and depth.
fn exact_pixel_sky() -> ExactPixel {
    var out: ExactPixel;
    out.color = vec4<f32>(globals.sky.rgb, 1.0);
    out.depth = 1.0;
    return out;
}

fn exact_pixel(px: f32, py: f32) -> ExactPixel {
    return exact_pixel_from(px, py, -EXACT_BIG, EXACT_START_LEVEL);
}

// `exact_pixel` from no earlier than `start`, from pyramid level `level`
// (`exact_pixel_hit_from`).
fn exact_pixel_from(px: f32, py: f32, start: f32, level: u32) -> ExactPixel {
    let h = exact_pixel_hit_from(px, py, start, level);
    var out = exact_pixel_sky();
    if (h.hit) {
        out = exact_pixel_shade(px, py, h.t, h.column);
    }
    out.iterations = h.iterations;
    out.capped = h.capped;
    return out;
}
