// `ray-exact`'s beam pre-pass (issue 36, item 1): one invocation per 8x8-pixel
// tile marches the beam that holds the tile's 64 camera rays through the
// pyramid and writes the least t at which any of them may meet a solid point;
// the march (`exact_pixel_hit_from`) then starts each ray of the tile there
// instead of at the near plane. The CPU twin is `replay.rs::Replay::beam`
// (`strata exact-counts` counts both).
//
// Why no ray of the tile is solid before the start (so its march, from the
// start, finds the hit the march from the near plane finds):
// - `camera_ray` is affine in the pixel, so every pixel's direction d is a
//   convex combination sum l_i d_i of the four corner pixels' (l_i >= 0,
//   sum 1), and the rays share the eye o and the parameter t (t * focal is the
//   view depth).
// - For s in [t, t2]: o + s d = sum l_i (o + s d_i), and o + s d_i lies on the
//   segment from o + t d_i to o + t2 d_i: every point of every ray of the tile
//   over [t, t2] is in the convex hull of those eight points, so in their
//   bounding box.
// - The box, widened by a margin for f32 rounding, spans at most 2x2 tiles
//   of the level whose tile is at least its xy extent. Every solid point of
//   a column lies at or below its top, and the pyramid holds the highest top
//   of each tile: when the box's lowest altitude is above the four tiles'
//   maxima (or above 255), no point of [t, t2] of any ray of the tile is
//   solid.
// - The search only moves t past such intervals, so the start is at or
//   before every ray's first solid point; a ray's march from it skips only
//   empty space (its first column is entered at the start instead of its
//   side, where nothing is solid). Tested: `the_beam_never_passes_a_hit`
//   (the replay) and `depth_and_shadow_variants_agree...` (the GPU images,
//   beam on and off, bit for bit).
//
// Two searches (`EXACT_BEAM_SEARCH`, `ExactOptions::beam_search`):
// - serial (`cs_exact_beam`, a pre-pass, one invocation per tile): intervals
//   [t, t + dt] double while clear and halve where not, until an interval
//   that is not clear moves the rays no further than the beam is wide (plus
//   a texel); at most `BEAM_CAP` iterations (the start stays where it got:
//   still safe). A chain of dependent fetches per tile: the pass is
//   latency-bound.
// - wide (`wide_search`, by an 8x8 workgroup per tile: the march's own, or
//   a pre-pass's, `cs_exact_beam_wide`): the 64 invocations test 64 slices
//   of the depth range at once, then 64 sub-slices of the first slice that
//   is not clear, and so on for at most `WIDE_ROUNDS` rounds: a few fetch
//   latencies instead of ~20. Why that start is safe too is at
//   `wide_search`.
// The shadow blocks search likewise, by their 64 invocations
// (`exact_shadow_block_start`): one round serially, `wide_search` wide.

#include "frame.wgsl"
#include "ray_exact_core.wgsl"

// Where each tile's rays start (`cs_exact_beam` writes; the march reads).
@group(1) @binding(12) var<storage, read_write> exact_beams: array<f32>;

// The march starts at its tile's beam (a pipeline constant; off: every ray
// starts at the near plane and the buffer is not read).
override EXACT_BEAM: bool = true;

// How the beam is searched (a pipeline constant, `ExactOptions::beam_search`):
// `BEAM_SERIAL` (the pre-pass `cs_exact_beam` writes `exact_beams`),
// `BEAM_WIDE` (`exact_group_start` searches in the march's workgroup; the
// buffer is bound but neither written nor read) or `BEAM_WIDE_PASS` (the
// same search in a pre-pass, `cs_exact_beam_wide`, so the march keeps no
// barrier).
override EXACT_BEAM_SEARCH: u32 = 2u;
const BEAM_SERIAL: u32 = 0u;
const BEAM_WIDE: u32 = 1u;
// The wide search in a pre-pass (`cs_exact_beam_wide` writes `exact_beams`).
const BEAM_WIDE_PASS: u32 = 2u;

// The pyramid level camera rays start at from their tile's beam (a pipeline
// constant, `ray_exact::BEAM_LEVEL`): near the ground, where the beam
// leaves them, small tiles (4 texels) take fewer steps than `EXACT_START_LEVEL`.
override EXACT_BEAM_LEVEL: u32 = 2u;

// A box no wider than a texel is tested against the (at most 2x2) texels
// that hold it (`texels_clear`), not the 4-texel tiles: near the ground the
// beam gets much closer to its rays' hits (a pipeline constant,
// `ExactOptions::beam_texels`).
override EXACT_BEAM_TEXELS: bool = false;

const BEAM_TILE: u32 = 8u;
const BEAM_CAP: u32 = 24u;
const BEAM_FIRST_STEP: f32 = 4.0;
const BEAM_MARGIN: f32 = 0.0625;
const BEAM_MARGIN_RELATIVE: f32 = 1.0e-5;

fn beam_tiles_across() -> u32 {
    return (u32(globals.screen.x) + BEAM_TILE - 1u) / BEAM_TILE;
}

// Where pixel `id`'s ray starts at the earliest: its tile's beam
// (-EXACT_BIG without the beam).
fn exact_tile_start(id: vec2<u32>) -> f32 {
    if (!EXACT_BEAM) {
        return -EXACT_BIG;
    }
    let tile = id / BEAM_TILE;
    return exact_beams[tile.y * beam_tiles_across() + tile.x];
}

// Where the rays of the march's 8x8-pixel workgroup `group` start (its tile's
// beam, -EXACT_BIG without one). Call it from every invocation of the
// workgroup (`li` its index) in uniform control flow: the wide search
// synchronises the workgroup.
fn exact_group_start(group: vec2<u32>, li: u32) -> f32 {
    if (EXACT_BEAM && EXACT_BEAM_SEARCH == BEAM_WIDE) {
        return exact_wide_tile_start(group, li);
    }
    return exact_tile_start(group * BEAM_TILE);
}

// The pyramid level camera rays start at.
fn exact_tile_level() -> u32 {
    return select(EXACT_START_LEVEL, EXACT_BEAM_LEVEL, EXACT_BEAM);
}

// The rays through the corner pixels' centres of tile `tile`.
fn beam_corner_rays(tile: vec2<u32>) -> array<vec3<f32>, 4> {
    let size = vec2<u32>(globals.screen.xy);
    let first = tile * BEAM_TILE;
    let a = vec2<f32>(first) + vec2<f32>(0.5);
    let b = vec2<f32>(min(first + vec2<u32>(BEAM_TILE), size)) - vec2<f32>(0.5);
    return array<vec3<f32>, 4>(camera_ray(a.x, a.y), camera_ray(b.x, a.y), camera_ray(a.x, b.y), camera_ray(b.x, b.y));
}

struct BeamBox {
    lo: vec3<f32>,
    hi: vec3<f32>,
}

// The box of the four corner rays' points at t.
fn beam_box(o0: vec3<f32>, o1: vec3<f32>, o2: vec3<f32>, o3: vec3<f32>, d0: vec3<f32>, d1: vec3<f32>, d2: vec3<f32>, d3: vec3<f32>, t: f32) -> BeamBox {
    let p0 = o0 + d0 * t;
    let p1 = o1 + d1 * t;
    let p2 = o2 + d2 * t;
    let p3 = o3 + d3 * t;
    return BeamBox(min(min(p0, p1), min(p2, p3)), max(max(p0, p1), max(p2, p3)));
}

// Whether nothing in the box (lo, hi), relative to `base` and widened by the
// margin, is solid: its lowest altitude above 255, or above the highest top
// of the 2x2 tiles, of the finest kept level whose tile is at least its
// extent, that hold it; or (`EXACT_CAVE_SKIP`) its altitudes between every
// one of those tiles' floors and slabs (`cave_clear`).
fn beam_clear(base: vec2<i32>, lo_in: vec3<f32>, hi_in: vec3<f32>) -> bool {
    let big = max(abs(lo_in), abs(hi_in));
    let m = BEAM_MARGIN + BEAM_MARGIN_RELATIVE * max(max(big.x, big.y), big.z);
    let lo = lo_in - vec3<f32>(m);
    let hi = hi_in + vec3<f32>(m);
    if (lo.z > MAX_ALTITUDE) {
        return true;
    }
    let top = xparams.config.x;
    let ext = max(hi.x - lo.x, hi.y - lo.y);
    if (EXACT_BEAM_TEXELS && ext <= 1.0) {
        return texels_clear(base, lo, hi);
    }
    var shift = EXACT_LOG_RATIO;
    // Bounded: `shift` rises by EXACT_LOG_RATIO (1 or 2) a pass to `top`,
    // the pyramid's coarsest level.
    loop {
        if (shift >= top || f32(1u << shift) >= ext) {
            break;
        }
        shift = shift + EXACT_LOG_RATIO;
    }
    let size = f32(1u << shift);
    if (size < ext) {
        return false;
    }
    let inv = 1.0 / size;
    let tiles = base >> vec2<u32>(shift);
    let c0 = vec2<i32>(floor(lo.xy * inv)) + tiles;
    let c1 = vec2<i32>(floor(hi.xy * inv)) + tiles;
    let h = max(
        max(maxmip_get(shift, c0.x, c0.y), maxmip_get(shift, c1.x, c0.y)),
        max(maxmip_get(shift, c0.x, c1.y), maxmip_get(shift, c1.x, c1.y)),
    );
    if (lo.z > h) {
        return true;
    }
    // Between every one of the four tiles' floors and slabs (their words
    // read at once, not one after another).
    if (!EXACT_CAVE_SKIP) {
        return false;
    }
    let w00 = cave_word(shift, c0.x, c0.y);
    let w10 = cave_word(shift, c1.x, c0.y);
    let w01 = cave_word(shift, c0.x, c1.y);
    let w11 = cave_word(shift, c1.x, c1.y);
    return cave_word_clear(w00, lo.z, hi.z) && cave_word_clear(w10, lo.z, hi.z)
        && cave_word_clear(w01, lo.z, hi.z) && cave_word_clear(w11, lo.z, hi.z);
}

// Whether nothing in the box (lo, hi), relative to `base`, at most a texel
// wide, is solid: its lowest altitude above the top of each of the (at most
// 2x2) texels that hold it, or (`EXACT_CAVE_SKIP`) its altitudes between the
// texel's floor and slab (`CAVE_MARGIN` clear of both).
fn texels_clear(base: vec2<i32>, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let c0 = vec2<i32>(floor(lo.xy)) + base;
    let c1 = vec2<i32>(floor(hi.xy)) + base;
    let texels = array<vec2<i32>, 4>(c0, vec2<i32>(c1.x, c0.y), vec2<i32>(c0.x, c1.y), c1);
    for (var k = 0u; k < 4u; k = k + 1u) {
        if (!texel_clear(decode_column(texels[k].x, texels[k].y), lo, hi)) {
            return false;
        }
    }
    return true;
}

// Whether nothing of column `c` is in the box (lo, hi): the box's lowest
// altitude above its top, or (`EXACT_CAVE_SKIP`) its altitudes between the
// column's floor and slab, `CAVE_MARGIN` clear of both.
fn texel_clear(c: Column, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let bottom = select(f32(CAVE_NO_SLAB), c.mid, c.dual);
    let above = lo.z > select(c.low, c.high, c.dual);
    let between = EXACT_CAVE_SKIP && lo.z > c.low + CAVE_MARGIN && hi.z < bottom - CAVE_MARGIN;
    return above || between;
}

// The least t in [t0, t1] at which a ray o + t d, d in the convex hull of
// d0..d3, may be solid (t1 when none may); o relative to `base`.
fn exact_beam(o: vec3<f32>, base: vec2<i32>, d0: vec3<f32>, d1: vec3<f32>, d2: vec3<f32>, d3: vec3<f32>, t0: f32, t1: f32) -> f32 {
    let q = max(max(abs(d0), abs(d1)), max(abs(d2), abs(d3)));
    let reach = max(max(q.x, q.y), q.z);
    var t = t0;
    if (reach == 0.0) {
        return t;
    }
    var dt = BEAM_FIRST_STEP / reach;
    var a = beam_box(o, o, o, o, d0, d1, d2, d3, t);
    var n = 0u;
    // Bounded: at most BEAM_CAP passes (`n`).
    loop {
        if (t >= t1 || n >= BEAM_CAP) {
            break;
        }
        n = n + 1u;
        let t2 = min(t + dt, t1);
        let b = beam_box(o, o, o, o, d0, d1, d2, d3, t2);
        if (beam_clear(base, min(a.lo, b.lo), max(a.hi, b.hi))) {
            t = t2;
            a = b;
            dt = dt * 2.0;
        } else if (dt * reach <= max(a.hi.x - a.lo.x, a.hi.y - a.lo.y) + 1.0) {
            break;
        } else {
            dt = dt * 0.5;
        }
    }
    return t;
}

// The wide search (`EXACT_BEAM_SEARCH` = `BEAM_WIDE` or `BEAM_WIDE_PASS`).
const WIDE_LANES: u32 = 64u;
const WIDE_ROUNDS: u32 = 8u;
const WIDE_RANGE_MARGIN: f32 = 1.0e-4;

// Most rounds of the shadow blocks' wide search (a pipeline constant,
// `ExactOptions::shadow_rounds`, 1 to `WIDE_ROUNDS`): the shadow pass is a
// single wave whose time is its longest chain of dependent steps, and each
// round is one more link (1: the first slice not clear, as the serial
// search's one round).
override EXACT_SHADOW_ROUNDS: u32 = 8u;

// Round 1's slices that are not clear (bit k of the 64: slice k).
var<workgroup> wide_mask: array<atomic<u32>, 2>;
// Round r's first sub-slice j that is not clear, as 64 - j (0: none).
var<workgroup> wide_first: array<atomic<u32>, WIDE_ROUNDS>;

// Bound k of 64 equal slices of [lo, hi]: bound 64 is hi itself, so
// neighbouring slices, and a slice and its sub-slices, share their bounds
// exactly.
fn wide_bound(lo: f32, hi: f32, k: u32) -> f32 {
    if (k >= WIDE_LANES) {
        return hi;
    }
    return lo + (hi - lo) * (f32(k) / f32(WIDE_LANES));
}

// [t0, t1] cut to where rays o + t d (o.z in [oz_lo, oz_hi], d.z in
// [dz_lo, dz_hi], t >= 0) may hold a solid point: not before the earliest t
// at which one may come down to 255 (less a relative margin: a start earlier
// than needed is still safe, the search tests from there), and no further
// than where every one is below -1 (every point at or below 0 is solid, so
// each has met the ground by then). Empty (x >= y) when none comes down to
// 255 before t1.
fn wide_range(oz_lo: f32, oz_hi: f32, dz_lo: f32, dz_hi: f32, t0: f32, t1: f32) -> vec2<f32> {
    var a = t0;
    var b = t1;
    if (oz_lo > MAX_ALTITUDE) {
        if (dz_lo >= 0.0) {
            return vec2<f32>(t1, t1);
        }
        a = max(a, (MAX_ALTITUDE - oz_lo) / dz_lo * (1.0 - WIDE_RANGE_MARGIN));
    }
    if (dz_hi < 0.0) {
        b = min(b, (-1.0 - oz_hi) / dz_hi * (1.0 + WIDE_RANGE_MARGIN));
    }
    return vec2<f32>(a, max(b, a));
}

// Whether no ray o + t d, o in the box (o_lo, o_hi), d in (d_lo, d_hi), is
// solid over [a, b] (0 <= a, b).
fn wide_clear(base: vec2<i32>, o_lo: vec3<f32>, o_hi: vec3<f32>, d_lo: vec3<f32>, d_hi: vec3<f32>, a: f32, b: f32) -> bool {
    let lo = min(o_lo + d_lo * a, o_lo + d_lo * b);
    let hi = max(o_hi + d_hi * a, o_hi + d_hi * b);
    return beam_clear(base, lo, hi);
}

// The least t in [ta, tb] at which a ray o + t d, o in the box (o_lo, o_hi)
// and d in (d_lo, d_hi), may be solid (tb when none may), searched by the
// workgroup's 64 invocations at once (call it from every invocation, `li`
// its index, in uniform control flow) in at most `rounds` rounds (and
// `WIDE_ROUNDS`). Twin: `Replay::wide_beam`.
//
// Why no such ray is solid before the start: for t >= 0 each coordinate of
// o + t d lies between o_lo + t d_lo and o_hi + t d_hi, which are affine in
// t, so over [a, b] every point lies in the union of the boxes at a and b
// (`wide_clear`; `beam_clear` then widens it by the rounding margin and
// compares its lowest altitude with the pyramid, as at the top). Round 1
// tests the 64 slices of [ta, tb]; each later round the 64 sub-slices of the
// first slice not clear and not yet refined. The start is the first
// sub-slice found not clear, or (rounds spent) the first slice not yet
// refined, or tb: every interval before it was found clear, and they leave
// no gap (`wide_bound`: slice k ends exactly where k + 1 begins, sub-slice 0
// begins at its slice's start and sub-slice 63 ends at its end; f32 rounding
// keeps the bounds in order, and a box is the same for [a, b] and [b, a]).
// Before ta nothing is solid (`wide_range`). Every value the rounds branch on
// is read with `workgroupUniformLoad`, so the loop and its barriers are
// uniform.
fn wide_search(base: vec2<i32>, o_lo: vec3<f32>, o_hi: vec3<f32>, d_lo: vec3<f32>, d_hi: vec3<f32>, ta: f32, tb: f32, li: u32, rounds: u32) -> f32 {
    if (!wide_clear(base, o_lo, o_hi, d_lo, d_hi, wide_bound(ta, tb, li), wide_bound(ta, tb, li + 1u))) {
        atomicOr(&wide_mask[li >> 5u], 1u << (li & 31u));
    }
    var mask = vec2<u32>(workgroupUniformLoad(&wide_mask[0]), workgroupUniformLoad(&wide_mask[1]));
    var round = 1u;
    // Bounded: each pass returns or clears one of the 64 bits of `mask`,
    // and the loop returns when none is left (and after WIDE_ROUNDS rounds).
    loop {
        if (all(mask == vec2<u32>(0u))) {
            return tb;
        }
        let c = select(32u + firstTrailingBit(mask.y), firstTrailingBit(mask.x), mask.x != 0u);
        let lo = wide_bound(ta, tb, c);
        let hi = wide_bound(ta, tb, c + 1u);
        if (round >= min(rounds, WIDE_ROUNDS)) {
            return lo;
        }
        if (!wide_clear(base, o_lo, o_hi, d_lo, d_hi, wide_bound(lo, hi, li), wide_bound(lo, hi, li + 1u))) {
            atomicMax(&wide_first[round], WIDE_LANES - li);
        }
        let first = workgroupUniformLoad(&wide_first[round]);
        if (first != 0u) {
            return wide_bound(lo, hi, WIDE_LANES - first);
        }
        round = round + 1u;
        // Slice c is clear after all: on to the next.
        if (c < 32u) {
            mask.x = mask.x & ~(1u << c);
        } else {
            mask.y = mask.y & ~(1u << (c - 32u));
        }
    }
    return tb;
}

// The wide search of the 8x8-pixel tile `group` (its march's workgroup):
// the corner pixels' ray directions boxed (every pixel's is a convex
// combination of theirs, as at the top), from the eye.
fn exact_wide_tile_start(group: vec2<u32>, li: u32) -> f32 {
    let d = beam_corner_rays(group);
    let d_lo = min(min(d[0], d[1]), min(d[2], d[3]));
    let d_hi = max(max(d[0], d[1]), max(d[2], d[3]));
    let eye = globals.eye.xyz;
    let focal = globals.eye.w;
    let base = exact_base(eye.xy);
    let o = vec3<f32>(eye.xy - vec2<f32>(base), eye.z);
    let range = wide_range(o.z, o.z, d_lo.z, d_hi.z, globals.forward.w / focal, globals.right.w / focal);
    return wide_search(base, o, o, d_lo, d_hi, range.x, range.y, li, WIDE_ROUNDS);
}

// The shadow block's first lane k that found its interval not clear, as
// 64 - k (0: none).
var<workgroup> beam_first: atomic<u32>;

// Where the rays of the 8x8-texel shadow block whose first texel is `first`
// start, searched by the block's 64 invocations at once (call it from every
// invocation of the workgroup, `li` its index): wide, `wide_search` over the
// box of the corner texels' rays' starts; serially, invocation k tests the k-th
// of 64 equal intervals of [0, span] of the box of the four corner texels'
// rays (parallel rays whose starts at altitude 255 are affine in the texel,
// so every ray of the block is a convex combination of theirs, as in the
// argument at the top), and the rays start at the first interval that is
// not clear.
fn exact_shadow_block_start(first: vec2<u32>, li: u32) -> f32 {
    if (!EXACT_BEAM) {
        return 0.0;
    }
    let far = BEAM_TILE - 1u;
    let r0 = exact_shadow_ray(first);
    let r1 = exact_shadow_ray(first + vec2<u32>(far, 0u));
    let r2 = exact_shadow_ray(first + vec2<u32>(0u, far));
    let r3 = exact_shadow_ray(first + vec2<u32>(far, far));
    let base = exact_base(r0.p.xy);
    let at = vec2<f32>(base);
    let o0 = vec3<f32>(r0.p.xy - at, r0.p.z);
    let o1 = vec3<f32>(r1.p.xy - at, r1.p.z);
    let o2 = vec3<f32>(r2.p.xy - at, r2.p.z);
    let o3 = vec3<f32>(r3.p.xy - at, r3.p.z);
    let d = globals.light_dir.xyz;
    if (EXACT_BEAM_SEARCH != BEAM_SERIAL) {
        let o_lo = min(min(o0, o1), min(o2, o3));
        let o_hi = max(max(o0, o1), max(o2, o3));
        return wide_search(base, o_lo, o_hi, d, d, 0.0, r0.span, li, EXACT_SHADOW_ROUNDS);
    }
    let lanes = f32(BEAM_TILE * BEAM_TILE);
    let a = beam_box(o0, o1, o2, o3, d, d, d, d, r0.span * (f32(li) / lanes));
    let b = beam_box(o0, o1, o2, o3, d, d, d, d, r0.span * (f32(li + 1u) / lanes));
    if (!beam_clear(base, min(a.lo, b.lo), max(a.hi, b.hi))) {
        atomicMax(&beam_first, BEAM_TILE * BEAM_TILE - li);
    }
    workgroupBarrier();
    let k = BEAM_TILE * BEAM_TILE - atomicLoad(&beam_first);
    return r0.span * (f32(k) / lanes);
}

// One invocation per 8x8-pixel tile: its rays' start, through the corner
// pixels' centres.
@compute @workgroup_size(8, 8, 1)
fn cs_exact_beam(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    let across = beam_tiles_across();
    let down = (size.y + BEAM_TILE - 1u) / BEAM_TILE;
    if (id.x >= across || id.y >= down) {
        return;
    }
    let d = beam_corner_rays(id.xy);
    let eye = globals.eye.xyz;
    let focal = globals.eye.w;
    let base = exact_base(eye.xy);
    let o = vec3<f32>(eye.xy - vec2<f32>(base), eye.z);
    exact_beams[id.y * across + id.x] = exact_beam(o, base, d[0], d[1], d[2], d[3], globals.forward.w / focal, globals.right.w / focal);
}

// The wide search as a pre-pass (`BEAM_WIDE_PASS`): one 8x8 workgroup per
// tile, dispatched tiles across by tiles down.
@compute @workgroup_size(8, 8, 1)
fn cs_exact_beam_wide(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    let t = exact_wide_tile_start(group.xy, li);
    if (li == 0u) {
        exact_beams[group.y * beam_tiles_across() + group.x] = t;
    }
}
