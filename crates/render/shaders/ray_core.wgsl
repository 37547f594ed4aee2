// The height-field ray march shared by `ray`, `ray-compute` and the shadow map.
// Needs frame.wgsl and surface.wgsl.
#include "frame.wgsl"
#include "surface.wgsl"

const BISECTIONS: u32 = 4u;

struct MarchHit {
    hit: bool,
    // ray parameter of the first solid point found
    t: f32,
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

// `n` uniform samples over (ta, tb] (ta is known empty) until one is solid,
// then `bisections` halvings between the last empty and the first solid
// sample: the refinement `march` and the voxel leaves share.
fn sample_and_bisect(o: vec3<f32>, d: vec3<f32>, ta: f32, tb: f32, n: u32, bisections: u32) -> MarchHit {
    var result: MarchHit;
    result.hit = false;
    result.t = tb;
    let dt = (tb - ta) / f32(n);
    var a = ta;
    var b = tb;
    for (var i = 1u; i <= n; i = i + 1u) {
        let t = ta + dt * f32(i);
        if (is_solid(o + d * t)) {
            b = t;
            result.hit = true;
            break;
        }
        a = t;
    }
    if (!result.hit) {
        return result;
    }
    for (var i = 0u; i < bisections; i = i + 1u) {
        let c = 0.5 * (a + b);
        if (is_solid(o + d * c)) {
            b = c;
        } else {
            a = c;
        }
    }
    result.t = b;
    return result;
}

// The paper's RAYMARCH: `steps` uniform samples over [t0, t1] until one is
// solid, then four bisections between the last empty and first solid sample.
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
    return sample_and_bisect(o, d, t0, t1, min(steps, MAX_MARCH_STEPS), BISECTIONS);
}

// Depth-buffer value of a point at view depth `view_z`: the twin of
// `Camera::view_z_to_depth`, so depth compares across methods.
fn view_z_to_depth(view_z: f32) -> f32 {
    let n = globals.forward.w;
    let f = globals.right.w;
    return f / (f - n) * (1.0 - n / view_z);
}
