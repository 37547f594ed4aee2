// The exact segment test of the CPU reference (`raycast.rs::column_hit`) for
// one column, and the texel a point on a texel line belongs to: shared by the
// exact march (`ray_exact_core.wgsl`) and the marched ray's final-interval
// refinement (`ray_core.wgsl::refine_exact`), and a short texel walk with it
// (`first_entry`, the refinement's and the mesh's colour search). No bindings
// of its own.
#include "surface.wgsl"

// The texel holding p + eps d: a point exactly on a texel line belongs to the
// side the ray moves into (twin of `raycast.rs::texel_after`).
fn texel_after(p: vec2<f32>, d: vec2<f32>) -> vec2<i32> {
    let f = floor(p);
    let on_line = (f == p) & (d < vec2<f32>(0.0));
    // vec2<i32>(bool) rather than select: GLSL ES 3.00 (WebGL2) has no mix() on ints.
    return vec2<i32>(f) - vec2<i32>(on_line);
}

// The first t in [t0, t1] at which o + t d is solid in column `c` (x; -1 when
// none) and whether it is in the slab (y = 1): the earlier entry wins, on a
// tie the floor.
fn column_entry(c: Column, oz: f32, dz: f32, t0: f32, t1: f32) -> vec2<f32> {
    var best = -1.0;
    var slab = 0.0;
    // The floor [.., low].
    if (dz < 0.0) {
        let e = max(t0, (c.low - oz) / dz);
        if (e <= t1) {
            best = e;
        }
    } else if (oz + dz * t0 <= c.low) {
        best = t0;
    }
    if (c.dual) {
        var lo = t0;
        var hi = t1;
        if (dz == 0.0) {
            if (oz < c.mid || oz > c.high) {
                lo = 1.0;
                hi = 0.0;
            }
        } else {
            let ta = (c.mid - oz) / dz;
            let tb = (c.high - oz) / dz;
            lo = max(t0, min(ta, tb));
            hi = min(t1, max(ta, tb));
        }
        if (lo <= hi && (best < 0.0 || lo < best)) {
            best = lo;
            slab = 1.0;
        }
    }
    return vec2<f32>(best, slab);
}

struct SegmentHit {
    hit: bool,
    // ray parameter of the first solid point
    t: f32,
    // the column entered, absolute texel coordinates
    column: vec2<i32>,
    // whether `t` enters the slab [mid, high] rather than the floor
    slab: bool,
}

// The first solid point of o + t d for t in [a, b]: a walk over the texels
// the segment crosses, `column_entry` in each, at most `max_texels` of them
// (no hit past that). Runs relative to the texel holding o + a d, so cell
// boundaries stay exact far from the origin.
fn first_entry(o: vec3<f32>, d: vec3<f32>, a: f32, b: f32, max_texels: u32) -> SegmentHit {
    var r: SegmentHit;
    r.hit = false;
    r.t = b;
    let q = o + d * a;
    let base = vec2<i32>(floor(q.xy));
    let lo = vec3<f32>(q.xy - vec2<f32>(base), q.z);
    let span = b - a;
    let pos = d.xy > vec2<f32>(0.0);
    let step = 2 * vec2<i32>(pos) - vec2<i32>(1);
    let far_side = vec2<i32>(pos);
    let still = d.xy == vec2<f32>(0.0);
    let inv = select(vec2<f32>(1.0) / d.xy, vec2<f32>(0.0), still);
    var cell = texel_after(lo.xy, d.xy);
    var s = 0.0;
    for (var i = 0u; i < max_texels; i = i + 1u) {
        let edge = vec2<f32>(cell + far_side);
        let tb = select((edge - lo.xy) * inv, vec2<f32>(3.0e38), still);
        let s_exit = min(tb.x, tb.y);
        let column = base + cell;
        let e = column_entry(decode_column(column.x, column.y), lo.z, d.z, s, min(s_exit, span));
        if (e.x >= 0.0) {
            r.hit = true;
            r.t = a + e.x;
            r.column = column;
            r.slab = e.y != 0.0;
            return r;
        }
        if (s_exit >= span) {
            return r;
        }
        s = s_exit;
        if (tb.x <= tb.y) {
            cell.x = cell.x + step.x;
        }
        if (tb.y <= tb.x) {
            cell.y = cell.y + step.y;
        }
    }
    return r;
}
