// The occupancy pyramid as the voxel traversal reads it: the GPU twin of
// `strata_occupancy::layout` (8x8x8 Morton tiles, tiles z-fastest, one u32
// buffer with a level table). Bind group 1 of `voxel` and `voxel-compute`.

const VOXEL_MAX_LEVELS: u32 = 16u;

struct VoxelLevel {
    // cells x, y, z (powers of two); w: first word of the level
    dims: vec4<u32>,
    // tiles x, y, z; w unused
    tiles: vec4<u32>,
}

struct VoxelParams {
    // x: step budget, y: level count, z and w unused
    config: vec4<u32>,
    // level-0 voxel size: x, y texels, z altitude units; w unused
    voxel: vec4<u32>,
    levels: array<VoxelLevel, VOXEL_MAX_LEVELS>,
}

@group(1) @binding(0) var<uniform> vparams: VoxelParams;
@group(1) @binding(1) var<storage, read> occupancy: array<u32>;

// Spread the low 3 bits of v to bits 0, 3, 6.
fn voxel_spread3(v: u32) -> u32 {
    return (v & 1u) | ((v & 2u) << 2u) | ((v & 4u) << 4u);
}

fn voxel_morton(l: vec3<u32>) -> u32 {
    return voxel_spread3(l.x) | (voxel_spread3(l.y) << 1u) | (voxel_spread3(l.z) << 2u);
}

// Is cell `c` of level `lod` maybe solid? x and y wrap (the map is a torus);
// below the grid is solid, above it empty.
fn voxel_occupied(lod: u32, c: vec3<i32>) -> bool {
    let info = vparams.levels[lod];
    if (c.z < 0) {
        return true;
    }
    if (u32(c.z) >= info.dims.z) {
        return false;
    }
    // u32(i32) reinterprets the bits: masking wraps negatives too.
    let x = u32(c.x) & (info.dims.x - 1u);
    let y = u32(c.y) & (info.dims.y - 1u);
    let z = u32(c.z);
    let tile = ((y >> 3u) * info.tiles.x + (x >> 3u)) * info.tiles.z + (z >> 3u);
    let m = voxel_morton(vec3<u32>(x & 7u, y & 7u, z & 7u));
    let word = occupancy[info.dims.w + tile * 16u + (m >> 5u)];
    return ((word >> (m & 31u)) & 1u) != 0u;
}

// Cell size of level `lod` in world units.
fn voxel_cell_size(lod: u32) -> vec3<f32> {
    return vec3<f32>(vparams.voxel.xyz << vec3<u32>(lod));
}
