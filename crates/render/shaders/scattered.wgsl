// `scattered` (§3.5): clear the screen buffer, then scatter point samples of
// a camera-aligned footprint grid into it with a 32-bit atomicMin of
// (24-bit depth << 8 | 8-bit info). Rust twin of `ScatterParams`:
// `methods::scattered::ScatterParams`. The resolve is `scattered_resolve.wgsl`.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"

struct ScatterParams {
    // xy: the horizontal view heading `flat`, zw: `right` (both unit, z = 0)
    axes: vec4<f32>,
    // xy: the eye; z: warp scale and clearance h (texels); w: vertical
    // samples per pixel of projected height
    origin: vec4<f32>,
    // x, y: asinh(a / h) of the footprint's nearest and farthest distance a;
    // z: columns a row needs per unit of its warped width
    warp: vec4<f32>,
    // rows (along), columns (across), hull vertices, vertical samples per
    // interval at most
    grid: vec4<u32>,
    // The footprint polygon in (a along flat, c along right) from the eye,
    // two vertices per entry, convex, in order.
    hull: array<vec4<f32>, 8>,
}

@group(1) @binding(0) var<uniform> params: ScatterParams;
@group(1) @binding(1) var<storage, read_write> screen_buf: array<atomic<u32>>;

const EMPTY: u32 = 0xFFFFFFFFu;
const DEPTH_MAX: u32 = 0xFFFFFEu;
const WORKGROUP: u32 = 64u;

@compute @workgroup_size(8, 8, 1)
fn cs_clear(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(globals.screen.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    atomicStore(&screen_buf[id.y * size.x + id.x], EMPTY);
}

fn hull_vertex(i: u32) -> vec2<f32> {
    let v = params.hull[i >> 1u];
    return select(v.xy, v.zw, (i & 1u) == 1u);
}

// The across range [c_lo, c_hi] of the footprint polygon at distance a
// (empty when x > y).
fn row_range(a: f32) -> vec2<f32> {
    var r = vec2<f32>(1e30, -1e30);
    let n = params.grid.z;
    for (var i = 0u; i < n; i++) {
        let p = hull_vertex(i);
        let q = hull_vertex(select(i + 1u, 0u, i + 1u == n));
        if (a < min(p.x, q.x) || a > max(p.x, q.x)) {
            continue;
        }
        var c = p.y;
        if (q.x != p.x) {
            c = mix(p.y, q.y, (a - p.x) / (q.x - p.x));
        }
        r = vec2<f32>(min(r.x, c), max(r.y, c));
    }
    return r;
}

// Clip [lo, hi] so that every z in it projects inside the image and between
// the near and far planes: each clip-space bound is linear in z
// (clip = base + z * dz).
fn clip_altitudes(base: vec4<f32>, dz: vec4<f32>, lo: f32, hi: f32) -> vec2<f32> {
    // Each pair (alpha, beta) says alpha + beta z >= 0.
    let alpha = array<f32, 6>(base.w + base.x, base.w - base.x, base.w + base.y,
        base.w - base.y, base.z, base.w - base.z);
    let beta = array<f32, 6>(dz.w + dz.x, dz.w - dz.x, dz.w + dz.y,
        dz.w - dz.y, dz.z, dz.w - dz.z);
    var r = vec2<f32>(lo, hi);
    for (var k = 0u; k < 6u; k++) {
        let a = alpha[k];
        let b = beta[k];
        if (abs(b) < 1e-12) {
            if (a < 0.0) {
                return vec2<f32>(1.0, 0.0);
            }
        } else if (b > 0.0) {
            r.x = max(r.x, -a / b);
        } else {
            r.y = min(r.y, -a / b);
        }
    }
    return r;
}

fn scatter(clip: vec4<f32>, info: u32) {
    let size = vec2<u32>(globals.screen.xy);
    let ndc = clip.xyz / clip.w;
    let px = (ndc.x * 0.5 + 0.5) * globals.screen.x;
    let py = (0.5 - ndc.y * 0.5) * globals.screen.y;
    // Clipping keeps points inside; the clamp only guards the right/bottom edge.
    let ij = min(vec2<u32>(max(vec2<f32>(px, py), vec2<f32>(0.0))), size - 1u);
    let depth = u32(clamp(ndc.z, 0.0, 1.0) * 16777215.0);
    let packed = (min(depth, DEPTH_MAX) << 8u) | info;
    atomicMin(&screen_buf[ij.y * size.x + ij.x], packed);
}

// Pixels of screen per unit of altitude at clip point p of a vertical line
// (clip = base + z * dz).
fn pixel_rate(p: vec4<f32>, dz: vec4<f32>) -> f32 {
    let d = (dz.xy * p.w - p.xy * dz.w) / (p.w * p.w);
    return length(d * globals.screen.xy * 0.5);
}

// Walk the solid interval [lo, hi] of column `c` (already clipped to the part
// that projects into the view) from the top down, each step 1 / Z pixels of
// projected height at the point. Every point is scattered, hidden ones
// included: culling points behind the neighbours' faces was tried and left
// rows of holes in near walls and broke cave views, which the stacked hidden
// points had been filling.
fn walk(base: vec4<f32>, dz: vec4<f32>, c: Column, lo: f32, hi: f32) {
    if (lo > hi) {
        return;
    }
    let per_px = params.origin.w;
    var z = hi;
    for (var k = 0u; k < params.grid.w; k++) {
        let p = base + dz * z;
        let kind = surface_kind(c, z, z - globals.eye.z);
        let t = select(c.upper_type, c.lower_type, kind == SURFACE_FLOOR);
        scatter(p, t | (kind << 3u));
        if (z <= lo) {
            break;
        }
        // The last point lands on lo exactly.
        z = max(z - 1.0 / (per_px * max(pixel_rate(p, dz), 1e-4)), lo);
    }
}

@compute @workgroup_size(64, 1, 1)
fn cs_scatter(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let rows = params.grid.x;
    let cols = params.grid.y;
    // Dispatches are split in 2D to stay within the per-dimension limit.
    let linear = (wid.y * groups.x + wid.x) * WORKGROUP + lid;
    if (linear >= rows * cols) {
        return;
    }
    let row = linear / cols;
    let col = linear % cols;
    // Rows are uniform in asinh(a / h): dense within ~h of the eye,
    // logarithmic (like perspective) beyond.
    let h = params.origin.z;
    let s = mix(params.warp.x, params.warp.y, (f32(row) + 0.5) / f32(rows));
    let a = h * sinh(s);
    let range = row_range(a);
    if (range.x > range.y) {
        return;
    }
    // Columns are uniform in asinh(c / d), d the row's least distance (a
    // column at c is at least sqrt(c^2 + d^2) away); a row that needs fewer
    // than `cols` keeps every 2^k-th.
    let d = sqrt(a * a + h * h);
    let u = vec2<f32>(asinh(range.x / d), asinh(range.y / d));
    let need = params.warp.z * (u.y - u.x);
    let ratio = f32(cols) / max(need, 1e-6);
    var k = 1u;
    if (ratio >= 2.0) {
        k = 1u << min(u32(floor(log2(ratio))), 30u);
        if ((col & (k - 1u)) != 0u) {
            return;
        }
    }
    let across = d * sinh(mix(u.x, u.y, (f32(col) + 0.5) / f32(cols)));
    let xy = params.origin.xy + params.axes.xy * a + params.axes.zw * across;
    let vp = globals.view_proj;
    let base = vp[0] * xy.x + vp[1] * xy.y + vp[3];
    let dz = vp[2];
    // The altitudes of the whole column that project into the view: none,
    // and the texture is never read.
    let r = clip_altitudes(base, dz, 0.0, 256.0);
    if (r.x > r.y) {
        return;
    }
    let c = decode_column(i32(floor(xy.x)), i32(floor(xy.y)));
    // The floor below every neighbour sample's floor (the next sample along
    // and across, both ways; within one texel, the same column) is hidden
    // behind them, so only samples next to a texel's edge walk its sides: the walk
    // stops half a unit below it. (Also walking the strip a ray over the
    // nearer neighbour could reach, as a margin for grazing views, changed no
    // coverage and cost a third more points at -60 degrees.)
    let da = d * (params.warp.y - params.warp.x) / f32(rows);
    let dc = sqrt(across * across + d * d) * (u.y - u.x) * f32(k) / f32(cols);
    let fa = params.axes.xy * da;
    let fc = params.axes.zw * dc;
    // The slab's sides are hidden, likewise, where every neighbour is solid:
    // `hid`, the intersection of each neighbour's slab (or, for a single-level
    // neighbour, everything up to its floor's top).
    var cover = c.low;
    var hid = vec2<f32>(-1e9, 1e9);
    for (var n = 0u; n < 4u; n++) {
        let off = select(select(-fc, fc, n == 2u), select(-fa, fa, n == 0u), n < 2u);
        let q = floor(xy + off);
        let nc = decode_column(i32(q.x), i32(q.y));
        cover = min(cover, nc.low);
        let hn = select(vec2<f32>(-1e9, nc.low), vec2<f32>(nc.mid, nc.high), nc.dual);
        hid = vec2<f32>(max(hid.x, hn.x), min(hid.y, hn.y));
    }
    let bottom = cover - 0.5;
    let top = min(c.low, r.y);
    walk(base, dz, c, min(max(bottom, r.x), top), top);
    if (c.dual) {
        let lo = max(c.mid, r.x);
        let hi = min(c.high, r.y);
        // Walk down from the top to the hidden core and from the core to the
        // underside.
        let core_top = hid.y - 0.5;
        let core_bottom = hid.x + 0.5;
        if (core_bottom < core_top) {
            walk(base, dz, c, min(max(core_top, lo), hi), hi);
            walk(base, dz, c, lo, max(min(core_bottom, hi), lo));
        } else {
            walk(base, dz, c, lo, hi);
        }
    }
}
