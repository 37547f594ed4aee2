// `sliced`: N horizontal quads over the camera's footprint at
// z_k = 256 - k * 256 / N (k = 1..N); a fragment keeps its point only where
// the decoded column is solid at that altitude, else discards it.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "forward.wgsl"

// count.y: slices N; count.z: the slice nearest the eye's altitude.
@group(1) @binding(0) var<uniform> footprint: Footprint;

// Twin of `methods::slice_tiles::SliceTileParams`.
struct SliceTiles {
    // x, y: the footprint's first tile (unwrapped); z, w: tiles across and
    // down (z 0: no culling, each slice one quad over the whole footprint)
    grid: vec4<i32>,
    // x: log2 of the tile side; y, z: the map's tiles across and down - 1
    tiles: vec4<u32>,
}

@group(1) @binding(1) var<uniform> slice_tiles: SliceTiles;
// The highest solid top over each tile of the map and a one-texel margin.
@group(1) @binding(2) var tile_max: texture_2d<u32>;

// Top of the sliced range (Rust: `forward::Z_MAX`).
const SLICE_TOP: f32 = 256.0;

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
        if (z > f32(textureLoad(tile_max, wrapped, 0).r)) {
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
fn slice_point(in: VertexOut) -> vec3<f32> {
    let d = camera_ray(in.clip.x, in.clip.y);
    let e = globals.eye.xyz;
    if (abs(d.z) < 1e-6 * length(d)) {
        return in.world;
    }
    return e + d * ((in.altitude - e.z) / d.z);
}

@fragment
fn fs_sliced(in: VertexOut) -> @location(0) vec4<f32> {
    let p = slice_point(in);
    if (!is_solid(p)) {
        discard;
    }
    return vec4<f32>(shade(p, p - globals.eye.xyz), 1.0);
}

// `sliced:N/refine`, pass 1: the same slices and the same test, but a kept
// fragment writes only its slice's rank + 1 (0 = none) into the marks image
// and no colour: pass 2 (`sliced_refine.wgsl`) searches the exact crossing
// once per pixel and shades it. The depth is the slice plane's, from the
// rasteriser, so early depth testing still rejects the slices behind.
@fragment
fn fs_slice_mark(in: VertexOut) -> @location(0) vec4<u32> {
    let p = slice_point(in);
    if (!is_solid(p)) {
        discard;
    }
    return vec4<u32>(in.rank + 1u, 0u, 0u, 0u);
}
