// `ray-exact`'s frame when it casts the shadow map: march, then cast only the
// shadow texels its hits sample, then shade. (Casting the map first, as the
// other methods' frames do, casts every texel the view's frustum could
// sample: on the default views 25-86 % of the map, where the visible surface
// samples 2-17 %.)
//
// 1. `cs_exact_march_hits`: the exact march per pixel. A pixel whose
//    shading reads only shadow blocks kept from earlier frames
//    (`shadow_keep.wgsl`), or the sky, is shaded there and then. Any other
//    writes the hit's column (relative to the eye's 256-texel tile) and `t`
//    into `hits`, and stamps the 8x8-texel blocks of the shadow map its
//    shading can read in `shadow_marks`; its 8x8 tile of pixels is listed
//    for the shading pass.
// 2. `ray_exact_shadow.wgsl` casts the texels of stamped blocks.
// 3. `cs_exact_shade`: one workgroup per listed tile (an indirect dispatch)
//    shades each of its hits exactly as the one-pass march does
//    (`exact_pixel_shade`: same `t`, same column) and writes the
//    depth-buffer value into `depth_out`.
// On a still or walking view nearly every block is kept, so the shadow pass
// and the shading dispatch nearly nothing.
//
// The hits are one storage buffer (8 bytes a pixel) rather than two
// images. Measured on the H100 only together with the shading's four
// terrain fetches (`bench/issue36-floors/`, call 4): the march 0.0009 ms
// faster, the shading 0.0007 slower.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "ray_core.wgsl"
#include "ray_exact_core.wgsl"
#include "ray_exact_pixel.wgsl"
#include "ray_exact_beam.wgsl"
#include "shadow_keep.wgsl"

@group(1) @binding(3) var color_out: texture_storage_2d<rgba8unorm, write>;
// The depth-buffer value of each pixel (the shading writes it).
@group(1) @binding(4) var depth_out: texture_storage_2d<r32float, write>;
// Pixel (x, y)'s hit at y * width + x: x its column relative to the eye's
// tile, x and y + 32768 in 16 bits each (HIT_NONE for the sky), y the bits
// of its `t` (negative: marched through a missing page, see below).
@group(1) @binding(5) var<storage, read_write> hits: array<vec2<u32>>;
// Words 0-2: the shadow pass's indirect dispatch (x the number of listed
// blocks, 0 at the frame's start; y and z 1). From word MARK_STAMPS, one
// stamp per 8x8-texel block of the shadow map: `xparams.config.z` when a
// pixel of this frame may sample the block. After the stamps, the shading
// pass's indirect dispatch (x the number of listed tiles), a word of
// padding, and a stamp per 8x8-pixel tile: `xparams.config.z` when a pixel
// of the tile left its shading to the shading pass. (One binding for all:
// paged terrain's frame binds as many storage buffers as WebGPU allows.)
@group(1) @binding(6) var<storage, read_write> shadow_marks: array<atomic<u32>>;
// The blocks stamped this frame, in the order they were first stamped; then
// the kept blocks' tags (`shadow_keep.wgsl`); then, from word 4 x blocks,
// the pixel tiles the shading pass shades, in the order listed.
@group(1) @binding(7) var<storage, read_write> shadow_blocks: array<u32>;

const HIT_NONE: u32 = 0xffffffffu;
// `hits.y` of a pixel the march shaded (`hits.x` HIT_NONE); 0 for the sky.
const HIT_SHADED: u32 = 1u;
const MARK_BLOCK: i32 = 8;
// Twin of `deferred::MARK_STAMPS`.
const MARK_STAMPS: u32 = 4u;

var<workgroup> group_most: atomic<u32>;

// The shading pass's dispatch: after the stamps.
fn shade_dispatch_word() -> u32 {
    let blocks = u32(globals.shadow_u.w) / u32(MARK_BLOCK);
    return MARK_STAMPS + blocks * blocks;
}

// The first listed tile's word in `shadow_blocks`: after the list and tags.
fn shade_tiles_word() -> u32 {
    let blocks = u32(globals.shadow_u.w) / u32(MARK_BLOCK);
    return 4u * blocks * blocks;
}

// Stamp the shadow-map blocks shading point `p` can read: `shadow_factor`
// moves the point up to 1.5 texels along its normal, then reads the 2x2 texels
// around it less half a texel, so every tap lies within 2 texels of p's own
// map coordinates (2.5 here, for rounding). Whether every one of them is
// kept from an earlier frame (then the point can be shaded now).
fn mark_shadow_blocks(p: vec3<f32>) -> bool {
    let texel = globals.shadow_origin.w;
    let rel = p - globals.shadow_origin.xyz;
    let uv = vec2<f32>(dot(rel, globals.shadow_u.xyz), dot(rel, globals.shadow_v.xyz)) / texel;
    let side = i32(globals.shadow_u.w);
    let lo = vec2<i32>(floor(uv - vec2<f32>(2.5)));
    let hi = vec2<i32>(floor(uv + vec2<f32>(2.5)));
    if (any(hi < vec2<i32>(0)) || any(lo >= vec2<i32>(side))) {
        // Off the map: shading reads nothing (taps outside are lit).
        return true;
    }
    var kept = true;
    let blocks = side / MARK_BLOCK;
    let b0 = clamp(lo, vec2<i32>(0), vec2<i32>(side - 1)) / MARK_BLOCK;
    let b1 = clamp(hi, vec2<i32>(0), vec2<i32>(side - 1)) / MARK_BLOCK;
    // Bounded: b0 and b1 are clamped to the map and lie within 5 texels of
    // each other: one or two blocks each way.
    for (var by = b0.y; by <= b1.y; by = by + 1) {
        // Bounded: as `by` is.
        for (var bx = b0.x; bx <= b1.x; bx = bx + 1) {
            // A block an earlier frame cast for this lattice block, with
            // nothing changed since, holds what casting it now would.
            if (shadow_block_kept(vec2<i32>(bx, by))) {
                continue;
            }
            kept = false;
            // Most pixels of a block find it stamped: read before the
            // exchange; the one exchange that changes the stamp lists it.
            let i = u32(by * blocks + bx);
            let stamp = xparams.config.z;
            let m = MARK_STAMPS + i;
            if (atomicLoad(&shadow_marks[m]) != stamp && atomicExchange(&shadow_marks[m], stamp) != stamp) {
                shadow_blocks[atomicAdd(&shadow_marks[0], 1u)] = i;
            }
        }
    }
    return kept;
}

// Casting the whole map (`ShadowCover` of every texel, how the tests check the
// stamps are enough): list every block, pixel `flat` of `pixels` taking every
// `pixels`-th.
fn list_every_block(flat: u32, pixels: u32) {
    let side = u32(globals.shadow_u.w) / 8u;
    let count = side * side;
    // Bounded: `pixels` is at least 1 (a pixel of the frame calls this) and
    // `k` stays below `count` (at most 2^20 blocks) + `pixels` (2^26), no wrap.
    for (var k = flat; k < count; k = k + pixels) {
        shadow_blocks[k] = k;
    }
    if (flat == 0u) {
        atomicStore(&shadow_marks[0], count);
    }
}

@compute @workgroup_size(8, 8, 1)
fn cs_exact_march_hits(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let size = vec2<u32>(globals.screen.xy);
    // The tile's beam (every invocation: the wide search is the workgroup's).
    let start = exact_group_start(group.xy, li);
    if (all(id.xy < size)) {
        page_pixel_begin();
        let px = vec2<f32>(id.xy) + vec2<f32>(0.5);
        let h = exact_pixel_hit_from(px.x, px.y, start, exact_tile_level());
        var hit = vec2<u32>(HIT_NONE, 0u);
        // Shaded here: only where blocks are kept at all (the whole map's
        // deferred frame; paged terrain keeps its pending marks in the
        // shading pass).
        var now = xparams.shadow_keep.x != 0u;
        if (h.hit) {
            let rel = h.column - exact_base(globals.eye.xy) + vec2<i32>(32768);
            // A hit on a missing page's box carries its pending mark to the
            // shading as a negative t (t >= 0 otherwise).
            let t_kept = select(h.t, -1.0 - h.t, page_pixel_missed());
            hit = vec2<u32>(u32(rel.x) | (u32(rel.y) << 16u), bitcast<u32>(t_kept));
            if (globals.light_dir.w != 0.0) {
                if (globals.shadow_cover_count.x != 0u) {
                    let d = camera_ray(px.x, px.y);
                    now = mark_shadow_blocks(globals.eye.xyz + d * h.t) && now;
                } else {
                    // Every block is cast this frame (`list_every_block`).
                    now = false;
                }
            }
        }
        if (now) {
            var s = exact_pixel_sky();
            if (h.hit) {
                s = exact_pixel_shade(px.x, px.y, h.t, h.column);
            }
            textureStore(color_out, id.xy, s.color);
            textureStore(depth_out, id.xy, vec4<f32>(s.depth, 0.0, 0.0, 0.0));
            hit = vec2<u32>(HIT_NONE, HIT_SHADED);
        } else {
            // The first of the tile's pixels to find it unstamped lists it
            // (a stamp, not a workgroup flag and barrier: llvmpipe pays for
            // a barrier after the walk over the whole walk).
            let across = (size.x + 7u) / 8u;
            let tile = group.y * across + group.x;
            let word = shade_dispatch_word() + 4u + tile;
            let stamp = xparams.config.z;
            if (atomicLoad(&shadow_marks[word]) != stamp && atomicExchange(&shadow_marks[word], stamp) != stamp) {
                let k = atomicAdd(&shadow_marks[shade_dispatch_word()], 1u);
                shadow_blocks[shade_tiles_word() + k] = tile;
            }
        }
        hits[id.y * size.x + id.x] = hit;
        if (globals.shadow_cover_count.x == 0u) {
            list_every_block(id.y * size.x + id.x, size.x * size.y);
        }
        if (h.capped) {
            atomicAdd(&xstats[0], 1u);
        }
        if (EXACT_ITERATION_STATS) {
            atomicMax(&group_most, h.iterations);
        }
    }
    if (EXACT_ITERATION_STATS) {
        workgroupBarrier();
        if (li == 0u) {
            atomicMax(&xstats[1], atomicLoad(&group_most));
        }
    }
}

// Workgroup k shades listed tile k's pixels the march left to it.
@compute @workgroup_size(8, 8, 1)
fn cs_exact_shade(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let size = vec2<u32>(globals.screen.xy);
    let tile = shadow_blocks[shade_tiles_word() + group.x];
    let across = (size.x + 7u) / 8u;
    let id = vec2<u32>(tile % across, tile / across) * 8u + local.xy;
    if (any(id >= size)) {
        return;
    }
    let hit = hits[id.y * size.x + id.x];
    let packed = hit.x;
    if (packed == HIT_NONE && hit.y == HIT_SHADED) {
        return;
    }
    var s = exact_pixel_sky();
    page_pixel_begin();
    var marched_missing = false;
    if (packed != HIT_NONE) {
        let rel = vec2<i32>(vec2<u32>(packed & 0xffffu, packed >> 16u)) - vec2<i32>(32768);
        let column = exact_base(globals.eye.xy) + rel;
        var t = bitcast<f32>(hit.y);
        marched_missing = t < 0.0;
        t = select(t, -1.0 - t, marched_missing);
        s = exact_pixel_shade(f32(id.x) + 0.5, f32(id.y) + 0.5, t, column);
    }
    page_pixel_end(marched_missing || page_pixel_missed());
    textureStore(color_out, id.xy, s.color);
    textureStore(depth_out, id.xy, vec4<f32>(s.depth, 0.0, 0.0, 0.0));
}
