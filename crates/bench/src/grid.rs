//! `grid.png`: views down, the reference first and then the methods across,
//! each cell a thumbnail, with the labels drawn in.

use crate::font;
use image::{Rgba, RgbaImage};

/// Thumbnails are at most this wide (a 1280-wide frame is box-filtered 4:1).
pub const THUMB_MAX_WIDTH: u32 = 320;

const BACKGROUND: Rgba<u8> = Rgba([24, 24, 28, 255]);
const LABEL: Rgba<u8> = Rgba([230, 230, 230, 255]);
const MISSING: Rgba<u8> = Rgba([90, 30, 60, 255]);

/// Box-filter an image down by the integer factor that brings it to at most
/// [`THUMB_MAX_WIDTH`] wide.
pub fn thumbnail(img: &RgbaImage) -> RgbaImage {
    thumbnail_to(img, THUMB_MAX_WIDTH)
}

/// Box-filter an image down by the integer factor that brings it to at most
/// `max_width` wide.
pub fn thumbnail_to(img: &RgbaImage, max_width: u32) -> RgbaImage {
    let k = img.width().div_ceil(max_width.max(1)).max(1);
    if k == 1 {
        return img.clone();
    }
    let (w, h) = ((img.width() / k).max(1), (img.height() / k).max(1));
    RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 4];
        let mut n = 0;
        for dy in 0..k {
            for dx in 0..k {
                let (sx, sy) = (x * k + dx, y * k + dy);
                if sx < img.width() && sy < img.height() {
                    let p = img.get_pixel(sx, sy).0;
                    for c in 0..4 {
                        sum[c] += u32::from(p[c]);
                    }
                    n += 1;
                }
            }
        }
        let n = n.max(1);
        Rgba(sum.map(|s| (s / n) as u8))
    })
}

/// Compose the grid. `cells[row][col]` are thumbnails (None: missing cell,
/// drawn as a solid block); `rows` and `columns` are the labels.
pub fn compose(rows: &[String], columns: &[String], cells: &[Vec<Option<RgbaImage>>]) -> RgbaImage {
    let (mut tw, mut th) = (1u32, 1u32);
    for img in cells.iter().flatten().flatten() {
        tw = tw.max(img.width());
        th = th.max(img.height());
    }
    let gap = 2;
    let left = rows.iter().map(|r| font::text_width(r)).max().unwrap_or(0) + 2 * gap + 4;
    let top = font::LINE + 2 * gap;
    let ncol = columns.len() as u32;
    let nrow = rows.len() as u32;
    let width = left + ncol * (tw + gap);
    let height = top + nrow * (th + gap);
    let mut grid = RgbaImage::from_pixel(width.max(1), height.max(1), BACKGROUND);
    for (c, title) in columns.iter().enumerate() {
        let x = left + c as u32 * (tw + gap);
        font::draw_text(&mut grid, x + 2, gap, &fit(title, tw), LABEL);
    }
    for (r, name) in rows.iter().enumerate() {
        let y = top + r as u32 * (th + gap);
        font::draw_text(&mut grid, gap, y + th / 2 - font::LINE / 2, name, LABEL);
        for c in 0..columns.len() {
            let x = left + c as u32 * (tw + gap);
            match cells
                .get(r)
                .and_then(|row| row.get(c))
                .and_then(|o| o.as_ref())
            {
                Some(img) => image::imageops::replace(&mut grid, img, i64::from(x), i64::from(y)),
                None => {
                    let block = RgbaImage::from_pixel(tw, th, MISSING);
                    image::imageops::replace(&mut grid, &block, i64::from(x), i64::from(y));
                }
            }
        }
    }
    grid
}

/// Cut a label to the characters that fit in `width` pixels.
fn fit(text: &str, width: u32) -> String {
    let n = (width / font::ADVANCE) as usize;
    text.chars().take(n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thumbnail_averages_boxes() {
        let img = RgbaImage::from_fn(1280, 800, |x, _| {
            if x % 2 == 0 {
                Rgba([200, 0, 0, 255])
            } else {
                Rgba([0, 0, 100, 255])
            }
        });
        let t = thumbnail(&img);
        assert_eq!(t.dimensions(), (320, 200));
        assert_eq!(t.get_pixel(10, 10).0, [100, 0, 50, 255]);
        let small = RgbaImage::new(320, 200);
        assert_eq!(thumbnail(&small).dimensions(), (320, 200));
    }

    #[test]
    fn grid_places_cells_and_marks_missing_ones() {
        let red = RgbaImage::from_pixel(8, 6, Rgba([255, 0, 0, 255]));
        let green = RgbaImage::from_pixel(8, 6, Rgba([0, 255, 0, 255]));
        let cells = vec![vec![Some(red), None], vec![None, Some(green)]];
        let g = compose(
            &["a".into(), "bb".into()],
            &["ref".into(), "ray".into()],
            &cells,
        );
        let left = font::text_width("bb") + 8;
        let top = font::LINE + 4;
        assert_eq!(g.dimensions(), (left + 2 * 10, top + 2 * 8));
        assert_eq!(g.get_pixel(left + 1, top + 1).0, [255, 0, 0, 255]);
        assert_eq!(g.get_pixel(left + 11, top + 1), &MISSING);
        assert_eq!(g.get_pixel(left + 11, top + 9).0, [0, 255, 0, 255]);
    }
}
