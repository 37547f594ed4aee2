// `mesh` (§3.6): the fitted TIN (crates/mesh). There is no vertex buffer:
// an index names a grid sample of its chunk and which altitude to take,
// `index = kind * positions + y * stride + x` (see strata_mesh::emit), and the
// vertex shader reads that column from the terrain texture. The instance
// index selects the draw's chunk origin in the unwrapped plane (a chunk near
// the map edge is drawn again at its wrapped copies).
//
// Two fragment entries: `fs_mesh_gbuffer` (the deferred frame: two words a
// pixel, coloured later by `mesh_deferred.wgsl`) and `fs_mesh` (the fragment
// path, where the adapter has no compute: the same colour step in place).
#include "frame.wgsl"
#include "surface.wgsl"
#include "mesh_colour.wgsl"

// Per draw: xy the chunk's sample (0, 0) in unwrapped texels.
@group(1) @binding(2) var<storage, read> draws: array<vec4<i32>>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) kind: u32,
}

// Steps of the field taller than this are walls (`wall_shift`).
const WALL_STEP: f32 = 6.0;

// The altitude a sample of vertex kind `kind` takes at column (x, y): the
// floor, or the slab's top where there is one.
fn kind_field(x: i32, y: i32, kind: u32) -> f32 {
    let c = decode_column(x, y);
    return select(c.low, c.high, kind == KIND_TOP);
}

// How far a sample at (x, y) of altitude `z` moves so that a wall between it
// and one neighbour along an axis stands on their texel boundary, as the
// height field's wall does, rather than ramping from centre to centre (whose
// top lies half a texel inside the wall's silhouette: see-through at grazing
// views). Both samples of the wall move to the boundary, the high one and the
// low one alike; a sample with walls on both sides along an axis stays.
fn wall_shift(x: i32, y: i32, kind: u32, z: f32) -> vec2<f32> {
    let lo = vec2<f32>(kind_field(x - 1, y, kind), kind_field(x, y - 1, kind)) - vec2<f32>(z);
    let hi = vec2<f32>(kind_field(x + 1, y, kind), kind_field(x, y + 1, kind)) - vec2<f32>(z);
    let wall_lo = abs(lo) > vec2<f32>(WALL_STEP);
    let wall_hi = abs(hi) > vec2<f32>(WALL_STEP);
    return 0.5 * (vec2<f32>(wall_hi & !wall_lo) - vec2<f32>(wall_lo & !wall_hi));
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
    // the texel boundary where the height field steps; a sample beside a
    // wall on one side only moves half a texel to it (`wall_shift`).
    var shift = vec2<f32>(0.0);
    if ((kind == KIND_FLOOR || kind == KIND_TOP) && mesh.grid.w == 0u) {
        shift = wall_shift(gx, gy, kind, z);
    }
    let p = vec3<f32>(f32(gx) + 0.5 + shift.x, f32(gy) + 0.5 + shift.y, z);
    var out: VertexOut;
    out.clip = globals.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.kind = kind;
    return out;
}

@fragment
fn fs_mesh_gbuffer(in: VertexOut) -> @location(0) vec2<u32> {
    return mesh_gbuffer(in.world, in.kind);
}

@fragment
fn fs_mesh(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(mesh_pixel_colour(in.clip.xy, mesh_gbuffer(in.world, in.kind)), 1.0);
}
