// `painted`: one instance per footprint sample; each draws a bar [0, low] and,
// for a dual column, a bar [mid, high], emitting only the (at most three)
// faces that face the eye. Positions come from the instance and vertex
// indices and the column decoded from the terrain texture. The draw is
// indexed (`methods::painted::BAR_INDICES`): a face's four corners are
// shaded once and its two triangles share them.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"

@group(1) @binding(0) var<uniform> footprint: Footprint;

// Vertices per bar: three faces of four corners.
const BAR_VERTICES: u32 = 12u;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) cell: vec2<i32>,
}

// The plane of the face of [lo, hi] on one axis that faces the eye at `e`,
// or -1 when the eye is between them (neither face can be seen).
fn facing_side(e: f32, lo: f32, hi: f32) -> f32 {
    if (e > hi) {
        return 1.0;
    }
    if (e < lo) {
        return 0.0;
    }
    return -1.0;
}

@vertex
fn vs_painted(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VertexOut {
    var out: VertexOut;
    // A degenerate triangle (all three vertices equal) rasterises nothing.
    out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    out.world = vec3<f32>(0.0);
    out.cell = vec2<i32>(0);
    let cell = footprint_cell(footprint, i);
    out.cell = cell;
    let c = decode_column(cell.x, cell.y);
    let bar = v / BAR_VERTICES;
    let k = v % BAR_VERTICES;
    var z0 = 0.0;
    var z1 = c.low;
    if (bar == 1u) {
        if (!c.dual) {
            return out;
        }
        z0 = c.mid;
        z1 = c.high;
    }
    // Corner k % 4 of face k / 4 at (s, t) = (bit 0, bit 1).
    let corner = k % 4u;
    let st = vec2<f32>(f32(corner & 1u), f32(corner >> 1u));
    let lo = vec3<f32>(f32(cell.x), f32(cell.y), z0);
    let hi = vec3<f32>(lo.x + 1.0, lo.y + 1.0, z1);
    let e = globals.eye.xyz;
    var p: vec3<f32>;
    switch (k / 4u) {
        case 0u: {
            // Top when the eye is above, bottom (a cave ceiling) when below.
            let side = facing_side(e.z, z0, z1);
            if (side < 0.0) {
                return out;
            }
            p = vec3<f32>(lo.xy + st, mix(z0, z1, side));
        }
        case 1u: {
            let side = facing_side(e.x, lo.x, hi.x);
            if (side < 0.0) {
                return out;
            }
            p = vec3<f32>(lo.x + side, lo.y + st.x, mix(z0, z1, st.y));
        }
        default: {
            let side = facing_side(e.y, lo.y, hi.y);
            if (side < 0.0) {
                return out;
            }
            p = vec3<f32>(lo.x + st.x, lo.y + side, mix(z0, z1, st.y));
        }
    }
    out.clip = globals.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    return out;
}

@fragment
fn fs_painted(in: VertexOut) -> @location(0) vec4<f32> {
    // A side face lies on the border of its column: pull the point inside so
    // the shading decodes this column, not the neighbour.
    let cell = vec2<f32>(in.cell);
    var p = in.world;
    p = vec3<f32>(clamp(p.xy, cell + 0.001, cell + 0.999), p.z);
    return vec4<f32>(shade(p, p - globals.eye.xyz), 1.0);
}
