// The height-field ray march shared by `ray`, `ray-compute` and the shadow map.
// Needs frame.wgsl and surface.wgsl.
#include "frame.wgsl"
#include "surface.wgsl"
#include "column_segment.wgsl"

const BISECTIONS: u32 = 4u;

struct MarchHit {
    hit: bool,
    // ray parameter of the first solid point found
    t: f32,
    // true when `t` is the exact entry into `column` (the marched ray's
    // final-interval refinement); else `t` lies up to a bisection interval
    // inside the solid and shading takes the column under the point
    exact: bool,
    column: vec2<i32>,
}

// Clip [t0, t1] of o + t d to the altitude slab [0, 255]; nothing is solid
// above 255 and everything is solid at and below 0. Empty when x > y.
fn clip_to_altitudes(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> vec2<f32> {
    if (abs(d.z) < 1e-9) {
        if (o.z > MAX_ALTITUDE) {
            return vec2<f32>(1.0, 0.0);
        }
        return vec2<f32>(t0, t1);
    }
    let ta = (0.0 - o.z) / d.z;
    let tb = (MAX_ALTITUDE - o.z) / d.z;
    return vec2<f32>(max(t0, min(ta, tb)), min(t1, max(ta, tb)));
}

// The first of `n` uniform samples over (ta, tb] (ta is known empty) that is
// solid: x 1 when found, y the last empty and z the first solid parameter.
fn first_solid_sample(o: vec3<f32>, d: vec3<f32>, ta: f32, tb: f32, n: u32) -> vec3<f32> {
    let dt = (tb - ta) / f32(n);
    var a = ta;
    for (var i = 1u; i <= n; i = i + 1u) {
        let t = ta + dt * f32(i);
        if (is_solid(o + d * t)) {
            return vec3<f32>(1.0, a, t);
        }
        a = t;
    }
    return vec3<f32>(0.0, a, tb);
}

// `bisections` halvings of (a, b], a empty and b solid: the hit at b.
fn bisect(o: vec3<f32>, d: vec3<f32>, a0: f32, b0: f32, bisections: u32) -> MarchHit {
    var a = a0;
    var b = b0;
    for (var i = 0u; i < bisections; i = i + 1u) {
        let c = 0.5 * (a + b);
        if (is_solid(o + d * c)) {
            b = c;
        } else {
            a = c;
        }
    }
    var result: MarchHit;
    result.hit = true;
    result.t = b;
    return result;
}

// `n` uniform samples over (ta, tb] (ta is known empty) until one is solid,
// then `bisections` halvings between the last empty and the first solid
// sample: the voxel leaves' refinement.
fn sample_and_bisect(o: vec3<f32>, d: vec3<f32>, ta: f32, tb: f32, n: u32, bisections: u32) -> MarchHit {
    let s = first_solid_sample(o, d, ta, tb, n);
    if (s.x == 0.0) {
        var miss: MarchHit;
        miss.hit = false;
        miss.t = tb;
        return miss;
    }
    return bisect(o, d, s.y, s.z, bisections);
}

// Most texels the final-interval walk visits. A step of the default march
// (128 samples over at most 600 units) crosses about 6; a longer interval
// (a few steps over a long ray) falls back to bisection.
const REFINE_MAX_TEXELS: u32 = 64u;

// The exact first solid point of o + t d in (a, b], a sampled empty and b
// solid: a texel walk over the columns the interval crosses with the CPU
// reference's segment test (`column_entry`, shared with `ray-exact`). Where
// the marched ray stopped, this is the surface the reference hits and the
// column it enters, not a point up to a bisection interval inside the solid
// (whose height fed the shadow test and whose column, at a grazing floor hit
// or a wall, could be the next one along the ray). Features the samples
// stepped over stay skipped: the step budget is the method's.
fn refine_exact(o: vec3<f32>, d: vec3<f32>, a: f32, b: f32) -> MarchHit {
    let e = first_entry(o, d, a, b, REFINE_MAX_TEXELS);
    if (!e.hit) {
        // Too long a walk, or f32 put b's solid point across a texel line.
        return bisect(o, d, a, b, BISECTIONS);
    }
    var r: MarchHit;
    r.hit = true;
    r.t = e.t;
    r.exact = true;
    r.column = e.column;
    return r;
}

// The paper's RAYMARCH: `steps` uniform samples over [t0, t1] until one is
// solid; then, in place of the paper's four bisections, the exact entry
// inside the interval between the last empty and the first solid sample.
// Twin of `methods::ray::MAX_RAY_STEPS`.
const MAX_MARCH_STEPS: u32 = 16384u;

fn march(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32) -> MarchHit {
    var result: MarchHit;
    result.hit = false;
    result.t = t1;
    if (t1 <= t0) {
        return result;
    }
    if (is_solid(o + d * t0)) {
        result.hit = true;
        result.t = t0;
        return result;
    }
    // A step count from a uniform bounds this loop: never trust it past
    // MAX_MARCH_STEPS (the CPU side refuses more), so a bad read cannot hang the GPU.
    let s = first_solid_sample(o, d, t0, t1, min(steps, MAX_MARCH_STEPS));
    if (s.x == 0.0) {
        return result;
    }
    return refine_exact(o, d, s.y, s.z);
}

// Depth-buffer value of a point at view depth `view_z`: the twin of
// `Camera::view_z_to_depth`, so depth compares across methods.
fn view_z_to_depth(view_z: f32) -> f32 {
    let n = globals.forward.w;
    let f = globals.right.w;
    return f / (f - n) * (1.0 - n / view_z);
}
