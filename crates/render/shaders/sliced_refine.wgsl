// `sliced:N/refine`, pass 2: one full-screen pass. Pass 1 (`fs_slice_mark` in
// sliced.wgsl) left in `slice_marks` the rank + 1 of the nearest slice whose
// point on this pixel's ray is solid (0: none, the plain slicer's sky). Every
// slice point before it on the ray was empty, but the ray can still have
// entered and left the solid between two of them (a ridge it grazes between
// two planes, a wall it cuts at a grazing angle), so the exact first crossing
// is searched over the whole ray up to that slice point, column by column as
// the CPU reference does. The surface, not the slice plane, writes depth and
// colour; one search per pixel instead of one per kept fragment. Unmarked
// pixels stay sky, except rays the slices cannot sample (below).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"
#include "fullscreen.wgsl"
#include "sliced_walk.wgsl"

// count.y: slices N; count.w: the most columns a slice fragment's gap walk
// takes (`sliced.wgsl::slice_hit`).
@group(1) @binding(0) var<uniform> footprint: Footprint;
// (Binding 2 is the beam's tile starts in `sliced_refine_beam.wgsl`.)
@group(1) @binding(4) var slice_marks: texture_2d<u32>;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;
// Most blocks one search crosses (far 600 crosses at most ~1300 columns).
const REFINE_BLOCKS: u32 = 512u;
// Set in a mark kept by the gap walk's block maxima alone (`sliced.wgsl`).
const MARK_MAYBE: u32 = 0x80000000u;

struct RefinedOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// An unmarked ray is empty only where the slices sampled it without gaps:
// each slice fragment in air walks the ray to its own point
// from the previous slice's crossing (`sliced.wgsl::slice_hit`; the first
// from the near plane), at most count.w columns. A ray whose gap
// between crossings needs more (near the horizon of a level view) may have
// slipped past a thin wall or peak, or crossed no slice at all, so the pass
// searches it whole. A segment whose ends are `dx`, `dy` apart crosses at
// most |dx| + |dy| + 2 columns.
fn gaps_walked(d: vec3<f32>, spacing: f32) -> bool {
    let gap = spacing / abs(d.z);
    return gap * (abs(d.x) + abs(d.y)) + 2.0 <= f32(footprint.count.w);
}

// From the near plane (adapters without compute or fragment storage).
@fragment
fn fs_sliced_refine(@builtin(position) pos: vec4<f32>) -> RefinedOut {
    return refine_pixel(pos, 0.0);
}

// The pixel's search, from `t_start` on (no solid point of its ray lies
// before it: its tile's beam start, or 0).
fn refine_pixel(pos: vec4<f32>, t_start: f32) -> RefinedOut {
    let marked = textureLoad(slice_marks, vec2<i32>(pos.xy), 0).x;
    // A maybe-mark: the slice's gap came down to a block's maximum, not
    // necessarily to the ground.
    let maybe = (marked & MARK_MAYBE) != 0u;
    let mark = marked & ~MARK_MAYBE;
    let n = footprint.count.y;
    let spacing = SLICE_TOP / f32(n);
    let d = camera_ray(pos.x, pos.y);
    let e = globals.eye.xyz;
    // View depth = t * focal.
    let t_near = globals.forward.w / globals.eye.w;
    let t_far = globals.right.w / globals.eye.w;
    // Search up to the slice point (edge-on or unmarked: as far as the view
    // goes).
    var t_k = t_far;
    let edge_on = abs(d.z) <= 1e-6 * length(d);
    if (mark == 0u) {
        if (!edge_on && gaps_walked(d, spacing)) {
            // The slices sampled this ray and found it empty: sky, as the
            // plain slicer leaves it (colour cleared here, depth by pass 1).
            discard;
        }
    } else if (!edge_on) {
        let altitude = SLICE_TOP - f32(mark) * spacing;
        t_k = clamp((altitude - e.z) / d.z, t_near, t_far);
    }
    var t = t_k;
    var cell = vec2<i32>(floor((e + d * t_k).xy));
    // Where the search begins: the start, unless rounding put it at or
    // past a kept slice point (which is solid, so the start is never truly
    // past it; then the search runs from the near plane).
    var t0 = max(t_near, t_start);
    if (mark != 0u && !maybe && t0 >= t_k) {
        t0 = t_near;
    }
    var x: SegmentHit;
    x.hit = false;
    // (`<=`: from the near plane, as before the beam, a zero-length search
    // at a slice point on the near plane still runs.)
    if (t0 <= t_k) {
        x = walk_gap(e, d, t0, t_k, REFINE_BLOCKS, true);
    }
    let t_rest = max(t_k, t_start);
    if (!x.hit && maybe && t_rest <= t_far) {
        // Its depth hid the slices behind: the rest of the ray.
        x = walk_gap(e, d, t_rest, t_far, REFINE_BLOCKS, true);
    }
    if (x.hit) {
        t = x.t;
        cell = x.column;
    } else if (mark == 0u) {
        discard;
    } else if (maybe) {
        // Sky after all: over the slice plane's depth.
        var sky: RefinedOut;
        sky.depth = 1.0;
        sky.color = vec4<f32>(globals.sky.rgb, 1.0);
        return sky;
    }
    let q = e + d * t;
    let clip = globals.view_proj * vec4<f32>(q, 1.0);
    var out: RefinedOut;
    out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    out.color = vec4<f32>(shade_column(q, cell.x, cell.y, q - e), 1.0);
    return out;
}
