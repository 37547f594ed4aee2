//! Our own palette and `world.ini` for generated worlds: eight terrain colour
//! ranges at Fostral's indices, each a dark-to-light ramp of one hue.

use super::GenerateError;
use crate::{Palette, WorldConfig};

/// First palette index of each terrain type (as Fostral's `world.ini`).
pub const BEGIN_COLORS: [u8; 8] = [1, 32, 64, 72, 88, 104, 112, 120];
/// Last palette index of each terrain type.
pub const END_COLORS: [u8; 8] = [31, 63, 71, 87, 103, 111, 119, 127];

/// Darkest and lightest colour of each terrain type: water, olive ground,
/// brown earth, grey road, sand, rust, dark green, pale metal.
const RAMPS: [([u8; 3], [u8; 3]); 8] = [
    ([8, 16, 40], [72, 112, 168]),
    ([36, 40, 24], [176, 184, 132]),
    ([40, 28, 20], [168, 136, 100]),
    ([40, 40, 44], [184, 184, 188]),
    ([60, 52, 32], [228, 208, 156]),
    ([48, 20, 16], [200, 108, 80]),
    ([16, 32, 20], [100, 152, 96]),
    ([52, 56, 64], [224, 232, 240]),
];

/// The generated worlds' palette. Values are multiples of 4 so they survive
/// the file's 6-bit storage unchanged.
pub fn palette() -> Palette {
    let mut colors = [[0u8; 3]; 256];
    for (i, c) in colors.iter_mut().enumerate() {
        // Outside the terrain ranges (object colours in the game): a grey ramp.
        let g = (i as u32 * 252 / 255) as u8 & !3;
        *c = [g, g, g];
    }
    for ty in 0..8 {
        let (b, e) = (BEGIN_COLORS[ty] as usize, END_COLORS[ty] as usize);
        let (lo, hi) = RAMPS[ty];
        for (i, color) in colors.iter_mut().enumerate().take(e + 1).skip(b) {
            let t = (i - b) as f32 / (e - b).max(1) as f32;
            for k in 0..3 {
                let v = f32::from(lo[k]) + t * (f32::from(hi[k]) - f32::from(lo[k]));
                color[k] = (v.round() as u8).min(252) & !3;
            }
        }
    }
    colors[0] = [0, 0, 0];
    Palette { colors }
}

/// `world.ini` of a generated world of the given size.
pub fn world_config(width: u32, height: u32) -> Result<WorldConfig, GenerateError> {
    super::check_size(width, height)?;
    Ok(config_of(width, height))
}

/// `world.ini` of a generated world of a size checked by the caller (a
/// store's may exceed what a Vangers world directory allows).
pub(crate) fn config_of(width: u32, height: u32) -> WorldConfig {
    WorldConfig {
        map_power_x: width.trailing_zeros(),
        map_power_y: height.trailing_zeros(),
        compressed: true,
        file_name: "output".into(),
        palette_file: "strata.pal".into(),
        begin_colors: BEGIN_COLORS,
        end_colors: END_COLORS,
        ..WorldConfig::default()
    }
}
