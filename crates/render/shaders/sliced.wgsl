// `sliced`: N horizontal quads over the camera's footprint at
// z_k = 256 - k * 256 / N (k = 1..N); a fragment keeps its point only where
// the decoded column is solid at that altitude, else discards it.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"
#include "sliced_walk.wgsl"

// count.y: slices N; count.z: the slice nearest the eye's altitude; count.w:
// the most columns a gap walk takes (at most a tile's side).
@group(1) @binding(0) var<uniform> footprint: Footprint;

// The highest solid top over each tile of the map and a one-texel margin.
@group(1) @binding(2) var tile_max: texture_2d<u32>;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;
// Where a pixel's ray crosses the slices more than GAP_MIN texels apart
// (grazing rays: the gap is spacing / slope), a thin wall or a peak can sit
// between two crossings, and the plain point test sees through it. Plain
// `sliced` walks such rays once per pixel after the slices
// (`sliced_gaps.wgsl`); with `/fragwalk` and in the refined slicer's marks a
// fragment whose point is air walks the ray from the previous slice's
// crossing (the first slice: from the near plane) to its own point (the
// last before the far plane: on to the far plane), the last
// footprint.count.w columns of it at most (`walk_gap`; Rust:
// `sliced::GAP_TEXELS`),
// and keeps the first solid point it meets: the slices then cover the ray
// without gaps down to slopes of about spacing / count.w. Steeper rays never
// walk. Rust twin: `sliced::rows::GAP_MIN`.
const GAP_MIN: f32 = 2.0;
// The walk from the near plane to the first slice a ray meets: one per
// pixel, so it may be long (near the horizon the first crossing is hundreds
// of texels out; the far plane 600 is under 900 columns away).
const FIRST_GAP_TEXELS: u32 = 1024u;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) altitude: f32,
    // j: the slice at altitude SLICE_TOP - (j + 1) * SLICE_TOP / N
    @location(2) @interpolate(flat) rank: u32,
}

// Instance i: slice rank i / tiles, tile i % tiles of the footprint's grid;
// the quad is the tile cut to the footprint bound, or nothing where the
// tile's highest top is below the slice (all of it air there).
@vertex
fn vs_sliced(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VertexOut {
    let n = footprint.count.y;
    let g = slice_tiles.grid;
    let per_slice = u32(max(g.z, 1) * max(g.w, 1));
    // Slices nearest the eye's altitude first: near to far for the floors
    // below and the ceilings above, so the depth test rejects early.
    let j = outward(i / per_slice, footprint.count.z, n);
    let z = SLICE_TOP - f32(j + 1u) * (SLICE_TOP / f32(n));
    // The bound's extent in x and y (rows run along x when origin.z is 0).
    var extent = vec2<i32>(i32(footprint.size.y), i32(footprint.size.x));
    if (footprint.origin.z != 0) {
        extent = extent.yx;
    }
    var lo = footprint.origin.xy;
    var hi = lo + extent;
    var out: VertexOut;
    if (g.z > 0) {
        let t = i % per_slice;
        let tile = g.xy + vec2<i32>(i32(t % u32(g.z)), i32(t / u32(g.z)));
        let k = slice_tiles.tiles.x;
        let wrapped = vec2<u32>(tile) & slice_tiles.tiles.yz;
        // The slices within a spacing of the eye's altitude are the first
        // that rays meet, whose gap walks start at the eye: never culled.
        // (The others are culled by their own tile, though a fragment's walk
        // may reach into the next tile: culling by the tiles around, less a
        // spacing, cost 25-35 % more frame time on lavapipe for no change in
        // see-through on the views measured.)
        let near_eye = abs(z - globals.eye.z) <= SLICE_TOP / f32(n);
        if (!near_eye && z > f32(textureLoad(tile_max, wrapped, 0).r)) {
            // A degenerate triangle (all three vertices equal) rasterises nothing.
            out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
            out.world = vec3<f32>(0.0);
            out.altitude = z;
            out.rank = j;
            return out;
        }
        lo = max(lo, tile << vec2<u32>(k));
        hi = min(hi, (tile + vec2<i32>(1)) << vec2<u32>(k));
    }
    // Corner v of the quad (indexed: `methods::sliced::QUAD_INDICES`): x bit
    // 0, y bit 1. A float select: naga writes a vector select as mix(),
    // which GLSL ES 3.00 (WebGL2) has for floats only.
    let xy = select(vec2<f32>(lo), vec2<f32>(hi), vec2<bool>((v & 1u) != 0u, (v & 2u) != 0u));
    out.world = vec3<f32>(xy, z);
    out.altitude = z;
    out.rank = j;
    out.clip = globals.view_proj * vec4<f32>(out.world, 1.0);
    return out;
}

// The point of the slice seen through this pixel: the pixel's ray meets the
// slice's plane. A quad spans the whole footprint, hundreds of units, so a
// world position interpolated across it is imprecise on some rasterisers
// (SwiftShader's showed sky for a whole horizon view); the plane hit is exact.
// Edge-on (the ray parallel to the slice) keeps the interpolated point.
struct SliceHit {
    // whether the fragment is kept
    keep: bool,
    // the solid point it stands for (the slice point, or the first solid
    // point of the gap walk)
    p: vec3<f32>,
    // the column `p` belongs to
    cell: vec2<i32>,
    // kept by a block the gap walk came down to, not by a solid point (not
    // `exact` only)
    maybe: bool,
}

// The slice's own point test alone, all a fragment needs where its ray
// crosses the slices at most GAP_MIN texels apart and never walks.
fn slice_point(in: VertexOut) -> SliceHit {
    var h: SliceHit;
    h.maybe = false;
    let d = camera_ray(in.clip.x, in.clip.y);
    if (abs(d.z) < 1e-6 * length(d)) {
        h.p = in.world;
    } else {
        let e = globals.eye.xyz;
        h.p = e + d * ((in.altitude - e.z) / d.z);
    }
    h.cell = vec2<i32>(floor(h.p.xy));
    h.keep = is_solid(h.p);
    return h;
}

fn slice_hit(in: VertexOut, exact: bool) -> SliceHit {
    var h = slice_point(in);
    let d = camera_ray(in.clip.x, in.clip.y);
    let e = globals.eye.xyz;
    if (abs(d.z) < 1e-6 * length(d)) {
        return h;
    }
    let t = (in.altitude - e.z) / d.z;
    // The ray met the previous slice `gap` before this one (or left the
    // near plane after that): walk from there to this slice's point, at
    // most the last count.w columns before it (a segment whose ends are dx,
    // dy apart crosses at most |dx| + |dy| + 2 columns), so a walk stays
    // within the culling tiles around this fragment's. The last slice before
    // the far plane also walks on towards the far plane.
    let gap = SLICE_TOP / f32(footprint.count.y) / abs(d.z);
    if (h.keep || gap * length(d.xy) <= GAP_MIN) {
        return h;
    }
    let t_near = globals.forward.w / globals.eye.w;
    let t_far = globals.right.w / globals.eye.w;
    let reach = f32(footprint.count.w - 2u) / (abs(d.x) + abs(d.y));
    let blocks = (footprint.count.w >> slice_tiles.tiles.w) + 2u;
    var x: SegmentHit;
    if (t - gap <= t_near) {
        // The first slice the ray meets (the eye's neighbours, never
        // culled) walks from the near plane as far as it takes.
        x = walk_gap(e, d, t_near, t, (FIRST_GAP_TEXELS >> slice_tiles.tiles.w) + 2u, exact);
    } else {
        x = walk_gap(e, d, t - min(gap, reach), t, blocks, exact);
    }
    if (!x.hit && t + gap > t_far) {
        x = walk_gap(e, d, t, min(t_far, t + reach), blocks, exact);
    }
    if (x.hit) {
        h.keep = true;
        h.maybe = !exact;
        h.p = e + d * x.t;
        h.cell = x.column;
    }
    return h;
}

fn slice_colour(h: SliceHit) -> vec4<f32> {
    return vec4<f32>(shade_column(h.p, h.cell.x, h.cell.y, h.p - globals.eye.xyz), 1.0);
}

// `sliced:N/fragwalk`: each air fragment of a grazing ray walks its gap.
@fragment
fn fs_sliced(in: VertexOut) -> @location(0) vec4<f32> {
    let h = slice_hit(in, true);
    if (!h.keep) {
        discard;
    }
    return slice_colour(h);
}

// Plain `sliced`: the point test alone, from a shader without the walk's
// loop, which costs occupancy on every fragment whether it is taken or not
// (H100: 9.19 ms against 8.09 with no walk taken). The rows of grazing rays
// are walked once per pixel after the slices (`sliced_gaps.wgsl`); on the
// others this is `fs_sliced`'s image (`sliced:N/fragwalk`).
@fragment
fn fs_sliced_steep(in: VertexOut) -> @location(0) vec4<f32> {
    let h = slice_point(in);
    if (!h.keep) {
        discard;
    }
    return slice_colour(h);
}

// `sliced:N/refine`, pass 1: the same slices and the same test, but a kept
// fragment writes only its slice's rank + 1 (0 = none) into the marks image,
// with MARK_MAYBE set where only the gap walk's block maxima kept it (no
// column walk here), and no colour: pass 2 (`sliced_refine.wgsl`) searches
// the exact crossing once per pixel (a maybe-mark on the rest of the ray too)
// and shades it. The depth is the slice plane's, from the rasteriser, so
// early depth testing still rejects the slices behind.
const MARK_MAYBE: u32 = 0x80000000u;

@fragment
fn fs_slice_mark(in: VertexOut) -> @location(0) vec4<u32> {
    let h = slice_hit(in, false);
    if (!h.keep) {
        discard;
    }
    return vec4<u32>((in.rank + 1u) | select(0u, MARK_MAYBE, h.maybe), 0u, 0u, 0u);
}

// `fs_slice_mark` on frames where no ray walks (`methods::sliced::rows`):
// the same marks without the walk's loop.
@fragment
fn fs_slice_mark_steep(in: VertexOut) -> @location(0) vec4<u32> {
    if (!slice_point(in).keep) {
        discard;
    }
    return vec4<u32>(in.rank + 1u, 0u, 0u, 0u);
}
