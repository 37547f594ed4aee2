// Move the exact march's R32Float depth image into the shared depth target
// without a fragment shader: one point per pixel at its own depth, drawn by a
// depth-only pipeline (sky pixels are dropped: the pass cleared depth to 1).
// Compared with the full-screen `fs_depth_blit` (frag_depth) on the GPU
// machine, whose graphics pipeline runs on few SMs.

@group(0) @binding(0) var depth_in: texture_2d<f32>;

@vertex
fn vs_depth_point(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let size = textureDimensions(depth_in);
    let xy = vec2<u32>(i % size.x, i / size.x);
    let z = textureLoad(depth_in, xy, 0).r;
    let ndc = (vec2<f32>(xy) + 0.5) / vec2<f32>(size) * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    // Outside the clip volume (culled) where there is nothing to write.
    let x = select(ndc.x, 4.0, z >= 1.0);
    return vec4<f32>(x, ndc.y, z, 1.0);
}
