//! The map: a top-down picture of the whole level (one pixel per square of
//! texels, the top surface's palette colour), the eye and its heading on it,
//! and a click to fly there. A Vangers world is 16384 texels long; flying
//! across it takes minutes, the map a click.

use glam::Vec2;
use strata_level::{DirtyRect, Level};
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
    /// The whole level's map.
    pub fn new(level: &Level, colors: &TerrainColors) -> Self {
        let (lw, lh) = (level.width(), level.height());
        let mut scale = 1;
        while lw / scale > MAX_WIDTH || lh / scale > MAX_HEIGHT {
            scale *= 2;
        }
        let (width, height) = ((lw / scale).max(1), (lh / scale).max(1));
        let mut map = Minimap {
            scale,
            width,
            height,
            rgba: vec![0; (width * height * 4) as usize],
        };
        map.paint(level, colors, [0, 0, width, height]);
        map
    }

    /// Repaint the pixels over the texels in `rects` (after an edit); the
    /// map-pixel rectangles `[x, y, width, height]` that changed.
    pub fn update(
        &mut self,
        level: &Level,
        colors: &TerrainColors,
        rects: &[DirtyRect],
    ) -> Vec<[u32; 4]> {
        let mut changed = Vec::new();
        for r in rects {
            let x0 = r.x / self.scale;
            let y0 = r.y / self.scale;
            let x1 = (r.x + r.width).div_ceil(self.scale).min(self.width);
            let y1 = (r.y + r.height).div_ceil(self.scale).min(self.height);
            if x1 > x0 && y1 > y0 {
                let region = [x0, y0, x1 - x0, y1 - y0];
                self.paint(level, colors, region);
                changed.push(region);
            }
        }
        changed
    }

    /// The RGBA8 pixels of `[x, y, width, height]`, row-major.
    pub fn region(&self, [x, y, w, h]: [u32; 4]) -> Vec<u8> {
        let mut out = Vec::with_capacity((w * h * 4) as usize);
        for row in y..y + h {
            let start = ((row * self.width + x) * 4) as usize;
            out.extend_from_slice(&self.rgba[start..start + (w * 4) as usize]);
        }
        out
    }

    /// Sample each pixel's centre column: its top's terrain colour, from the
    /// type's palette ramp by height (as the renderers' base colour).
    fn paint(&mut self, level: &Level, colors: &TerrainColors, [x0, y0, w, h]: [u32; 4]) {
        let scale = self.scale;
        for py in y0..y0 + h {
            for px in x0..x0 + w {
                let x = i64::from(px * scale + scale / 2);
                let y = i64::from(py * scale + scale / 2);
                let c = level.column(x, y);
                let kind = if c.dual { c.upper_type } else { c.lower_type };
                let t = usize::from(kind & 7);
                let (begin, end) = (colors.begin[t], colors.end[t]);
                let span = f32::from(end.saturating_sub(begin));
                let index = begin as usize + (span * f32::from(c.top()) / 255.0).round() as usize;
                let [r, g, b] = colors.palette[index.min(255)];
                let at = ((py * self.width + px) * 4) as usize;
                self.rgba[at..at + 4].copy_from_slice(&[r, g, b, 255]);
            }
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

    #[test]
    fn an_edit_repaints_only_its_pixels_to_what_a_new_map_shows() {
        let colors = TerrainColors::test_ramps();
        let mut level = Level::flat(2048, 4096, 100, 3).unwrap();
        let mut map = Minimap::new(&level, &colors);
        let site = strata_level::EditSite {
            centre_x: 2040,
            centre_y: 5,
            radius: 30,
            depth: 60.0,
            ..strata_level::EditSite::fostral()
        };
        let rects = strata_level::edit::crater(&mut level, &site);
        let changed = map.update(&level, &colors, &rects);
        assert_eq!(changed.len(), rects.len(), "the crater wraps the corner");
        let fresh = Minimap::new(&level, &colors);
        assert!(map.rgba == fresh.rgba);
        let [x, y, w, h] = changed[0];
        assert_eq!(map.region(changed[0]).len(), (w * h * 4) as usize);
        assert!(x + w <= map.width && y + h <= map.height);
    }
}
