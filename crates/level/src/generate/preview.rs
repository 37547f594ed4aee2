//! A top-down shaded picture of part of a level (no image dependency: RGB
//! bytes). Height picks a colour in the terrain type's palette range, a
//! hillshade and cast shadows from the north-west show the relief, and
//! slabs get a bluish tint so bridges and roofs stand out.

use crate::{Level, Palette, WorldConfig};

/// A rectangle of the map to draw, in texels (wraps around the map).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// Left column, texels (any value; wraps).
    pub x: i64,
    /// Top row, texels (any value; wraps).
    pub y: i64,
    /// Columns, pixels of the picture.
    pub width: u32,
    /// Rows, pixels of the picture.
    pub height: u32,
}

/// RGB bytes, `region.width * region.height * 3`, row-major.
pub fn shade(level: &Level, palette: &Palette, config: &WorldConfig, region: Region) -> Vec<u8> {
    use rayon::prelude::*;
    let w = region.width as usize;
    let mut out = vec![0u8; w * region.height as usize * 3];
    let top = |x: i64, y: i64| f32::from(level.column(x, y).top());
    out.par_chunks_mut(w * 3).enumerate().for_each(|(j, row)| {
        let y = region.y + j as i64;
        for (i, px) in row.chunks_exact_mut(3).enumerate() {
            let x = region.x + i as i64;
            let c = level.column(x, y);
            let h = f32::from(c.top());
            let ty = (if c.dual { c.upper_type } else { c.lower_type } & 7) as usize;
            let (b, e) = (config.begin_colors[ty], config.end_colors[ty]);
            let span = f32::from(e.saturating_sub(b));
            let index = b as usize + (h / 255.0 * span).round() as usize;
            let rgb = palette.colors[index.min(255)];
            // Light from the north-west (up-left in the picture).
            let gx = top(x + 1, y) - top(x - 1, y);
            let gy = top(x, y + 1) - top(x, y - 1);
            let mut light = (1.0 + (gx + gy) * -0.06).clamp(0.35, 1.5);
            for d in 1..48 {
                if top(x - d, y - d) > h + d as f32 * 1.2 {
                    light *= 0.55;
                    break;
                }
            }
            for k in 0..3 {
                let mut v = f32::from(rgb[k]) * light;
                if c.dual {
                    v = v * 0.8 + [10.0, 30.0, 60.0][k];
                }
                px[k] = v.clamp(0.0, 255.0) as u8;
            }
        }
    });
    out
}
