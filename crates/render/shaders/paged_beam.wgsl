// Paged terrain's stand-in for `ray_exact_beam.wgsl`: no beam pre-pass (its
// finer levels live per page, read with feedback), so every camera ray starts
// at the near plane and every shadow ray at altitude 255.
#include "ray_exact_core.wgsl"

fn exact_tile_start(id: vec2<u32>) -> f32 {
    return -EXACT_BIG;
}

fn exact_group_start(group: vec2<u32>, li: u32) -> f32 {
    return -EXACT_BIG;
}

fn exact_tile_level() -> u32 {
    return EXACT_START_LEVEL;
}

fn exact_shadow_block_start(first: vec2<u32>, li: u32) -> f32 {
    return 0.0;
}
