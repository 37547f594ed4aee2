// The paged mesh's stand-in for a chunk copy it cannot draw yet (its fit is
// not in the index pool, or a page it reads is not resident): the chunk's box
// from z = 0 up to the highest top of the pages holding its samples, which
// holds the chunk's surface, so nothing behind it shows through. Every
// fragment counts as pending (`page_feedback[0]`, as in `paged.wgsl`).
#include "frame.wgsl"

// Per draw: xy the chunk's sample (0, 0) in unwrapped texels, z the box's
// top, w the chunk's side.
@group(1) @binding(2) var<storage, read> draws: array<vec4<i32>>;
@group(1) @binding(10) var<storage, read_write> page_feedback: array<atomic<u32>>;

struct BoxOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) face: u32,
}

// Six faces (the top, the four sides, the bottom at z = 0 for an eye inside
// the box: it is above the terrain but may be below the box's top), two
// triangles each.
@vertex
fn vs_mesh_box(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> BoxOut {
    let face = v / 6u;
    let corner = v % 6u;
    // The quad's corners: (0,0) (1,0) (1,1), (0,0) (1,1) (0,1).
    let u = f32(corner == 1u || corner == 2u || corner == 4u);
    let w = f32(corner == 2u || corner == 4u || corner == 5u);
    var q = vec3<f32>(u, w, 1.0);
    switch face {
        case 1u: { q = vec3<f32>(u, 0.0, w); }
        case 2u: { q = vec3<f32>(u, 1.0, w); }
        case 3u: { q = vec3<f32>(0.0, u, w); }
        case 4u: { q = vec3<f32>(1.0, u, w); }
        case 5u: { q = vec3<f32>(u, w, 0.0); }
        default: {}
    }
    let d = draws[i];
    let side = f32(d.w);
    let p = vec3<f32>(f32(d.x) + 0.5 + q.x * side, f32(d.y) + 0.5 + q.y * side, q.z * f32(d.z));
    var out: BoxOut;
    out.clip = globals.view_proj * vec4<f32>(p, 1.0);
    out.face = face;
    return out;
}

@fragment
fn fs_mesh_box(in: BoxOut) -> @location(0) vec4<f32> {
    atomicAdd(&page_feedback[0], 1u);
    let light = select(0.75, 1.0, in.face == 0u);
    return vec4<f32>(vec3<f32>(0.42, 0.40, 0.36) * light, 1.0);
}
