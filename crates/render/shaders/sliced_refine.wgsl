// `sliced:N/refine`, pass 2: one full-screen pass. Pass 1 (`fs_slice_mark` in
// sliced.wgsl) left in `slice_marks` the rank + 1 of the nearest slice whose
// point on this pixel's ray is solid (0: none, the plain slicer's sky). Every
// slice point before it on the ray was empty, but the ray can still have
// entered and left the solid between two of them (a ridge it grazes between
// two planes, a wall it cuts at a grazing angle), so the exact first crossing
// is searched over the whole ray up to that slice point, column by column as
// the CPU reference does. The surface, not the slice plane, writes depth and
// colour; one search per pixel instead of one per kept fragment. Unmarked
// pixels stay sky, except rays the slices cannot sample (below).
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"
#include "fullscreen.wgsl"

// count.y: slices N; count.w: the most columns a slice fragment's gap walk
// takes (`sliced.wgsl::slice_hit`).
@group(1) @binding(0) var<uniform> footprint: Footprint;
@group(1) @binding(1) var slice_marks: texture_2d<u32>;

// Twin of `methods::slice_tiles::SliceTileParams` (the slice pass's): here
// only `tiles` (x: log2 of the tile side; y, z: the map's tiles across and
// down - 1) is read.
struct SliceTiles {
    grid: vec4<i32>,
    tiles: vec4<u32>,
}

@group(1) @binding(2) var<uniform> slice_tiles: SliceTiles;
// The highest solid top over each tile of the map and a one-texel margin.
@group(1) @binding(3) var tile_max: texture_2d<u32>;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;
// Most texel columns one search walks (far 600 crosses at most ~850): past it
// the slice point is kept.
const REFINE_COLUMNS: u32 = 2048u;
const NO_ENTRY: f32 = 1e30;
// Set in a mark kept by the gap walk's block maxima alone (`sliced.wgsl`).
const MARK_MAYBE: u32 = 0x80000000u;

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

// The first solid point of e + t d over [t0, t1]: a 2D walk over the texel
// columns the segment crosses, each column's solid intervals ([.., low] and
// a slab's [mid, high]) intersected exactly.
fn first_crossing(e: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> Crossing {
    var out: Crossing;
    out.found = false;
    out.t = t1;
    let p0 = e + d * t0;
    var cell = vec2<i32>(floor(p0.xy));
    let step = vec2<i32>(select(-1, 1, d.x > 0.0), select(-1, 1, d.y > 0.0));
    let moves = abs(d.xy) > vec2<f32>(1e-12);
    let inv = select(vec2<f32>(0.0), vec2<f32>(1.0) / d.xy, moves);
    var t = t0;
    for (var i = 0u; i < REFINE_COLUMNS; i = i + 1u) {
        // Each boundary from its own integer coordinate, never accumulated.
        let next = vec2<f32>(cell + max(step, vec2<i32>(0)));
        let tb = select(vec2<f32>(NO_ENTRY), (next - e.xy) * inv, moves);
        let t_exit = min(min(tb.x, tb.y), t1);
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
        if (tb.x <= tb.y) {
            cell.x = cell.x + step.x;
        } else {
            cell.y = cell.y + step.y;
        }
    }
    return out;
}

// Most tiles one search crosses (far 600 crosses at most ~60 of 32 texels).
const REFINE_TILES: u32 = 512u;

// `first_crossing` over [t0, t1], tile by tile of the slice pass's culling
// tiles: a tile whose highest top (margin included) is below the segment's
// lowest point in it holds no crossing and is stepped over whole, so the
// column walk runs only where the ray comes down to the ground.
fn first_crossing_tiled(e: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> Crossing {
    var out: Crossing;
    out.found = false;
    out.t = t1;
    let side = f32(1u << slice_tiles.tiles.x);
    let step = vec2<i32>(select(-1, 1, d.x > 0.0), select(-1, 1, d.y > 0.0));
    let moves = abs(d.xy) > vec2<f32>(1e-12);
    let inv = select(vec2<f32>(0.0), vec2<f32>(1.0) / d.xy, moves);
    var tile = vec2<i32>(floor((e + d * t0).xy / side));
    var t = t0;
    for (var i = 0u; i < REFINE_TILES; i = i + 1u) {
        let next = vec2<f32>(tile + max(step, vec2<i32>(0))) * side;
        let tb = select(vec2<f32>(NO_ENTRY), (next - e.xy) * inv, moves);
        let t_out = max(min(min(tb.x, tb.y), t1), t);
        let z_min = min(e.z + d.z * t, e.z + d.z * t_out);
        let top = textureLoad(tile_max, vec2<u32>(tile) & slice_tiles.tiles.yz, 0).r;
        if (z_min <= f32(top)) {
            let x = first_crossing(e, d, t, t_out);
            if (x.found) {
                return x;
            }
        }
        if (t_out >= t1) {
            break;
        }
        t = t_out;
        if (tb.x <= tb.y) {
            tile.x = tile.x + step.x;
        } else {
            tile.y = tile.y + step.y;
        }
    }
    return out;
}

struct RefinedOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// An unmarked ray is empty only where the slices sampled it without gaps:
// each slice fragment in air walks the ray to its own point
// from the previous slice's crossing (`sliced.wgsl::slice_hit`; the first
// from the near plane), at most count.w columns. A ray whose gap
// between crossings needs more (near the horizon of a level view) may have
// slipped past a thin wall or peak, or crossed no slice at all, so the pass
// searches it whole. A segment whose ends are `dx`, `dy` apart crosses at
// most |dx| + |dy| + 2 columns.
fn gaps_walked(d: vec3<f32>, spacing: f32) -> bool {
    let gap = spacing / abs(d.z);
    return gap * (abs(d.x) + abs(d.y)) + 2.0 <= f32(footprint.count.w);
}

@fragment
fn fs_sliced_refine(@builtin(position) pos: vec4<f32>) -> RefinedOut {
    let marked = textureLoad(slice_marks, vec2<i32>(pos.xy), 0).x;
    // A maybe-mark: the slice's gap came down to a block's maximum, not
    // necessarily to the ground.
    let maybe = (marked & MARK_MAYBE) != 0u;
    let mark = marked & ~MARK_MAYBE;
    let n = footprint.count.y;
    let spacing = SLICE_TOP / f32(n);
    let d = camera_ray(pos.x, pos.y);
    let e = globals.eye.xyz;
    // View depth = t * focal.
    let t_near = globals.forward.w / globals.eye.w;
    let t_far = globals.right.w / globals.eye.w;
    // Search up to the slice point (edge-on or unmarked: as far as the view
    // goes).
    var t_k = t_far;
    let edge_on = abs(d.z) <= 1e-6 * length(d);
    if (mark == 0u) {
        if (!edge_on && gaps_walked(d, spacing)) {
            // The slices sampled this ray and found it empty: sky, as the
            // plain slicer leaves it (colour cleared here, depth by pass 1).
            discard;
        }
    } else if (!edge_on) {
        let altitude = SLICE_TOP - f32(mark) * spacing;
        t_k = clamp((altitude - e.z) / d.z, t_near, t_far);
    }
    var t = t_k;
    var cell = vec2<i32>(floor((e + d * t_k).xy));
    var x = first_crossing_tiled(e, d, t_near, t_k);
    if (!x.found && maybe) {
        // Its depth hid the slices behind: the rest of the ray.
        x = first_crossing_tiled(e, d, t_k, t_far);
    }
    if (x.found) {
        t = x.t;
        cell = x.cell;
    } else if (mark == 0u) {
        discard;
    } else if (maybe) {
        // Sky after all: over the slice plane's depth.
        var sky: RefinedOut;
        sky.depth = 1.0;
        sky.color = vec4<f32>(globals.sky.rgb, 1.0);
        return sky;
    }
    let q = e + d * t;
    let clip = globals.view_proj * vec4<f32>(q, 1.0);
    var out: RefinedOut;
    out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    out.color = vec4<f32>(shade_column(q, cell.x, cell.y, q - e), 1.0);
    return out;
}
