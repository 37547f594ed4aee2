// `mesh`'s colour step, one module for both of its paths: the fragment path
// (`fs_mesh` in `mesh.wgsl`, where the adapter has no compute) and the
// deferred one (the raster pass writes only depth and `mesh_gbuffer`'s two
// words a pixel; `mesh_deferred.wgsl` colours every pixel in one compute
// pass). Both run `mesh_pixel_colour` on the same packed words, so they draw
// the same picture.
#include "frame.wgsl"
#include "surface.wgsl"
#include "shading.wgsl"
#include "column_segment.wgsl"

struct MeshParams {
    // x stride (chunk side + 1), y positions per kind ((side_x + 1) * (side_y + 1)),
    // z 1: the gradient-normal diagnostic (`mesh_gradient_normal`), w 1: every
    // sample at its texel's centre (`mesh_texel_centres`; `wall_shift` in mesh.wgsl)
    grid: vec4<u32>,
}

@group(1) @binding(0) var<uniform> mesh: MeshParams;

const KIND_FLOOR: u32 = 0u;
const KIND_TOP: u32 = 1u;

// Where the eye's ray through `p` meets the height field's own surface near
// `p`: the TIN lies up to its fit error above or below that surface, so the
// point under `p` is not what the reference sees there (off-axis, the true
// hit is texels away), and between samples a wall's ramp lies half over the
// low column, up to the wall's height above its floor (from above, that
// floor is what shows). The exact segment test (`first_entry`, shared with
// ray and ray-exact) walks the ray from a few texels before `p` to several
// past it; the first entry names the column and interval the pixel takes its
// colour from, and the point it is shaded at. The walk costs one decode per
// texel crossed, so the window is set in texels across (a near-vertical ray
// may run far: down a wall) and capped along the ray. The mesh's geometry
// and depth are unchanged; a miss keeps the column under the TIN.
const SURFACE_BACK_TEXELS: f32 = 3.0;
const SURFACE_AHEAD_TEXELS: f32 = 8.0;
const SURFACE_MAX_ALONG: f32 = 64.0;
const SURFACE_MAX_TEXELS: u32 = 16u;

struct ColourSource {
    column: vec2<i32>,
    kind: u32,
    // whether the walk entered the surface (`t` is then that entry along
    // the unit ray from the eye)
    exact: bool,
    t: f32,
}

// The column and interval the pixel at TIN point `p` (flat normal `n`, of a
// triangle of vertex kind `vkind`) is coloured from.
fn colour_source(p: vec3<f32>, n: vec3<f32>, vkind: u32) -> ColourSource {
    let eye = globals.eye.xyz;
    let dist = length(p - eye);
    let d = (p - eye) / dist;
    let across = max(length(d.xy), 1e-4);
    let back = min(SURFACE_BACK_TEXELS / across, SURFACE_MAX_ALONG);
    let ahead = min(SURFACE_AHEAD_TEXELS / across, SURFACE_MAX_ALONG);
    let a = max(dist - back, 0.0);
    let h = first_entry(eye, d, a, dist + ahead, SURFACE_MAX_TEXELS);
    var src: ColourSource;
    src.exact = false;
    src.t = dist;
    if (h.hit && h.t > a) {
        src.column = h.column;
        let c = decode_column(h.column.x, h.column.y);
        src.kind = surface_kind(c, eye.z + d.z * h.t, d.z);
        src.exact = true;
        src.t = h.t;
        return src;
    }
    // No surface entered in the window (the TIN bridges a gap, or the window
    // starts inside the solid): the column under the TIN point, walls half a
    // texel inwards (a steep ramp between two texel centres lies half over
    // the low column; its colour belongs to the high one, inside the solid).
    var at = p.xy;
    let steep = length(n.xy);
    if (steep > 0.7) {
        at -= n.xy / steep * 0.5;
    }
    src.column = vec2<i32>(floor(at));
    src.kind = SURFACE_FLOOR;
    if (vkind != KIND_FLOOR) {
        // Slab triangles: tops and walls take the slab top's light, faces
        // looking down are the cave ceiling.
        src.kind = select(SURFACE_SLAB_TOP, SURFACE_CEILING, n.z < -0.5);
    }
    return src;
}

// What the colour step needs of a covered pixel, packed in two words (the
// deferred path's G-buffer, `Rg32Uint`): x the bits of `t`, the TIN point's
// parameter along `camera_ray` through the pixel centre (> 0: 0 is "no
// triangle"); y the flat normal, octahedral in 15 + 15 bits, and the
// triangle's vertex kind in the top 2.
const OCT_SCALE: f32 = 32767.0;

fn mesh_pack(t: f32, n: vec3<f32>, kind: u32) -> vec2<u32> {
    var e = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z < 0.0) {
        let flip = select(vec2<f32>(-1.0), vec2<f32>(1.0), e >= vec2<f32>(0.0));
        e = (vec2<f32>(1.0) - abs(e.yx)) * flip;
    }
    let q = vec2<u32>(round(clamp(e * 0.5 + vec2<f32>(0.5), vec2<f32>(0.0), vec2<f32>(1.0)) * OCT_SCALE));
    return vec2<u32>(bitcast<u32>(t), q.x | (q.y << 15u) | (min(kind, 3u) << 30u));
}

fn mesh_unpack_normal(w: u32) -> vec3<f32> {
    let q = vec2<f32>(f32(w & 0x7fffu), f32((w >> 15u) & 0x7fffu));
    let e = q / OCT_SCALE * 2.0 - vec2<f32>(1.0);
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) {
        let flip = select(vec2<f32>(-1.0), vec2<f32>(1.0), e >= vec2<f32>(0.0));
        n = vec3<f32>((vec2<f32>(1.0) - abs(e.yx)) * flip, n.z);
    }
    return normalize(n);
}

// The packed words of a fragment at world point `p` of a triangle of vertex
// kind `kind` (the fragment stage: the flat normal from `p`'s derivatives).
fn mesh_gbuffer(p: vec3<f32>, kind: u32) -> vec2<u32> {
    // The triangle's flat geometric normal: world position is linear over
    // the triangle, so its screen derivatives span the triangle's plane.
    var n = normalize(cross(dpdx(p), dpdy(p)));
    let to_eye = globals.eye.xyz - p;
    if (dot(n, to_eye) < 0.0) {
        // Whichever side is seen is the outside of the solid.
        n = -n;
    }
    // `camera_ray`'s component along the view axis is the focal length.
    let t = dot(p - globals.eye.xyz, globals.forward.xyz) / globals.eye.w;
    return mesh_pack(max(t, 1e-30), n, kind);
}

// The colour of the covered pixel whose centre is `pixel` from its packed
// words. Where the walk enters the surface, the pixel is shaded at that entry
// with the height field's normal, as `ray-exact` shades its hit; elsewhere at
// the TIN point with the flat normal (the gradient normal under the
// diagnostic).
fn mesh_pixel_colour(pixel: vec2<f32>, g: vec2<u32>) -> vec3<f32> {
    let p = globals.eye.xyz + camera_ray(pixel.x, pixel.y) * bitcast<f32>(g.x);
    var n = mesh_unpack_normal(g.y);
    let src = colour_source(p, n, g.y >> 30u);
    if (src.exact) {
        let d = normalize(p - globals.eye.xyz);
        return shade_column(globals.eye.xyz + d * src.t, src.column.x, src.column.y, d);
    }
    let c = decode_column(src.column.x, src.column.y);
    if (mesh.grid.z != 0u) {
        // Diagnostic: the height-field normal the other methods shade with.
        let here = select(c.high, c.mid, src.kind == SURFACE_CEILING);
        n = surface_normal(src.column.x, src.column.y, src.kind, here);
    }
    return shade_with_normal(p, c, src.kind, n);
}
