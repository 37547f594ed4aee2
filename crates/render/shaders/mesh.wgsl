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

@fragment
fn fs_mesh_gbuffer(in: VertexOut) -> @location(0) vec2<u32> {
    return mesh_gbuffer(in.world, in.kind);
}

@fragment
fn fs_mesh(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(mesh_pixel_colour(in.clip.xy, mesh_gbuffer(in.world, in.kind)), 1.0);
}
