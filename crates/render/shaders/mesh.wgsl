// `mesh` (§3.6): the fitted TIN (crates/mesh). There is no vertex buffer:
// an index names a grid sample of its chunk and which altitude to take,
// `index = kind * positions + y * stride + x` (see strata_mesh::emit), and the
// vertex shader reads that column from the terrain texture. The instance
// index selects the draw's chunk origin in the unwrapped plane (a chunk near
// the map edge is drawn again at its wrapped copies).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "column_segment.wgsl"

struct MeshParams {
    // x stride (chunk side + 1), y positions per kind ((side_x + 1) * (side_y + 1)),
    // z 1: the gradient-normal diagnostic (`mesh_gradient_normal`)
    grid: vec4<u32>,
}

@group(1) @binding(0) var<uniform> mesh: MeshParams;
// Per draw: xy the chunk's sample (0, 0) in unwrapped texels.
@group(1) @binding(2) var<storage, read> draws: array<vec4<i32>>;

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

// Where the eye's ray through `p` meets the height field's own surface near
// `p`: the TIN lies up to its fit error above or below that surface, so the
// point under `p` is not what the reference sees there (off-axis, the true
// hit is texels away), and between samples a wall's ramp lies half over the
// low column, up to the wall's height above its floor (from above, that
// floor is what shows). The exact segment test (`first_entry`, shared with
// ray and ray-exact) walks the ray from a few texels before `p` to several
// past it; the first entry names the column and interval the pixel takes its
// colour from. The walk costs one decode per texel crossed, so the window is
// set in texels across (a near-vertical ray may run far: down a wall) and
// capped along the ray. The mesh's geometry, depth and flat normal are
// unchanged; a miss keeps the column under the TIN.
const SURFACE_BACK_TEXELS: f32 = 3.0;
const SURFACE_AHEAD_TEXELS: f32 = 8.0;
const SURFACE_MAX_ALONG: f32 = 64.0;
const SURFACE_MAX_TEXELS: u32 = 16u;

struct ColourSource {
    column: vec2<i32>,
    kind: u32,
}

// The column and interval the pixel at TIN point `p` (flat normal `n`, of a
// triangle of vertex kind `vkind`) is coloured from.
fn colour_source(p: vec3<f32>, n: vec3<f32>, vkind: u32) -> ColourSource {
    let eye = globals.eye.xyz;
    let dist = length(p - eye);
    let d = (p - eye) / dist;
    let across = max(length(d.xy), 1e-4);
    let back = min(SURFACE_BACK_TEXELS / across, SURFACE_MAX_ALONG);
    let ahead = min(SURFACE_AHEAD_TEXELS / across, SURFACE_MAX_ALONG);
    let a = max(dist - back, 0.0);
    let h = first_entry(eye, d, a, dist + ahead, SURFACE_MAX_TEXELS);
    var src: ColourSource;
    if (h.hit && h.t > a) {
        src.column = h.column;
        let c = decode_column(h.column.x, h.column.y);
        src.kind = surface_kind(c, eye.z + d.z * h.t, d.z);
        return src;
    }
    // No surface entered in the window (the TIN bridges a gap, or the window
    // starts inside the solid): the column under the TIN point, walls half a
    // texel inwards (a steep ramp between two texel centres lies half over
    // the low column; its colour belongs to the high one, inside the solid).
    var at = p.xy;
    let steep = length(n.xy);
    if (steep > 0.7) {
        at -= n.xy / steep * 0.5;
    }
    src.column = vec2<i32>(floor(at));
    src.kind = SURFACE_FLOOR;
    if (vkind != KIND_FLOOR) {
        // Slab triangles: tops and walls take the slab top's light, faces
        // looking down are the cave ceiling.
        src.kind = select(SURFACE_SLAB_TOP, SURFACE_CEILING, n.z < -0.5);
    }
    return src;
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
    let src = colour_source(p, n, in.kind);
    let c = decode_column(src.column.x, src.column.y);
    if (mesh.grid.z != 0u) {
        // Diagnostic: the height-field normal the other methods shade with.
        let here = select(c.high, c.mid, src.kind == SURFACE_CEILING);
        n = surface_normal(src.column.x, src.column.y, src.kind, here);
    }
    return vec4<f32>(shade_with_normal(p, c, src.kind, n), 1.0);
}
