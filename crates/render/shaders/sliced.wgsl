// `sliced`: N horizontal quads over the camera's footprint at
// z_k = 256 - k * 256 / N (k = 1..N); a fragment keeps its point only where
// the decoded column is solid at that altitude, else discards it.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"

// count.y: slices N; count.z: the slice nearest the eye's altitude.
@group(1) @binding(0) var<uniform> footprint: Footprint;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) altitude: f32,
}

@vertex
fn vs_sliced(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VertexOut {
    let n = footprint.count.y;
    // Slices nearest the eye's altitude first: near to far for the floors
    // below and the ceilings above, so the depth test rejects early.
    let j = outward(i, footprint.count.z, n);
    let z = SLICE_TOP - f32(j + 1u) * (SLICE_TOP / f32(n));
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
    );
    // The bound's extent in x and y (rows run along x when origin.z is 0).
    var extent = vec2<f32>(f32(footprint.size.y), f32(footprint.size.x));
    if (footprint.origin.z != 0) {
        extent = extent.yx;
    }
    let xy = vec2<f32>(footprint.origin.xy) + corners[v] * extent;
    var out: VertexOut;
    out.world = vec3<f32>(xy, z);
    out.altitude = z;
    out.clip = globals.view_proj * vec4<f32>(out.world, 1.0);
    return out;
}

// The point of the slice seen through this pixel: the pixel's ray meets the
// slice's plane. A quad spans the whole footprint, hundreds of units, so a
// world position interpolated across it is imprecise on some rasterisers
// (SwiftShader's showed sky for a whole horizon view); the plane hit is exact.
// Edge-on (the ray parallel to the slice) keeps the interpolated point.
fn slice_point(in: VertexOut) -> vec3<f32> {
    let d = camera_ray(in.clip.x, in.clip.y);
    let e = globals.eye.xyz;
    if (abs(d.z) < 1e-6 * length(d)) {
        return in.world;
    }
    return e + d * ((in.altitude - e.z) / d.z);
}

@fragment
fn fs_sliced(in: VertexOut) -> @location(0) vec4<f32> {
    let p = slice_point(in);
    if (!is_solid(p)) {
        discard;
    }
    return vec4<f32>(shade(p, p - globals.eye.xyz), 1.0);
}

// `sliced_refine`: the kept fragment's slice point lies up to one slice
// interval past where the ray really enters the solid (at a grazing ray,
// many texels past a wall). The previous slice's point on this ray was
// empty (else it would be nearer and win the depth test), so the entry lies
// in (t_prev, t_k]: walk the texel columns of that segment and intersect each
// column's solid intervals exactly, as the CPU reference does. The surface,
// not the slice plane, then writes depth and colour. Past REFINE_COLUMNS
// columns the slice point is kept.
const REFINE_COLUMNS: u32 = 256u;
const NO_ENTRY: f32 = 1e30;

struct Crossing {
    found: bool,
    t: f32,
    cell: vec2<i32>,
}

// First t in [t0, t1] with a <= oz + t dz <= b, or NO_ENTRY.
fn interval_entry(a: f32, b: f32, oz: f32, dz: f32, t0: f32, t1: f32) -> f32 {
    var lo = -NO_ENTRY;
    var hi = NO_ENTRY;
    if (abs(dz) < 1e-12) {
        if (oz < a || oz > b) {
            return NO_ENTRY;
        }
    } else {
        let ta = (a - oz) / dz;
        let tb = (b - oz) / dz;
        lo = min(ta, tb);
        hi = max(ta, tb);
    }
    let enter = max(lo, t0);
    return select(NO_ENTRY, enter, enter <= min(hi, t1));
}

fn first_crossing(e: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> Crossing {
    var out: Crossing;
    out.found = false;
    out.t = t1;
    let p0 = e + d * t0;
    var cell = vec2<i32>(floor(p0.xy));
    let step = vec2<i32>(select(-1, 1, d.x > 0.0), select(-1, 1, d.y > 0.0));
    let inv = vec2<f32>(
        select(NO_ENTRY, 1.0 / d.x, abs(d.x) > 1e-12),
        select(NO_ENTRY, 1.0 / d.y, abs(d.y) > 1e-12),
    );
    var t = t0;
    for (var i = 0u; i < REFINE_COLUMNS; i = i + 1u) {
        let next = vec2<f32>(cell + max(step, vec2<i32>(0)));
        let tx = select(NO_ENTRY, (next.x - e.x) * inv.x, abs(d.x) > 1e-12);
        let ty = select(NO_ENTRY, (next.y - e.y) * inv.y, abs(d.y) > 1e-12);
        let t_exit = min(min(tx, ty), t1);
        let c = decode_column(cell.x, cell.y);
        var hit = interval_entry(-NO_ENTRY, c.low, e.z, d.z, t, t_exit);
        if (c.dual) {
            hit = min(hit, interval_entry(c.mid, c.high, e.z, d.z, t, t_exit));
        }
        if (hit < NO_ENTRY) {
            out.found = true;
            out.t = hit;
            out.cell = cell;
            return out;
        }
        if (t_exit >= t1) {
            break;
        }
        t = t_exit;
        if (tx <= ty) {
            cell.x = cell.x + step.x;
        } else {
            cell.y = cell.y + step.y;
        }
    }
    return out;
}

struct RefinedOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_sliced_refined(in: VertexOut) -> RefinedOut {
    let p = slice_point(in);
    if (!is_solid(p)) {
        discard;
    }
    let d = camera_ray(in.clip.x, in.clip.y);
    let e = globals.eye.xyz;
    var q = p;
    var cell = vec2<i32>(floor(p.xy));
    if (abs(d.z) > 1e-6 * length(d)) {
        let interval = SLICE_TOP / f32(footprint.count.y);
        // The slice this ray crossed just before: above when looking down.
        let z_prev = in.altitude + select(-interval, interval, d.z < 0.0);
        let t_k = (in.altitude - e.z) / d.z;
        // Not nearer than the near plane (view depth = t * focal).
        let t_near = globals.forward.w / globals.eye.w;
        let t_prev = max((z_prev - e.z) / d.z, t_near);
        if (t_prev < t_k) {
            let x = first_crossing(e, d, t_prev, t_k);
            if (x.found) {
                q = e + d * x.t;
                cell = x.cell;
            }
        }
    }
    let clip = globals.view_proj * vec4<f32>(q, 1.0);
    var out: RefinedOut;
    out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    out.color = vec4<f32>(shade_column(q, cell.x, cell.y, q - e), 1.0);
    return out;
}
