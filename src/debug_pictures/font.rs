//! Text in the debug pictures: the public-domain 8 x 8 bitmap font of the `font8x8` crate
//! (IBM's VGA glyphs, ASCII), drawn at an integer scale. Other characters are drawn as '?'.

use image::{Rgb, RgbImage};

/// Pixels per glyph side at scale 1.
pub const GLYPH: u32 = 8;

/// The width of `text` at `scale`, in pixels.
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * GLYPH * scale
}

/// Whether pixel (`x`, `y`) of `c`'s glyph is set (row `y` from the top, column `x` from the
/// left).
pub fn glyph_pixel(c: char, x: u32, y: u32) -> bool {
    let code = if c.is_ascii() && !c.is_ascii_control() {
        c as usize
    } else {
        '?' as usize
    };
    let rows = font8x8::legacy::BASIC_LEGACY[code];
    // Bit 0 of a row is its leftmost pixel.
    x < GLYPH && y < GLYPH && rows[y as usize] & (1 << x) != 0
}

/// Draws `text` with its top-left corner at (`x`, `y`) in `colour`, each font pixel a
/// `scale` x `scale` block; what falls outside the image is clipped.
pub fn draw_text(img: &mut RgbImage, x: i64, y: i64, text: &str, colour: [u8; 3], scale: u32) {
    let s = scale as i64;
    for (k, c) in text.chars().enumerate() {
        let left = x + k as i64 * GLYPH as i64 * s;
        for gy in 0..GLYPH {
            for gx in 0..GLYPH {
                if !glyph_pixel(c, gx, gy) {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        let (px, py) = (left + gx as i64 * s + dx, y + gy as i64 * s + dy);
                        if px >= 0
                            && py >= 0
                            && (px as u32) < img.width()
                            && (py as u32) < img.height()
                        {
                            img.put_pixel(px as u32, py as u32, Rgb(colour));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_have_their_shapes() {
        // 'L': a vertical bar on the left (not mirrored), a foot along the bottom row of ink.
        let rows: Vec<String> = (0..GLYPH)
            .map(|y| {
                (0..GLYPH)
                    .map(|x| if glyph_pixel('L', x, y) { '#' } else { '.' })
                    .collect()
            })
            .collect();
        let ink: Vec<&String> = rows.iter().filter(|r| r.contains('#')).collect();
        assert!(ink.len() >= 6, "{rows:#?}");
        assert!(ink.iter().all(|r| r.as_bytes()[1] == b'#'), "{rows:#?}");
        assert!(ink[..3].iter().all(|r| !r[4..].contains('#')), "{rows:#?}");
        assert!(ink.last().unwrap().matches('#').count() >= 5, "{rows:#?}");
        let dash_rows = (0..GLYPH).filter(|&y| (0..GLYPH).any(|x| glyph_pixel('-', x, y)));
        assert_eq!(dash_rows.count(), 1);
        assert!((0..GLYPH).all(|y| (0..GLYPH).all(|x| !glyph_pixel(' ', x, y))));
    }

    #[test]
    fn text_is_drawn_at_scale_and_clipped() {
        let mut img = RgbImage::new(20, 20);
        draw_text(&mut img, 0, 0, "I", [255, 0, 0], 2);
        let lit = img.pixels().filter(|p| p.0 == [255, 0, 0]).count();
        let ink = (0..GLYPH)
            .flat_map(|y| (0..GLYPH).map(move |x| (x, y)))
            .filter(|&(x, y)| glyph_pixel('I', x, y))
            .count();
        assert_eq!(lit, 4 * ink);
        assert_eq!(text_width("abc", 2), 48);
        draw_text(&mut img, 15, 15, "WW", [0, 255, 0], 3); // partly outside: no panic
    }
}
