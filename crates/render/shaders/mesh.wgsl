// `mesh` (§3.6): the fitted TIN (crates/mesh). There is no vertex buffer:
// an index names a grid sample of its chunk and which altitude to take,
// `index = kind * positions + y * stride + x` (see strata_mesh::emit), and the
// vertex shader reads that column from the terrain texture. The instance
// index selects the draw's chunk origin in the unwrapped plane (a chunk near
// the map edge is drawn again at its wrapped copies).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"

struct MeshParams {
    // x stride (chunk side + 1), y positions per kind ((side_x + 1) * (side_y + 1)),
    // z 1: the gradient-normal diagnostic (`mesh_gradient_normal`)
    grid: vec4<u32>,
}

@group(1) @binding(0) var<uniform> mesh: MeshParams;
// Per draw: xy the chunk's sample (0, 0) in unwrapped texels.
@group(1) @binding(1) var<storage, read> draws: array<vec4<i32>>;

const KIND_FLOOR: u32 = 0u;
const KIND_TOP: u32 = 1u;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) kind: u32,
}

@vertex
fn vs_mesh(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VertexOut {
    let kind = v / mesh.grid.y;
    let pos = v % mesh.grid.y;
    let origin = draws[i].xy;
    let gx = origin.x + i32(pos % mesh.grid.x);
    let gy = origin.y + i32(pos / mesh.grid.x);
    let c = decode_column(gx, gy);
    var z = c.low;
    if (kind == KIND_TOP) {
        z = c.high;
    } else if (kind != KIND_FLOOR) {
        z = c.mid;
    }
    // Samples stand at texel centres, so a ramp between two samples crosses
    // the texel boundary where the height field steps.
    let p = vec3<f32>(f32(gx) + 0.5, f32(gy) + 0.5, z);
    var out: VertexOut;
    out.clip = globals.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.kind = kind;
    return out;
}

// Where the eye's ray through `p` meets the height field's own surface (the
// interval of `kind`), near `p`: the TIN lies up to its fit error above or
// below that surface, and off-axis rays (every pixel away from the image
// centre) then reach it several texels away from where the true ray hits,
// taking those texels' terrain type. Two fixed-point steps along the ray to
// the column's altitude, the shift capped at 4 texels; the mesh's geometry,
// depth and flat normal are unchanged.
const PARALLAX_STEPS: u32 = 2u;
const PARALLAX_MAX: f32 = 4.0;

fn surface_along_ray(p: vec3<f32>, kind: u32) -> vec2<f32> {
    let d = normalize(p - globals.eye.xyz);
    if (abs(d.z) < 0.2) {
        // Grazing rays: a height error moves the hit far; keep the mesh's.
        return p.xy;
    }
    var q = p.xy;
    for (var i = 0u; i < PARALLAX_STEPS; i = i + 1u) {
        let c = decode_column(i32(floor(q.x)), i32(floor(q.y)));
        var z = c.low;
        if (kind != KIND_FLOOR && c.dual) {
            z = select(c.mid, c.high, kind == KIND_TOP);
        }
        let t = clamp((z - p.z) / d.z, -PARALLAX_MAX, PARALLAX_MAX);
        q = p.xy + d.xy * t;
    }
    return q;
}

@fragment
fn fs_mesh(in: VertexOut) -> @location(0) vec4<f32> {
    let p = in.world;
    // The triangle's flat geometric normal: world position is linear over
    // the triangle, so its screen derivatives span the triangle's plane.
    var n = normalize(cross(dpdx(p), dpdy(p)));
    let to_eye = globals.eye.xyz - p;
    if (dot(n, to_eye) < 0.0) {
        // Whichever side is seen is the outside of the solid.
        n = -n;
    }
    // A wall is a steep ramp between two texel centres, half over the low
    // column; its colour and light belong to the high one, which lies inside
    // the solid, against the outward normal. Half a texel inwards maps an
    // axis-aligned ramp's span [i + 0.5, i + 1.5] onto column i + 1 (what a
    // ray entering the wall meets). Gentler faces keep their own column.
    var at = p.xy;
    let across = length(n.xy);
    if (across > 0.7) {
        at -= n.xy / across * 0.5;
    } else {
        at = surface_along_ray(p, in.kind);
    }
    let column = vec2<i32>(floor(at));
    let c = decode_column(column.x, column.y);
    var kind = SURFACE_FLOOR;
    if (in.kind != KIND_FLOOR) {
        // Slab triangles: tops and walls take the slab top's light, faces
        // looking down are the cave ceiling.
        kind = select(SURFACE_SLAB_TOP, SURFACE_CEILING, n.z < -0.5);
    }
    if (mesh.grid.z != 0u) {
        // Diagnostic: the height-field normal the other methods shade with.
        let here = select(c.high, c.mid, kind == SURFACE_CEILING);
        n = surface_normal(column.x, column.y, kind, here);
    }
    return vec4<f32>(shade_with_normal(p, c, kind, n), 1.0);
}
