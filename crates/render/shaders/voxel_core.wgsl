// `voxel` / `voxel-compute`: the hierarchical DDA over the occupancy pyramid
// (paper §3.2). An empty cell is skipped to its exit; an occupied cell is
// descended into; an occupied leaf voxel is sampled with the exact
// two-interval test over the texels it crosses (`voxel_leaf`).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_pixel.wgsl"
#include "voxel_occupancy.wgsl"

// An occupied leaf voxel's piece of the ray [ta, tb] (ta known empty) is
// tested exactly: the walk over the texels it crosses with the CPU
// reference's segment test (`first_entry`, as `ray` refines its last step
// and `ray-exact` marches), at most a leaf's width and depth in texels plus
// two. It replaced points 0.5 apart with five bisections at a solid one
// (issue 36 item 2): on the H100 those took about a third of the fragment
// pass (sample spacing 2.0: -20 %, no bisections: -13 %), and they could
// step over a thin wall the walk does not. The hit is the exact entry, named
// by its column, as `ray-exact` shades it.
fn voxel_leaf(o: vec3<f32>, d: vec3<f32>, ta: f32, tb: f32) -> MarchHit {
    var r: MarchHit;
    r.hit = false;
    r.t = tb;
    r.exact = false;
    if (tb <= ta) {
        return r;
    }
    let leaf = voxel_cell_size(0u);
    let e = first_entry(o, d, ta, tb, u32(leaf.x + leaf.y) + 2u);
    if (e.hit) {
        r.hit = true;
        r.t = e.t;
        r.exact = true;
        r.column = e.column;
    }
    return r;
}

// The first solid point of o + t d in [t0, t1] (already clipped to the
// altitude slab), or a miss when none is found within `steps` DDA steps.
fn voxel_march(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32) -> MarchHit {
    return voxel_march_from(o, d, t0, t1, steps, t0);
}

// `voxel_march` told that no point of the ray before `start` is solid (its
// 8x8-pixel tile's beam, `march_beam.wgsl`; at or below t0: nothing known;
// issue 36 item 2). The traversal begins at the entry of the leaf voxel
// that holds the start's point, where the march from t0 samples that leaf
// from (a cell's entry is the exit plane of the cell before it, the same
// float): every leaf it samples, it samples over the same interval, so it
// finds the same hit in fewer steps of its budget.
fn voxel_march_from(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, steps: u32, start: f32) -> MarchHit {
    var result: MarchHit;
    result.hit = false;
    result.t = t1;
    if (t1 <= t0 || start >= t1) {
        return result;
    }
    let top = vparams.config.y - 1u;
    let dir_pos = d > vec3<f32>(0.0);
    let step = select(vec3<i32>(-1), vec3<i32>(1), dir_pos);
    // An axis the ray does not move along never gives the exit.
    let still = abs(d) < vec3<f32>(1e-12);
    let inv = select(1.0 / d, vec3<f32>(3.0e38), still);
    var t = t0;
    if (start > t0) {
        let leaf_size = voxel_cell_size(0u);
        let leaf = floor((o + d * start) / leaf_size);
        let near_face = (leaf + select(vec3<f32>(1.0), vec3<f32>(0.0), dir_pos)) * leaf_size;
        let tn = select((near_face - o) * inv, vec3<f32>(-3.0e38), still);
        t = max(t0, min(start, max(tn.x, max(tn.y, tn.z))));
    }
    if (t == t0 && is_solid(o + d * t0)) {
        result.hit = true;
        result.t = t0;
        return result;
    }
    // A started ray begins at its leaf (near the ground, where the beam
    // leaves it, a descent from the top costs a step a level; the steps
    // after climb as before): 12.3 steps a pixel from there against 17.7
    // from the top (`examples/march_counts.rs`).
    var lod = top;
    if (t > t0) {
        lod = 0u;
    }
    var size = voxel_cell_size(lod);
    var cell = vec3<i32>(floor((o + d * t) / size));
    cell.z = max(cell.z, 0);
    for (var i = 0u; i < steps; i = i + 1u) {
        if (t > t1) {
            break;
        }
        let occupied = voxel_occupied(lod, cell);
        if (occupied && lod > 0u) {
            // Descend into the child that holds the current point.
            lod = lod - 1u;
            size = voxel_cell_size(lod);
            let child = vec3<i32>(floor((o + d * t) / size));
            cell = clamp(child, cell * 2, cell * 2 + vec3<i32>(1));
            continue;
        }
        let far_face = (vec3<f32>(cell) + select(vec3<f32>(0.0), vec3<f32>(1.0), dir_pos)) * size;
        let te = (far_face - o) * inv;
        let t_exit = min(te.x, min(te.y, te.z));
        if (occupied) {
            let h = voxel_leaf(o, d, t, min(t_exit, t1));
            if (h.hit) {
                return h;
            }
        }
        t = max(t, t_exit);
        // Step to the neighbour across the exit face, by integers (no epsilon).
        var axis = 2u;
        if (te.x <= te.y && te.x <= te.z) {
            axis = 0u;
        } else if (te.y <= te.z) {
            axis = 1u;
        }
        var old_c = cell[axis];
        var new_c = old_c + step[axis];
        cell[axis] = new_c;
        // Climb while the step also left the parent: the next parent may be empty.
        // Bounded: `lod` rises by one a pass to `top`.
        while (lod < top && (new_c >> 1u) != (old_c >> 1u)) {
            cell = cell >> vec3<u32>(1u);
            old_c = old_c >> 1u;
            new_c = new_c >> 1u;
            lod = lod + 1u;
        }
        size = voxel_cell_size(lod);
    }
    return result;
}

// March the camera ray of image point (px, py) through the pyramid and shade
// it: the whole of `voxel` and `voxel-compute` per pixel (same output as `ray_pixel`).
fn voxel_pixel(px: f32, py: f32) -> PixelSample {
    let o = globals.eye.xyz;
    let d = camera_ray(px, py);
    let seg = camera_segment(o, d);
    let h = voxel_march(o, d, seg.x, seg.y, vparams.config.x);
    return shade_hit(o, d, h);
}

// `voxel_pixel` whose ray is empty before `start` (`voxel_march_from`).
fn voxel_pixel_from(px: f32, py: f32, start: f32) -> PixelSample {
    let o = globals.eye.xyz;
    let d = camera_ray(px, py);
    let seg = camera_segment(o, d);
    let h = voxel_march_from(o, d, seg.x, seg.y, vparams.config.x, start);
    return shade_hit(o, d, h);
}
