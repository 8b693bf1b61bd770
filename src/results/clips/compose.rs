//! The pictures of `lodbench clips` (`commands/clips.rs`): the crop around what is drawn, integer upscaling,
//! the 8x8 font's text, the heat-map's legend, labelled grids of tiles and grids stacked one over another.

use crate::raster::{Rgba, RgbaImage};
use crate::results::png::{heatmap, HEATMAP_FULL_SCALE};

/// Pictures lower than this are upscaled (by default) until they are at least this high.
pub const MIN_TILE_HEIGHT: u32 = 200;
/// ... unless that makes them wider than this or the run's width, whichever is larger.
pub const MAX_TILE_WIDTH: u32 = 480;
/// Pixels around the drawn box kept in the crop.
pub const CROP_MARGIN: u32 = 8;
/// A box covering more than this share of the frame shows the whole frame.
pub const CROP_MAX_SHARE: f64 = 0.5;

/// A rectangle of the run's pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Crop {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
}

/// The box around every pixel of `pictures` (all `w` x `h`) that differs from the background (the first
/// picture's top-left pixel, the clear colour), widened by [`CROP_MARGIN`]; the whole frame when nothing is
/// drawn or the box covers more than [`CROP_MAX_SHARE`] of it.
pub fn crop_box<'a>(pictures: impl Iterator<Item = &'a RgbaImage>, w: u32, h: u32) -> Crop {
    let full = Crop { x: 0, y: 0, w, h };
    let mut background = None;
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0u32, 0u32);
    for p in pictures {
        let bg = *background.get_or_insert(p.get_pixel(0, 0));
        for (x, y, px) in p.enumerate_pixels() {
            if px != bg {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x);
                y1 = y1.max(y);
            }
        }
    }
    if x0 > x1 || y0 > y1 {
        return full;
    }
    let x = x0.saturating_sub(CROP_MARGIN);
    let y = y0.saturating_sub(CROP_MARGIN);
    let c = Crop {
        x,
        y,
        w: (x1 + CROP_MARGIN + 1).min(w) - x,
        h: (y1 + CROP_MARGIN + 1).min(h) - y,
    };
    if (c.w as f64 * c.h as f64) > CROP_MAX_SHARE * w as f64 * h as f64 {
        full
    } else {
        c
    }
}

/// The smallest factor that makes `crop` at least [`MIN_TILE_HEIGHT`] high, capped so it is no wider than
/// [`MAX_TILE_WIDTH`] or the run's width `w`; at least 1.
pub fn auto_scale(crop: &Crop, w: u32) -> u32 {
    let tall = MIN_TILE_HEIGHT.div_ceil(crop.h.max(1));
    let wide = MAX_TILE_WIDTH.max(w) / crop.w.max(1);
    tall.min(wide).max(1)
}

/// The heat-map of `picture` against `reference`, for dumps made without their `_error.png`.
pub fn heatmap_of(picture: &RgbaImage, reference: &RgbaImage) -> RgbaImage {
    let diff = crate::measure::metrics::difference_image(picture.as_raw(), reference.as_raw());
    RgbaImage::from_raw(picture.width(), picture.height(), heatmap(&diff))
        .unwrap_or_else(|| RgbaImage::new(picture.width(), picture.height()))
}

/// Nearest-neighbour upscaling by an integer factor.
pub fn upscale(img: &RgbaImage, scale: u32) -> RgbaImage {
    if scale == 1 {
        return img.clone();
    }
    RgbaImage::from_fn(img.width() * scale, img.height() * scale, |x, y| {
        img.get_pixel(x / scale, y / scale)
    })
}

/// The heat-map's colour bar from 0 to [`HEATMAP_FULL_SCALE`], for the reference's tile of the error grid.
pub fn legend(w: u32, h: u32) -> RgbaImage {
    let mut img = RgbaImage::from_pixel(w, h, BACKGROUND);
    let (x0, x1) = (8.min(w), w.saturating_sub(8));
    let (y0, y1) = (h / 3, h / 3 + (h / 8).max(6));
    for x in x0..x1 {
        let d = HEATMAP_FULL_SCALE * (x - x0) as f32 / (x1 - x0).max(1) as f32;
        let c = heatmap(&[d]);
        for y in y0..y1.min(h) {
            img.put_pixel(x, y, Rgba([c[0], c[1], c[2], 255]));
        }
    }
    let y = y1 + 4;
    text(&mut img, x0, y, "0", 1, TEXT);
    let top = format!("{HEATMAP_FULL_SCALE}");
    text(
        &mut img,
        x1.saturating_sub(8 * top.len() as u32),
        y,
        &top,
        1,
        TEXT,
    );
    text(&mut img, x0, y + 12, "mean |RGB diff|", 1, TEXT);
    text(&mut img, x0, y0.saturating_sub(14), "error scale", 1, TEXT);
    img
}

pub const BACKGROUND: Rgba = Rgba([24, 24, 24, 255]);
pub const TEXT: Rgba = Rgba([235, 235, 235, 255]);
pub const GAP: u32 = 2;

/// Text of the 8x8 public-domain font of `font8x8`, each pixel `size` x `size`; characters outside ASCII
/// show as '?'.
pub fn text(img: &mut RgbaImage, x: u32, y: u32, s: &str, size: u32, colour: Rgba) {
    for (i, ch) in s.chars().enumerate() {
        let code = if ch.is_ascii() {
            ch as usize
        } else {
            '?' as usize
        };
        let glyph = font8x8::legacy::BASIC_LEGACY[code];
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits >> col & 1 == 1 {
                    for dy in 0..size {
                        for dx in 0..size {
                            let px = x + (i as u32 * 8 + col) * size + dx;
                            let py = y + row as u32 * size + dy;
                            if px < img.width() && py < img.height() {
                                img.put_pixel(px, py, colour);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The largest text size (1 or 2) at which `s` fits in `width` pixels.
pub fn text_size(s: &str, width: u32) -> u32 {
    if s.len() as u32 * 16 + 8 <= width {
        2
    } else {
        1
    }
}

/// A labelled grid of pictures, and where each picture lies in it.
pub struct Grid {
    pub image: RgbaImage,
    /// Each picture's box `[x, y, width, height]` in the grid.
    pub boxes: Vec<[u32; 4]>,
}

/// A labelled grid: a header line, then `pictures` (all one size) in rows of `columns`, each under its label.
pub fn grid(header: &str, labels: &[String], pictures: &[RgbaImage], columns: u32) -> Grid {
    let (pw, ph) = pictures.first().map_or((1, 1), |p| p.dimensions());
    let cols = columns.min(pictures.len() as u32).max(1);
    let rows = (pictures.len() as u32).div_ceil(cols);
    let label_size = labels.iter().map(|l| text_size(l, pw)).min().unwrap_or(1);
    let label_h = 8 * label_size + 6;
    let width = cols * pw + (cols + 1) * GAP;
    let header_size = text_size(header, width);
    let header_h = 8 * header_size + 8;
    let height = header_h + rows * (label_h + ph + GAP) + GAP;
    // Even sides, so the H.264 encoder takes the frames as they are.
    let mut img = RgbaImage::from_pixel(width + width % 2, height + height % 2, BACKGROUND);
    text(&mut img, GAP + 2, 4, header, header_size, TEXT);
    let mut boxes = Vec::with_capacity(pictures.len());
    for (i, (label, picture)) in labels.iter().zip(pictures).enumerate() {
        let (c, r) = (i as u32 % cols, i as u32 / cols);
        let x = GAP + c * (pw + GAP);
        let y = header_h + r * (label_h + ph + GAP);
        text(&mut img, x + 2, y + 3, label, label_size, TEXT);
        img.replace(picture, x as i64, (y + label_h) as i64);
        boxes.push([x, y + label_h, pw, ph]);
    }
    Grid { image: img, boxes }
}

pub fn stack(top: &RgbaImage, bottom: &RgbaImage) -> RgbaImage {
    let mut img = RgbaImage::from_pixel(
        top.width().max(bottom.width()),
        top.height() + bottom.height(),
        BACKGROUND,
    );
    img.replace(top, 0, 0);
    img.replace(bottom, 0, top.height() as i64);
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_box_spans_what_any_picture_draws() {
        let bg = Rgba([10, 10, 10, 255]);
        let mut a = RgbaImage::from_pixel(100, 80, bg);
        let mut b = a.clone();
        a.put_pixel(40, 30, Rgba([200, 0, 0, 255]));
        b.put_pixel(50, 35, Rgba([0, 200, 0, 255]));
        let c = crop_box([&a, &b].into_iter(), 100, 80);
        assert_eq!(
            c,
            Crop {
                x: 40 - CROP_MARGIN,
                y: 30 - CROP_MARGIN,
                w: 11 + 2 * CROP_MARGIN,
                h: 6 + 2 * CROP_MARGIN
            }
        );
        // Nothing drawn, or most of the frame drawn: the whole frame.
        let empty = RgbaImage::from_pixel(100, 80, bg);
        assert_eq!(crop_box([&empty].into_iter(), 100, 80).w, 100);
        for x in 5..95 {
            for y in 5..75 {
                b.put_pixel(x, y, Rgba([0, 0, 200, 255]));
            }
        }
        assert_eq!(crop_box([&a, &b].into_iter(), 100, 80).h, 80);
        assert_eq!(auto_scale(&c, 100), MIN_TILE_HEIGHT.div_ceil(c.h));
        assert_eq!(
            auto_scale(
                &Crop {
                    x: 0,
                    y: 0,
                    w: 400,
                    h: 10
                },
                100
            ),
            1
        );
    }

    #[test]
    fn upscale_is_nearest_neighbour() {
        let mut img = RgbaImage::new(2, 1);
        img.put_pixel(1, 0, Rgba([9, 8, 7, 255]));
        let up = upscale(&img, 3);
        assert_eq!(up.dimensions(), (6, 3));
        assert_eq!(up.get_pixel(2, 2), Rgba([0, 0, 0, 0]));
        assert_eq!(up.get_pixel(3, 0), Rgba([9, 8, 7, 255]));
        assert_eq!(up.get_pixel(5, 2), Rgba([9, 8, 7, 255]));
    }

    #[test]
    fn text_draws_glyph_bits() {
        let mut img = RgbaImage::from_pixel(16, 8, BACKGROUND);
        text(&mut img, 0, 0, "1", 1, TEXT);
        let lit = img.pixels().filter(|p| *p == TEXT).count();
        let bits: u32 = font8x8::legacy::BASIC_LEGACY['1' as usize]
            .iter()
            .map(|b| b.count_ones())
            .sum();
        assert_eq!(lit as u32, bits);
        assert!(bits > 0);
    }

    #[test]
    fn grid_places_tiles_by_columns() {
        let tile = |v: u8| RgbaImage::from_pixel(10, 6, Rgba([v, v, v, 255]));
        let labels: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let Grid { image: g, boxes } = grid(
            "a long header",
            &labels,
            &[tile(50), tile(100), tile(150)],
            2,
        );
        // Two columns, two rows: the third tile starts the second row, under the first (labels and header
        // too long for the 2x font: 1x, 8 pixels high).
        let label_h = 8 + 6;
        let header_h = 8 + 8;
        let y2 = header_h + (label_h + 6 + GAP) + label_h;
        assert_eq!(g.get_pixel(GAP, y2), Rgba([150, 150, 150, 255]));
        assert_eq!(
            g.get_pixel(GAP + 10 + GAP, header_h + label_h),
            Rgba([100, 100, 100, 255])
        );
        assert_eq!(boxes[2], [GAP, y2, 10, 6]);
        assert_eq!(g.width() % 2, 0);
        assert_eq!(g.height() % 2, 0);
    }
}
