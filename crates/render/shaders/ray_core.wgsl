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
    // Bounded: n passes (the caller passes at most MAX_MARCH_STEPS).
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

// Most texels the final-interval walk visits. A step of the default march
// (128 samples over at most 600 units) crosses about 6; a longer interval
// (a few steps over a long ray) falls back to bisection where its end sample
// is solid, else the march goes on.
const REFINE_MAX_TEXELS: u32 = 64u;

// The exact first solid point of o + t d in (a, b], a sampled empty: a texel
// walk over the columns the interval crosses with the CPU reference's
// segment test (`column_entry`, shared with `ray-exact`). Where the marched
// ray stopped, this is the surface the reference hits and the column it
// enters, not a point up to a bisection interval inside the solid (whose
// height fed the shadow test and whose column, at a grazing floor hit or a
// wall, could be the next one along the ray). No entry in the walk's texels:
// when b is solid (`solid_b`: too long a walk, or f32 put b's solid point
// across a texel line), bisection between a and b; else a miss (`hit`
// false), and the march goes on from b. Features the samples stepped over
// stay skipped: the step budget is the method's.
fn refine_exact(o: vec3<f32>, d: vec3<f32>, a: f32, b: f32, solid_b: bool) -> MarchHit {
    let e = first_entry(o, d, a, b, REFINE_MAX_TEXELS);
    if (!e.hit) {
        if (solid_b) {
            return bisect(o, d, a, b, BISECTIONS);
        }
        var miss: MarchHit;
        miss.hit = false;
        miss.t = b;
        return miss;
    }
    var r: MarchHit;
    r.hit = true;
    r.t = e.t;
    r.exact = true;
    r.column = e.column;
    return r;
}

// Whether the ray's z over a piece of it, between z0 and z1, meets a solid
// interval of column `c`: the floor [.., low] or the slab [mid, high].
fn z_span_meets_solid(c: Column, z0: f32, z1: f32) -> bool {
    let lo = min(z0, z1);
    let hi = max(z0, z1);
    return lo <= c.low || (c.dual && lo <= c.high && c.mid <= hi);
}

// How far (in t) o + t d runs from a point inside the point's texel,
// backwards to the texel's entry and forwards to its exit, as one multiply-add
// per axis on the point's fraction of a texel: per axis, back = f s + back0
// and forward = fwd0 - f s (3e38 on an axis the ray does not move along).
struct TexelRun {
    s: vec2<f32>,
    back0: vec2<f32>,
    fwd0: vec2<f32>,
}

fn texel_run_of(d: vec2<f32>) -> TexelRun {
    let pos = d > vec2<f32>(0.0);
    let still = d == vec2<f32>(0.0);
    let inv = select(vec2<f32>(1.0) / abs(d), vec2<f32>(0.0), still);
    var r: TexelRun;
    r.s = select(-inv, inv, pos);
    r.back0 = select(select(inv, vec2<f32>(0.0), pos), vec2<f32>(3.0e38), still);
    r.fwd0 = select(select(vec2<f32>(0.0), inv, pos), vec2<f32>(3.0e38), still);
    return r;
}

// x: back to the entry of p's texel, y: on to its exit.
fn texel_run(r: TexelRun, p: vec2<f32>) -> vec2<f32> {
    let fs = (p - floor(p)) * r.s;
    let back = fs + r.back0;
    let fwd = r.fwd0 - fs;
    return vec2<f32>(min(back.x, back.y), min(fwd.x, fwd.y));
}

// The paper's RAYMARCH: `steps` uniform samples over [t0, t1]; then, in place
// of the paper's four bisections, the exact entry inside the first flagged
// step (`refine_exact`). The step test: the paper flags step i (from sample
// i - 1 to sample i) when sample i is solid. With SEGMENT_STEP_TEST (on) it
// also flags the step when the ray's piece of it inside the column under
// sample i, or inside the column under sample i - 1, meets a solid interval
// of that column: the same column decodes as the point test (the previous
// one is kept from the step before), tested over the ray's z span in them,
// so a slab thinner than a step and a wall corner the step clips are found.
// Such a flag is a real entry inside the step, which the walk then finds; if
// the walk finds none (f32 at a texel line, or past its texels) and sample i
// is not solid, the march goes on. Either way a ray takes at most `steps`
// samples, one column decode each, and the columns strictly between two
// samples stay untested: the step budget is the method's. The shared shadow
// map (`shadow.wgsl`) keeps the point test (`march_points`).
// Measured (default world, twelve views, 1280x800, lavapipe = the H100's
// images): ray mean ꟻLIP 0.0561 with the point test, 0.0499 with this one
// (0.0460 with the shadow map on it too, `bench/ray-flip/`). Its price on the
// H100: `ray` 4.0 -> 7.1 ms, `ray-compute`'s march 0.135 -> 0.229 ms; with
// the refinement out of the hot loop and the previous column's test carried
// as one flag, 6.04 and 0.196 ms (`bench/ray-loop/`).
const SEGMENT_STEP_TEST: bool = true;

// Twin of `methods::ray::MAX_RAY_STEPS`.
const MAX_MARCH_STEPS: u32 = 16384u;

// The paper's point test: `steps` samples until one is solid, then the exact
// entry inside the step that ends there. The shared shadow map marches this
// way: the segment test made its pass 75 % dearer on the H100 (0.103 -> 0.180
// ms at 1280x800, every method but `ray-exact` pays it) for 0.0040 of ray's
// mean ꟻLIP.
fn march_points(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32) -> MarchHit {
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
    let s = first_solid_sample(o, d, t0, t1, min(steps, MAX_MARCH_STEPS));
    if (s.x == 0.0) {
        return result;
    }
    return refine_exact(o, d, s.y, s.z, true);
}

// `segment`: the step test above (`ray`, `ray-compute`), else the point test
// (`march_points`: the shadow map).
fn march(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32, segment: bool) -> MarchHit {
    if (!segment) {
        return march_points(o, d, t0, t1, steps);
    }
    return march_from(o, d, t0, t1, steps, t0, MAX_ALTITUDE);
}

// The step test's march (`march` with `segment`) told two things that let it
// take fewer samples and find the same hit (issue 36 item 2):
// - `start`: no point of the ray before it is solid (its 8x8-pixel tile's
//   beam, `march_beam.wgsl`; at or below t0: nothing known). The march then
//   begins at the last sample at or before it, as the march from t0 reaches
//   it: every step before lies in empty space, so none is flagged; the
//   sample there is taken as before and the steps after are the same.
// - `top`: no column is solid above it (the map's highest top;
//   MAX_ALTITUDE: nothing known). A rising ray ends its march at the first
//   step that begins above it (plus a unit for rounding), where every later
//   step is empty too: the same miss.
// Both move only where the march begins and ends on its own sample grid
// (t0 + dt i, dt from the whole segment): the samples it takes are the ones
// the march from t0 takes.
fn march_from(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32, start: f32, top: f32) -> MarchHit {
    var result: MarchHit;
    result.hit = false;
    result.t = t1;
    if (t1 <= t0) {
        return result;
    }
    // A step count from a uniform bounds this loop: never trust it past
    // MAX_MARCH_STEPS (the CPU side refuses more), so a bad read cannot hang the GPU.
    let n = min(steps, MAX_MARCH_STEPS);
    let dt = (t1 - t0) / f32(n);
    var last = n;
    if (d.z > 0.0 && top < MAX_ALTITUDE) {
        let t_top = (top + 1.0 - o.z) / d.z;
        last = min(u32(clamp(floor((t_top - t0) / dt), 0.0, f32(n))) + 1u, n);
    }
    var first_sample = 0u;
    if (start > t0) {
        first_sample = u32(min(floor((start - t0) / dt), f32(n)));
        if (first_sample > 0u && t0 + dt * f32(first_sample) > start) {
            first_sample = first_sample - 1u;
        }
    }
    var a = t0;
    var i = 1u;
    let runs = texel_run_of(d.xy);
    // The step's piece in the previous sample's column (from that sample to
    // the column's exit, or the next sample) is known when that sample is
    // taken: carry its test as one flag, not the column, its z and its exit
    // (fewer live registers in the loop; the same test).
    var leaves_solid = false;
    if (first_sample == 0u) {
        let p0 = o + d * t0;
        let first = decode_column(i32(floor(p0.x)), i32(floor(p0.y)));
        if (column_is_solid(first, p0.z)) {
            result.hit = true;
            result.t = t0;
            return result;
        }
        leaves_solid = z_span_meets_solid(first, p0.z, p0.z + d.z * min(texel_run(runs, p0.xy).y, dt));
    } else {
        // The step into the start's sample is empty: the loop takes that
        // sample as the march from t0 does (its flag false, its carried test).
        i = first_sample;
        a = t0 + dt * f32(first_sample - 1u);
    }
    // The hot loop only finds the next flagged step; its refinement runs
    // outside it (fewer live registers while marching), and a refinement
    // that finds nothing resumes the march at the next step.
    // Bounded: each pass breaks, returns, or moves `i` one sample on;
    // the samples end at `last` (at most MAX_MARCH_STEPS).
    loop {
        var flagged = false;
        var t = t1;
        var solid_end = false;
        // Bounded: `i` rises by one to `last` (at most MAX_MARCH_STEPS).
        for (; i <= last; i = i + 1u) {
            t = t0 + dt * f32(i);
            let p = o + d * t;
            let c = decode_column(i32(floor(p.x)), i32(floor(p.y)));
            let run = texel_run(runs, p.xy);
            // The step's piece in this column: from its entry (or sample
            // i - 1) to p, which holds the point test.
            let z_in = p.z - d.z * min(run.x, dt);
            let flag = leaves_solid || z_span_meets_solid(c, z_in, p.z);
            leaves_solid = z_span_meets_solid(c, p.z, p.z + d.z * min(run.y, dt));
            if (flag) {
                flagged = true;
                solid_end = column_is_solid(c, p.z);
                break;
            }
            a = t;
        }
        if (!flagged) {
            break;
        }
        let r = refine_exact(o, d, a, t, solid_end);
        if (r.hit) {
            return r;
        }
        a = t;
        i = i + 1u;
    }
    return result;
}

// Depth-buffer value of a point at view depth `view_z`: the twin of
// `Camera::view_z_to_depth`, so depth compares across methods.
fn view_z_to_depth(view_z: f32) -> f32 {
    let n = globals.forward.w;
    let f = globals.right.w;
    return f / (f - n) * (1.0 - n / view_z);
}
