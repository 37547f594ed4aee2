// `painted`: one instance per footprint sample; each draws a bar [0, low] and,
// for a dual column, a bar [mid, high], emitting only the (at most three)
// faces that face the eye. Positions come from the instance and vertex
// indices and the column decoded from the terrain texture. The draw is
// indexed (`methods::painted::BAR_INDICES`): a bar's visible faces meet at
// one corner, and the three quads around it have seven corners, each shaded
// once.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"

@group(1) @binding(0) var<uniform> footprint: Footprint;

// Vertices per bar: the corner the visible faces share, then the six around
// it in order (a face is that corner and three consecutive ones).
const BAR_VERTICES: u32 = 7u;

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

// How high column `n`'s solid reaches from `z0` up, within [z0, z1]: the top
// of its interval that holds z0 (z0 when it holds none).
fn cover_top(n: Column, z0: f32, z1: f32) -> f32 {
    if (z0 <= n.low) {
        return min(n.low, z1);
    }
    if (n.dual && n.mid <= z0 && z0 <= n.high) {
        return min(n.high, z1);
    }
    return z0;
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
    let lo = vec3<f32>(f32(cell.x), f32(cell.y), z0);
    let hi = vec3<f32>(lo.x + 1.0, lo.y + 1.0, z1);
    let e = globals.eye.xyz;
    // Per axis, the face that faces the eye: 1 the high one, 0 the low one,
    // -1 neither (the eye is between them). Top when the eye is above,
    // bottom (a cave ceiling) when below.
    let side = vec3<f32>(
        facing_side(e.x, lo.x, hi.x),
        facing_side(e.y, lo.y, hi.y),
        facing_side(e.z, z0, z1),
    );
    // The shared corner sits on each visible face (a hidden face's axis takes
    // the low side). Vertex k flips it on the axes of bits x 1, y 2, z 4: the
    // faces are z (0, 1, 2, 3), x (0, 3, 4, 5) and y (0, 5, 6, 1).
    var flips = array<u32, 7>(0u, 1u, 3u, 2u, 6u, 4u, 5u);
    var flip = flips[k];
    // A hidden face's own corner (2 for z, 4 for x, 6 for y) falls onto the
    // shared one, so both its triangles are degenerate and the faces beside
    // it keep their corners.
    if ((k == 2u && side.z < 0.0) || (k == 4u && side.x < 0.0) || (k == 6u && side.y < 0.0)) {
        flip = 0u;
    }
    let flipped = (vec3<u32>(flip, flip >> 1u, flip >> 2u) & vec3<u32>(1u)) == vec3<u32>(1u);
    let at_hi = (side > vec3<f32>(0.0)) != flipped;
    var p = select(lo, hi, at_hi);
    // A side face's part that touches the neighbour column's solid is inside
    // the terrain: never the first surface along a ray, and most of a tall
    // wall's area. Raise the face's bottom corners over it, so the rasteriser
    // does not cover it only for the depth test to reject it. A corner on
    // two side faces takes the lower of their cuts, so each face still
    // covers all its visible part. Not where the bottom face is drawn.
    if (!at_hi.z && side.z != 0.0) {
        var z = z1;
        var cut = false;
        if ((flip & 1u) == 0u && side.x >= 0.0) {
            let n = decode_column(cell.x + select(-1, 1, side.x > 0.0), cell.y);
            z = min(z, cover_top(n, z0, z1));
            cut = true;
        }
        if ((flip & 2u) == 0u && side.y >= 0.0) {
            let n = decode_column(cell.x, cell.y + select(-1, 1, side.y > 0.0));
            z = min(z, cover_top(n, z0, z1));
            cut = true;
        }
        if (cut) {
            p.z = z;
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
