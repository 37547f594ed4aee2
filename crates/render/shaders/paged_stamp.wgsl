// The frame stamp `paged.wgsl` reads as `xparams.config.z`, for paged shaders
// without the exact march's parameters (`ray_exact_core.wgsl`): the paged
// mesh's passes (`methods/mesh/paged.rs`).
struct PagedStamp {
    // z: the frame's stamp, never 0
    config: vec4<u32>,
}

@group(1) @binding(12) var<uniform> xparams: PagedStamp;
