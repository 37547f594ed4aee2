// Embedding (`composite_split.rs`): write Strata's colour straight into the
// caller's colour texture as a storage image, one thread per pixel. On the
// H100 this moves a 1280x800 frame in 0.02 ms where a texture copy or a
// full-screen pass takes 0.08 ms or more (its graphics path is narrow).
// The storage format is `rgba8unorm` here; the renderer swaps the word for
// `rgba16float` targets (a WGSL binding names its format).

@group(0) @binding(0) var color_in: texture_2d<f32>;
@group(0) @binding(1) var color_out: texture_storage_2d<rgba8unorm, write>;
// sRGB byte k -> linear light (as `composite.wgsl`'s table, flat).
@group(0) @binding(2) var<storage, read> srgb_to_linear: array<f32, 256>;

// The bytes Strata's Rgba8Unorm target holds, as they are (a UNORM target).
@compute @workgroup_size(8, 8)
fn cs_color(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(color_in);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    textureStore(color_out, id.xy, textureLoad(color_in, id.xy, 0));
}

// Linear light, for a float target (what `fs_composite_linear` writes).
@compute @workgroup_size(8, 8)
fn cs_color_linear(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(color_in);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let c = textureLoad(color_in, id.xy, 0);
    let k = vec3<u32>(round(c.rgb * 255.0));
    let linear = vec3<f32>(srgb_to_linear[k.r], srgb_to_linear[k.g], srgb_to_linear[k.b]);
    textureStore(color_out, id.xy, vec4<f32>(linear, c.a));
}
