//! The map: a top-down picture of the whole level (one pixel per square of
//! texels, the top surface's palette colour), the eye and its heading on it,
//! and a click to fly there. A Vangers world is 16384 texels long; flying
//! across it takes minutes, the map a click.

use glam::Vec2;
use strata_level::Level;
use strata_render::TerrainColors;

/// The picture's largest sides, pixels (the level's aspect is kept).
const MAX_WIDTH: u32 = 256;
const MAX_HEIGHT: u32 = 2048;

/// The level seen from above, downsampled.
pub struct Minimap {
    /// Texels per pixel along each axis (a power of two).
    pub scale: u32,
    pub width: u32,
    pub height: u32,
    /// RGBA8, row-major.
    pub rgba: Vec<u8>,
}

impl Minimap {
    /// Sample each pixel's centre column: its top's terrain colour, from the
    /// type's palette ramp by height (as the renderers' base colour).
    pub fn new(level: &Level, colors: &TerrainColors) -> Self {
        let (lw, lh) = (level.width(), level.height());
        let mut scale = 1;
        while lw / scale > MAX_WIDTH || lh / scale > MAX_HEIGHT {
            scale *= 2;
        }
        let (width, height) = ((lw / scale).max(1), (lh / scale).max(1));
        let mut rgba = Vec::with_capacity((width * height * 4) as usize);
        for py in 0..height {
            for px in 0..width {
                let x = i64::from(px * scale + scale / 2);
                let y = i64::from(py * scale + scale / 2);
                let c = level.column(x, y);
                let kind = if c.dual { c.upper_type } else { c.lower_type };
                let t = usize::from(kind & 7);
                let (begin, end) = (colors.begin[t], colors.end[t]);
                let span = f32::from(end.saturating_sub(begin));
                let index = begin as usize + (span * f32::from(c.top()) / 255.0).round() as usize;
                let [r, g, b] = colors.palette[index.min(255)];
                rgba.extend_from_slice(&[r, g, b, 255]);
            }
        }
        Minimap {
            scale,
            width,
            height,
            rgba,
        }
    }

    /// Map pixel coordinates (fractions allowed) of a world position.
    pub fn to_map(&self, world: Vec2) -> Vec2 {
        world / self.scale as f32
    }

    /// The world position at map pixel coordinates.
    pub fn to_world(&self, map: Vec2) -> Vec2 {
        map * self.scale as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_level_fits_and_coordinates_round_trip() {
        let level = Level::flat(2048, 16384, 100, 3).unwrap();
        let map = Minimap::new(&level, &TerrainColors::test_ramps());
        assert_eq!((map.scale, map.width, map.height), (8, 256, 2048));
        assert_eq!(map.rgba.len(), 256 * 2048 * 4);
        let p = Vec2::new(1000.0, 9000.0);
        assert_eq!(map.to_world(map.to_map(p)), p);
        // Every pixel has type 3's colour at height 100.
        let colors = TerrainColors::test_ramps();
        let want = colors.palette[3 * 32 + (31.0f32 * 100.0 / 255.0).round() as usize];
        assert_eq!(&map.rgba[..3], &want);
        let small = Minimap::new(&Level::flat(256, 256, 0, 0).unwrap(), &colors);
        assert_eq!((small.scale, small.width, small.height), (1, 256, 256));
    }
}
