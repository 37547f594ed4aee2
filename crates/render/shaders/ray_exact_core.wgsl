// The exact march shared by `ray-exact`, `ray-exact-fragment` and their shadow
// map: a hierarchical 2D grid traversal over the max-height pyramid of column
// tops (`strata_maxmip`: level k holds the highest top of each 2^k-texel tile),
// descending where the ray dips to a tile's maximum and climbing when it leaves
// its parent, and at the finest level the exact segment-interval test of the
// CPU reference (`raycast.rs::column_hit`) against [0, low] and [mid, high].
// No step budget: a safety cap on iterations (`xparams.config.y`), counted.
//
// Precision: the map is up to 16384 long, where f32 keeps ~0.002 of a unit.
// The traversal runs relative to `base`, a point whose x and y are multiples of
// the coarsest tile (256) near the ray's start, so every cell index is small,
// every boundary parameter is computed from its own integer coordinate (never
// accumulated), and tile indices are `(base >> k) + cell` exactly.
#include "frame.wgsl"
#include "surface.wgsl"
#include "column_segment.wgsl"
#include "exact_levels.wgsl"

// Twin of `methods::ray_exact::ExactParams`.
struct ExactParams {
    // x coarsest level, y iteration cap, z/w unused
    config: vec4<u32>,
    // level k at index k: x first byte, y log2 tiles across, z tiles across
    // - 1, w tiles down - 1; index 0 the texel plane's, if any
    // (`texel_block_rows`)
    levels: array<vec4<u32>, 9>,
    // x the key of the shadow blocks kept from earlier frames (0: keep
    // none; `ray_exact_deferred.wgsl`), yzw unused
    shadow_keep: vec4<u32>,
}

@group(1) @binding(0) var<uniform> xparams: ExactParams;
// [0] camera rays that hit the cap, [1] most iterations of a camera ray,
// [2] shadow rays that hit the cap, [3] most iterations of a shadow ray
@group(1) @binding(2) var<storage, read_write> xstats: array<atomic<u32>, 4>;

// Most levels climbed after a step leaves its parent tile (a pipeline
// constant, for measuring: 1 as the reference, 8 = as far as the step allows).
override EXACT_CLIMB: u32 = 1u;

// log2 of the tile ratio between the levels the traversal visits (a pipeline
// constant, for measuring): 1 visits every level (tiles 2, 4, .., 256), 2 every
// other one (4, 16, 64, 256, as the CPU reference does).
override EXACT_LOG_RATIO: u32 = 1u;

// A descent into the texels tests the texel it lands on in the same iteration
// (a pipeline constant, `ExactOptions::fused_descent`; the same hits either
// way). Off (the default), the descent is an iteration of its own, as the
// CPU reference walks; on, near the ground a warp runs the column test once
// an iteration for its lanes already at the texels and those just come down,
// rather than a pass of descents and then a pass of column tests: 20 % fewer
// iterations, but on the H100 a slower frame (`bench/issue36-cave-skip/`).
override EXACT_FUSED_DESCENT: bool = false;

// Keep the most iterations of any camera and of any shadow ray (`xstats[1]`
// and `[3]`; a pipeline constant, `ExactOptions::iteration_stats`). They cost
// each workgroup a barrier and a global atomic on one shared word (1.2 % of
// the H100 frame, `bench/issue36-floors/`), so they are kept only when asked;
// rays stopped by the cap are counted always.
override EXACT_ITERATION_STATS: bool = false;

// A tile whose maximum is above the ray is skipped still when the ray
// passes between the tile's floors and slabs (`cave_clear`: under a bridge,
// through a cave), rather than descended into (a pipeline constant,
// `ExactOptions::cave_skip`; the same hits either way). The beam's test
// (`beam_clear`) likewise.
override EXACT_CAVE_SKIP: bool = false;

// How far above the highest floor and below the lowest slab bottom of a tile
// a segment must stay for `cave_clear` (altitude units): a margin for the
// rounding of the segment's ends, so a tile is skipped only where the exact
// column test (`column_entry`) would find nothing either.
const CAVE_MARGIN: f32 = 0.015625;
// A column's slab bottom when it has none (`strata_maxmip::NO_SLAB`).
const CAVE_NO_SLAB: u32 = 255u;

// How a ray walks the texels of a 4x4-texel tile it comes down into (a
// pipeline constant, `ExactOptions::texel_walk`; the same hits, the same
// iterations): 0 a terrain fetch per texel; 1 from the texel plane
// (`texel_block_rows`: the tile's sixteen tops in four loads side by side),
// loaded once the ray comes down into the tile, decoding only the columns
// that have a slab; 2 the same, the plane's words loaded beside the tile's
// maximum at every step over a 4x4 tile, so coming down waits on nothing.
// Both are slower on the H100 than 0 (`bench/issue36-texel-blocks/`).
override EXACT_TEXEL_BLOCKS: u32 = 0u;
// A texel plane byte whose column must be decoded (`strata_maxmip::TEXEL_DECODE`).
const TEXEL_DECODE: u32 = 255u;

// The pyramid level rays start at (a pipeline constant): the coarsest kept
// level at or below it. The whole map's compute pipelines start at 6 (tiles
// of 64 texels; `ray_exact::START_LEVEL`): on the default views that takes
// 4 % fewer iterations than starting at the 256-texel tiles, with the same
// hits (`strata exact-counts --start-level`). Paged terrain starts at the
// top, its coarse level.
override EXACT_START_LEVEL: u32 = 255u;

// The coarsest tile: `base` is a multiple of it.
const EXACT_BASE_TILE: f32 = 256.0;
const EXACT_BIG: f32 = 3.0e38;

struct ExactHit {
    hit: bool,
    // ray parameter of the first solid point (t1 at a miss)
    t: f32,
    // the hit column, absolute (unwrapped) texel coordinates
    column: vec2<i32>,
    // what was hit, as `strata_reference::HitClass` codes: 1 floor, 2 slab
    // top, 3 cave ceiling, 4 wall (a column entered through its side)
    hit_class: u32,
    iterations: u32,
    capped: bool,
}

// The first solid point of o + t d, t in [t0, t1], with o relative to `base`
// (see the top). t0 must be at or below the altitude 255 along the ray.
fn exact_march(o: vec3<f32>, base: vec2<i32>, d: vec3<f32>, t0: f32, t1: f32) -> ExactHit {
    return exact_march_at(o, base, d, t0, t1, EXACT_START_LEVEL);
}

// `exact_march` from pyramid level `start` (the coarsest kept level at or
// below it) rather than `EXACT_START_LEVEL`.
fn exact_march_at(o: vec3<f32>, base: vec2<i32>, d: vec3<f32>, t0: f32, t1: f32, start: u32) -> ExactHit {
    var r: ExactHit;
    r.hit = false;
    r.t = t1;
    r.hit_class = 0u;
    r.iterations = 0u;
    r.capped = false;
    if (t1 < t0) {
        return r;
    }
    let top = xparams.config.x;
    let cap = xparams.config.y;
    let pos = d.xy > vec2<f32>(0.0);
    let step = select(vec2<i32>(-1), vec2<i32>(1), pos);
    let far_side = select(vec2<i32>(0), vec2<i32>(1), pos);
    let still = d.xy == vec2<f32>(0.0);
    let inv = select(vec2<f32>(1.0) / d.xy, vec2<f32>(0.0), still);
    let ratio = EXACT_LOG_RATIO;
    // Visited levels are lvl * ratio (pyramid level 0 = the texels).
    var lvl = min(top, start) / ratio;
    var t = t0;
    var cell = texel_after(o.xy + d.xy * t, d.xy) >> vec2<u32>(lvl * ratio);
    // Bounded: each pass counts an iteration first and the loop returns
    // at the cap (`xparams.config.y`, ITERATION_CAP).
    loop {
        if (r.iterations >= cap) {
            r.capped = true;
            return r;
        }
        r.iterations = r.iterations + 1u;
        // Paged terrain: the level of detail at t (0 on the whole map). Tiles
        // no larger than its texels are columns: a coarse texel's column
        // stands for its whole block, so descending into it finds nothing
        // new (and a grazing ray would step its plateau texel by texel).
        let leaf = exact_lod_at(t);
        var shift = lvl * ratio;
        if (shift < leaf && lvl < top / ratio) {
            // The level of detail grew past this tile: take its parent (the
            // point at t is in it) rather than walk fine tiles of one coarse
            // column.
            cell = cell >> vec2<u32>(ratio);
            lvl = lvl + 1u;
            continue;
        }
        let size = f32(1u << shift);
        let edge = vec2<f32>(cell + far_side) * size;
        var tb = select((edge - o.xy) * inv, vec2<f32>(EXACT_BIG), still);
        var t_exit = min(tb.x, tb.y);
        var t_out = min(t_exit, t1);
        var test_column = !(lvl > 0u && shift > leaf);
        if (!test_column) {
            let z_a = o.z + d.z * t;
            let z_b = o.z + d.z * t_out;
            let z_min = min(z_a, z_b);
            let tile = (base >> vec2<u32>(shift)) + cell;
            // The cave word is read beside the maximum, not after it: the
            // step waits for one fetch, not two in a row.
            let tile_top = maxmip_get(shift, tile.x, tile.y);
            var caves = 0u;
            if (EXACT_CAVE_SKIP) {
                caves = cave_word(shift, tile.x, tile.y);
            }
            let block = EXACT_TEXEL_BLOCKS != 0u && shift == 2u && leaf == 0u;
            var rows = vec4<u32>(0u);
            if (EXACT_TEXEL_BLOCKS == 2u && block) {
                rows = texel_block_rows(tile.x, tile.y);
            }
            if (z_min <= tile_top && !(EXACT_CAVE_SKIP && cave_word_clear(caves, z_min, max(z_a, z_b)))) {
                if (block) {
                    // The tile's texels from the texel plane: the iterations
                    // the walk below would take at level 0, one per texel,
                    // with the same bounds and tests.
                    let first = cell << vec2<u32>(2u);
                    if (EXACT_TEXEL_BLOCKS == 1u) {
                        rows = texel_block_rows(tile.x, tile.y);
                    }
                    var texel = clamp(texel_after(o.xy + d.xy * t, d.xy), first, first + vec2<i32>(3));
                    // Bounded: each texel steps out along x or y, so the
                    // walk leaves the tile after 7 at most; and each pass
                    // counts an iteration, returning at the cap.
                    loop {
                        if (r.iterations >= cap) {
                            r.capped = true;
                            return r;
                        }
                        r.iterations = r.iterations + 1u;
                        let tt = select((vec2<f32>(texel + far_side) - o.xy) * inv, vec2<f32>(EXACT_BIG), still);
                        let tt_exit = min(tt.x, tt.y);
                        let at = vec2<u32>(texel - first);
                        let byte = (rows[at.y] >> (at.x << 3u)) & 0xffu;
                        let column = base + texel;
                        var c: Column;
                        if (byte == TEXEL_DECODE) {
                            c = decode_column(column.x, column.y);
                        } else {
                            c.low = f32(byte);
                            c.mid = c.low;
                            c.high = c.low;
                            c.dual = false;
                        }
                        let e = column_entry(c, o.z, d.z, t, min(tt_exit, t1));
                        if (e.x >= 0.0) {
                            return exact_hit(r, e, column, t > t0 && e.x <= t, d.z);
                        }
                        if (tt_exit >= t1) {
                            return r;
                        }
                        t = tt_exit;
                        let was = texel;
                        if (tt.x <= tt.y) {
                            texel.x = texel.x + step.x;
                        }
                        if (tt.y <= tt.x) {
                            texel.y = texel.y + step.y;
                        }
                        if (any(texel >> vec2<u32>(2u) != cell)) {
                            // Out of the tile: climb from the texels as the
                            // walk at level 0 would.
                            let up = exact_climb(was, texel, 0u);
                            cell = up.xy;
                            lvl = u32(up.z);
                            break;
                        }
                    }
                    continue;
                }
                // The ray may touch something here: the child it is in at t.
                lvl = lvl - 1u;
                let child = texel_after(o.xy + d.xy * t, d.xy) >> vec2<u32>(shift - ratio);
                let first = cell << vec2<u32>(ratio);
                cell = clamp(child, first, first + vec2<i32>((1 << ratio) - 1));
                if (!EXACT_FUSED_DESCENT || lvl > 0u || leaf != 0u) {
                    continue;
                }
                // Down at the texels: the texel's bounds (as the next
                // iteration would compute them at size 1), then its column.
                shift = 0u;
                tb = select((vec2<f32>(cell + far_side) - o.xy) * inv, vec2<f32>(EXACT_BIG), still);
                t_exit = min(tb.x, tb.y);
                t_out = min(t_exit, t1);
                test_column = true;
            }
        }
        if (test_column) {
            // The tile's first texel (the tile itself at level 0).
            let column = base + (cell << vec2<u32>(shift));
            let c = decode_column(column.x, column.y);
            let e = column_entry(c, o.z, d.z, t, t_out);
            if (e.x >= 0.0) {
                return exact_hit(r, e, column, t > t0 && e.x <= t, d.z);
            }
        }
        if (t_exit >= t1) {
            return r;
        }
        t = t_exit;
        let old = cell;
        if (tb.x <= tb.y) {
            cell.x = cell.x + step.x;
        }
        if (tb.y <= tb.x) {
            cell.y = cell.y + step.y;
        }
        let up = exact_climb(old, cell, lvl);
        cell = up.xy;
        lvl = u32(up.z);
    }
    return r;
}

// `r` with the hit `e` (`column_entry`'s) in `column`: a wall where the ray
// entered the column through its side (`side`).
fn exact_hit(r0: ExactHit, e: vec2<f32>, column: vec2<i32>, side: bool, dz: f32) -> ExactHit {
    var r = r0;
    r.hit = true;
    r.t = e.x;
    r.column = column;
    if (side) {
        r.hit_class = 4u;
    } else if (e.y == 0.0) {
        r.hit_class = 1u;
    } else {
        r.hit_class = select(3u, 2u, dz < 0.0);
    }
    return r;
}

// After a step from cell `was` to `cell` of visited level `lvl`: if it left
// the parent tile, climb (one level by default, as the reference does, so a
// ray skimming rough ground does not climb high and come back down at every
// crossing). The cell (xy) and the visited level (z) after.
fn exact_climb(was0: vec2<i32>, cell0: vec2<i32>, lvl0: u32) -> vec3<i32> {
    let ratio = EXACT_LOG_RATIO;
    let top = xparams.config.x / ratio;
    var was = was0;
    var cell = cell0;
    var lvl = lvl0;
    for (var n = 0u; n < EXACT_CLIMB; n = n + 1u) {
        if (lvl >= top || all((was >> vec2<u32>(ratio)) == (cell >> vec2<u32>(ratio)))) {
            break;
        }
        was = was >> vec2<u32>(ratio);
        cell = cell >> vec2<u32>(ratio);
        lvl = lvl + 1u;
    }
    return vec3<i32>(cell, i32(lvl));
}

// A texel of the shadow map's ray along the light: where it comes down to
// altitude 255 (`p`, at `t_in` from the map's plane) and the ray parameter
// from there at which it leaves the map below 0 (`span`).
struct ShadowRay {
    p: vec3<f32>,
    t_in: f32,
    span: f32,
}

fn exact_shadow_ray(id: vec2<u32>) -> ShadowRay {
    let o = shadow_texel_centre(id);
    let d = globals.light_dir.xyz;
    // The light travels down: from altitude 255 to below 0, where every
    // column is solid.
    let t_in = (MAX_ALTITUDE - o.z) / d.z;
    let t_out = (-1.0 - o.z) / d.z;
    return ShadowRay(o + d * t_in, t_in, t_out - t_in);
}

// The base (multiple of the coarsest tile) for a ray starting near world `p`.
fn exact_base(p: vec2<f32>) -> vec2<i32> {
    return vec2<i32>(floor(p / EXACT_BASE_TILE)) * i32(EXACT_BASE_TILE);
}

// Clip [t0, t1] of world o + t d to altitudes <= 255 (nothing is solid above).
// Empty (x > y) when the segment stays above.
fn exact_clip(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> vec2<f32> {
    var a = t0;
    var b = t1;
    if (d.z < 0.0) {
        a = max(a, (MAX_ALTITUDE - o.z) / d.z);
    } else if (o.z > MAX_ALTITUDE) {
        return vec2<f32>(1.0, 0.0);
    } else if (d.z > 0.0) {
        b = min(b, (MAX_ALTITUDE - o.z) / d.z);
    }
    return vec2<f32>(a, b);
}
