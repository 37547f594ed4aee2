//! Terrain colours: each type's palette ramp at a fixed light, as the
//! renderer's shading picks entries (a lit, mid-bright entry of the ramp).

use strata_level::World;

/// Where on a type's dark-to-light ramp the exported colour sits (the
/// renderer's `RAMP_FLOOR + (1 - RAMP_FLOOR) * light` at light 0.75).
const RAMP_POINT: f32 = 0.3 + 0.7 * 0.75;

/// RGBA8 colour of each terrain type.
pub fn type_colors(world: &World) -> [[u8; 4]; 8] {
    std::array::from_fn(|t| {
        let (b, e) = (
            f32::from(world.config.begin_colors[t]),
            f32::from(world.config.end_colors[t]),
        );
        let idx = (b + (e - b) * RAMP_POINT).round().clamp(0.0, 255.0) as usize;
        let [r, g, bl] = world.palette.colors[idx];
        [r, g, bl, 255]
    })
}
