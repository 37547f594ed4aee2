// The shared frame: bind group 0, seen by every method. Rust twin: `frame::Globals`
// and `frame::ShadingParams` (field order and sizes must match).

struct Globals {
    view_proj: mat4x4<f32>,
    // xyz eye position, w focal length in pixels
    eye: vec4<f32>,
    // xyz view axis, w near
    forward: vec4<f32>,
    // xyz camera `right` (the image x axis runs along -right), w far
    right: vec4<f32>,
    // xyz camera up
    up: vec4<f32>,
    // width, height in pixels, 1/width, 1/height
    screen: vec4<f32>,
    // xyz direction the light travels (unit, pointing down), w 1 = shadows on
    light_dir: vec4<f32>,
    // xyz a corner of the shadow map's plane (normal = light_dir), w texel size
    shadow_origin: vec4<f32>,
    // xyz shadow map u axis (unit), w shadow map side in texels
    shadow_u: vec4<f32>,
    // xyz shadow map v axis (unit), w depth bias in world units
    shadow_v: vec4<f32>,
    // rgb sky colour, w unused
    sky: vec4<f32>,
    // map width, map height (powers of two), log2 rows per texture layer,
    // added to the gap code before << 3 (1 original, 0 vange-rs)
    level: vec4<u32>,
    // x how many of shadow_cover apply (0: every shadow texel is cast)
    shadow_cover_count: vec4<u32>,
    // the shadow texels this frame casts: half-planes (nx, ny, d, 0) in texel
    // coordinates, inside when nx cx + ny cy + d <= 0 (`ShadowCover`)
    shadow_cover: array<vec4<f32>, 16>,
    // xyz the shadow map lattice's anchor on its plane, w the texel size
    // paged shadow rays take their level of detail from (`lod_texel`)
    shadow_anchor: vec4<f32>,
    // xy shadow texel (0, 0)'s index on the light's lattice, zw unused
    shadow_lattice: vec4<i32>,
}

struct ShadingParams {
    // the world's palette, rgb in 0..1
    palette: array<vec4<f32>, 256>,
    // per terrain type: x first palette index, y last palette index
    ranges: array<vec4<u32>, 8>,
}

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var<uniform> shading: ShadingParams;
// One texel per dual pair: (height even, meta even, height odd, meta odd);
// rows wrap across square-ish layers (see terrain.rs).
@group(0) @binding(2) var terrain: texture_2d_array<u32>;
// Distance along the light from the shadow plane to the first solid point.
@group(0) @binding(3) var shadow_map: texture_2d<f32>;

// Whether the shadow pass casts texel `ij` this frame: only texels a visible
// point can sample are (twin of `ShadowCover::covers`); the rest hold a miss.
fn shadow_texel_cast(ij: vec2<u32>) -> bool {
    let c = vec2<f32>(ij) + vec2<f32>(0.5);
    for (var k = 0u; k < globals.shadow_cover_count.x; k = k + 1u) {
        let plane = globals.shadow_cover[k];
        if (plane.x * c.x + plane.y * c.y + plane.z > 0.0) {
            return false;
        }
    }
    return true;
}

// Texel `ij`'s centre on the shadow map's plane, from its lattice index
// (twin of `ShadowFrame::texel_centre`): the same point in every frame with
// this texel size and plane, so a texel cast by an earlier frame holds what
// casting it now would store.
fn shadow_texel_centre(ij: vec2<u32>) -> vec3<f32> {
    let texel = globals.shadow_origin.w;
    let at = (vec2<f32>(globals.shadow_lattice.xy + vec2<i32>(ij)) + vec2<f32>(0.5)) * texel;
    return globals.shadow_anchor.xyz + globals.shadow_u.xyz * at.x + globals.shadow_v.xyz * at.y;
}

// Where the shadow map's texture stores texel `ij` (twin of
// `ShadowFrame::slot`): its lattice index wrapped to the map's side.
fn shadow_slot(ij: vec2<i32>) -> vec2<i32> {
    return (ij + globals.shadow_lattice.xy) & vec2<i32>(i32(globals.shadow_u.w) - 1);
}

// The shadow texel a slot of the texture holds this frame (`shadow_slot`'s
// inverse): for passes that run over the texture's texels.
fn shadow_texel_of_slot(slot: vec2<u32>) -> vec2<u32> {
    return vec2<u32>((vec2<i32>(slot) - globals.shadow_lattice.xy) & vec2<i32>(i32(globals.shadow_u.w) - 1));
}

// Unnormalised ray through the image point (px, py) in pixels from the top-left
// (a pixel centre is i + 0.5): the twin of `Camera::image_direction`. Its
// component along the view axis is the focal length, so view depth = t * focal.
fn camera_ray(px: f32, py: f32) -> vec3<f32> {
    let sx = px - globals.screen.x * 0.5;
    let sy = globals.screen.y * 0.5 - py;
    return globals.forward.xyz * globals.eye.w - globals.right.xyz * sx + globals.up.xyz * sy;
}
