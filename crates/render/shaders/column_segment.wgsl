// The exact segment test of the CPU reference (`raycast.rs::column_hit`) for
// one column, and the texel a point on a texel line belongs to: shared by the
// exact march (`ray_exact_core.wgsl`) and the marched ray's final-interval
// refinement (`ray_core.wgsl::refine_exact`). No bindings of its own.
#include "surface.wgsl"

// The texel holding p + eps d: a point exactly on a texel line belongs to the
// side the ray moves into (twin of `raycast.rs::texel_after`).
fn texel_after(p: vec2<f32>, d: vec2<f32>) -> vec2<i32> {
    let f = floor(p);
    let on_line = (f == p) & (d < vec2<f32>(0.0));
    return vec2<i32>(f) - select(vec2<i32>(0), vec2<i32>(1), on_line);
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
