//! The side-by-side frame: one tile per method, each labelled with its name
//! and that frame's time, drawn with the grid's bitmap font.

use crate::font;
use image::{Rgba, RgbaImage};

const BACKGROUND: Rgba<u8> = Rgba([24, 24, 28, 255]);
const LABEL: Rgba<u8> = Rgba([240, 240, 240, 255]);
const LABEL_BACK: Rgba<u8> = Rgba([0, 0, 0, 255]);
const NOTE: Rgba<u8> = Rgba([255, 210, 80, 255]);

/// Columns and rows for `n` tiles: one row up to three, then two rows
/// (eight methods: 4 x 2), then a square-ish grid.
pub fn layout(n: usize) -> (u32, u32) {
    let n = n.max(1) as u32;
    match n {
        1..=3 => (n, 1),
        4 => (2, 2),
        5..=8 => (n.div_ceil(2), 2),
        _ => {
            let cols = (n as f64).sqrt().ceil() as u32;
            (cols, n.div_ceil(cols))
        }
    }
}

/// Each tile's size in a `width` x `height` frame of `n` tiles.
pub fn tile_size(n: usize, width: u32, height: u32) -> (u32, u32) {
    let (cols, rows) = layout(n);
    ((width / cols).max(1), (height / rows).max(1))
}

/// One tile: the method's picture, its label and a note (the edit) or none.
pub struct Tile<'a> {
    pub image: &'a RgbaImage,
    pub label: String,
}

/// Compose the frame; `note` is written at the bottom of every tile.
pub fn compose(width: u32, height: u32, tiles: &[Tile<'_>], note: Option<&str>) -> RgbaImage {
    let mut frame = RgbaImage::from_pixel(width, height, BACKGROUND);
    let (cols, _) = layout(tiles.len());
    let (tw, th) = tile_size(tiles.len(), width, height);
    for (i, tile) in tiles.iter().enumerate() {
        let (x, y) = ((i as u32 % cols) * tw, (i as u32 / cols) * th);
        image::imageops::replace(&mut frame, tile.image, i64::from(x), i64::from(y));
        label(&mut frame, x + 2, y + 2, &tile.label, LABEL);
        if let Some(note) = note {
            let ny = (y + th).saturating_sub(font::LINE + 4);
            label(&mut frame, x + 2, ny, note, NOTE);
        }
    }
    frame
}

/// Text on a black box, so it reads over sky and terrain alike.
fn label(img: &mut RgbaImage, x: u32, y: u32, text: &str, colour: Rgba<u8>) {
    let (w, h) = (font::text_width(text) + 2, font::LINE + 1);
    for dy in 0..h {
        for dx in 0..w {
            let (px, py) = (x + dx, y + dy);
            if px < img.width() && py < img.height() {
                img.put_pixel(px, py, LABEL_BACK);
            }
        }
    }
    font::draw_text(img, x + 1, y + 1, text, colour);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts() {
        assert_eq!(layout(1), (1, 1));
        assert_eq!(layout(2), (2, 1));
        assert_eq!(layout(8), (4, 2));
        assert_eq!(layout(9), (3, 3));
        assert_eq!(tile_size(8, 1280, 720), (320, 360));
        assert_eq!(tile_size(2, 320, 180), (160, 180));
    }

    #[test]
    fn tiles_land_side_by_side_with_labels() {
        let red = RgbaImage::from_pixel(160, 180, Rgba([200, 0, 0, 255]));
        let blue = RgbaImage::from_pixel(160, 180, Rgba([0, 0, 200, 255]));
        let tiles = [
            Tile {
                image: &red,
                label: "ray 1.0 ms".into(),
            },
            Tile {
                image: &blue,
                label: "mesh 2.0 ms".into(),
            },
        ];
        let f = compose(320, 180, &tiles, Some("dig"));
        assert_eq!(f.dimensions(), (320, 180));
        assert_eq!(f.get_pixel(100, 100).0, [200, 0, 0, 255]);
        assert_eq!(f.get_pixel(260, 100).0, [0, 0, 200, 255]);
        // The label box is drawn at each tile's top-left corner.
        assert_eq!(f.get_pixel(2, 2), &LABEL_BACK);
        assert_eq!(f.get_pixel(162, 2), &LABEL_BACK);
    }
}
