//! Drawing what makes a picture explain itself: a header with a title and a colour key,
//! labels on a dark box, outlines of masks, panels side by side.

use image::{Rgb, RgbImage};

use super::font::{draw_text, text_width, GLYPH};

/// The scale of titles, keys and labels on a picture `width` pixels wide: 16-pixel letters,
/// or 8-pixel ones on pictures narrower than 400 pixels.
pub fn text_scale(width: u32) -> u32 {
    if width >= 400 {
        2
    } else {
        1
    }
}

fn line_height(scale: u32) -> u32 {
    GLYPH * scale + 3 * scale
}

const MARGIN: u32 = 6;
const BACKGROUND: [u8; 3] = [24, 24, 28];
const INK: [u8; 3] = [235, 235, 235];

/// One entry of a colour key.
pub struct Key {
    /// The colour as drawn.
    pub colour: [u8; 3],
    /// What it means.
    pub label: String,
}

impl Key {
    /// `colour` means `label`.
    pub fn new(colour: [u8; 3], label: impl Into<String>) -> Self {
        Key {
            colour,
            label: label.into(),
        }
    }
}

/// Lines of `text` at `scale` no wider than `width` pixels, broken at spaces.
fn wrap(text: &str, width: u32, scale: u32) -> Vec<String> {
    let max = (width / (GLYPH * scale)).max(8) as usize;
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let line = lines.last_mut().expect("one line at least");
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > max {
            lines.push(word.to_owned());
        } else {
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
    }
    lines
}

/// `img` under a header: the title (wrapped to the width) and the key's entries, each a
/// swatch and its label, as many to a row as fit.
pub fn with_header(img: &RgbImage, title: &str, key: &[Key]) -> RgbImage {
    let w = img.width();
    let scale = text_scale(w);
    let line = line_height(scale);
    let title_lines = wrap(title, w.saturating_sub(2 * MARGIN), scale);
    // Lay the key out in rows.
    let swatch = GLYPH * scale;
    let mut rows: Vec<Vec<(u32, &Key)>> = Vec::new();
    let mut x = MARGIN;
    for k in key {
        let item = swatch + 6 + text_width(&k.label, scale) + 3 * MARGIN;
        if rows.is_empty() || (x + item > w && x > MARGIN) {
            rows.push(Vec::new());
            x = MARGIN;
        }
        rows.last_mut().expect("a row").push((x, k));
        x += item;
    }
    let header = MARGIN + line * (title_lines.len() + rows.len()) as u32 + MARGIN;
    let mut out = RgbImage::from_pixel(w, img.height() + header, Rgb(BACKGROUND));
    let mut y = MARGIN;
    for text in &title_lines {
        draw_text(&mut out, MARGIN as i64, y as i64, text, INK, scale);
        y += line;
    }
    for row in &rows {
        for &(x, k) in row {
            fill(&mut out, x, y, swatch, swatch, k.colour);
            let tx = x + swatch + 6;
            draw_text(&mut out, tx as i64, y as i64, &k.label, INK, scale);
        }
        y += line;
    }
    image::imageops::replace(&mut out, img, 0, header as i64);
    out
}

/// The height of the header [`with_header`] puts above a picture.
pub fn header_height(framed: &RgbImage, picture: &RgbImage) -> u32 {
    framed.height() - picture.height()
}

fn fill(img: &mut RgbImage, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
    for py in y..(y + h).min(img.height()) {
        for px in x..(x + w).min(img.width()) {
            img.put_pixel(px, py, Rgb(c));
        }
    }
}

/// `text` in `colour` on a dark box, its top-left corner near (`x`, `y`) but kept inside the
/// image.
pub fn label(img: &mut RgbImage, x: i64, y: i64, text: &str, colour: [u8; 3]) {
    let scale = text_scale(img.width());
    let (w, h) = (text_width(text, scale) + 4, GLYPH * scale + 4);
    if img.width() < w || img.height() < h {
        return;
    }
    let x = x.clamp(0, (img.width() - w) as i64) as u32;
    let y = y.clamp(0, (img.height() - h) as i64) as u32;
    fill(img, x, y, w, h, [0, 0, 0]);
    draw_text(img, x as i64 + 2, y as i64 + 2, text, colour, scale);
}

/// Marks in `colour` the pixels of `mask` (row-major, `img`'s size) that border a pixel
/// outside it, two pixels thick.
pub fn outline(img: &mut RgbImage, mask: &[bool], colour: [u8; 3]) {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && mask[(y * w + x) as usize];
    for y in 0..h {
        for x in 0..w {
            if !inside(x, y) {
                continue;
            }
            let border = (-2..=2).any(|d: i64| !inside(x + d, y) || !inside(x, y + d));
            if border {
                img.put_pixel(x as u32, y as u32, Rgb(colour));
            }
        }
    }
}

/// The pictures side by side, 4 dark pixels apart, bottoms aligned (so that pictures of one
/// size under headers of different heights line up).
pub fn side_by_side(panels: &[RgbImage]) -> RgbImage {
    const GAP: u32 = 4;
    let w =
        panels.iter().map(|p| p.width()).sum::<u32>() + GAP * panels.len().saturating_sub(1) as u32;
    let h = panels.iter().map(|p| p.height()).max().unwrap_or(0);
    let mut out = RgbImage::from_pixel(w, h, Rgb(BACKGROUND));
    let mut x = 0;
    for p in panels {
        image::imageops::replace(&mut out, p, x as i64, (h - p.height()) as i64);
        x += p.width() + GAP;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_sits_above_the_unchanged_picture() {
        let picture = RgbImage::from_pixel(300, 40, Rgb([9, 99, 199]));
        let keys = [
            Key::new([255, 0, 0], "left edge"),
            Key::new([0, 255, 0], "right edge"),
        ];
        let framed = with_header(
            &picture,
            "a title long enough to be wrapped onto two lines",
            &keys,
        );
        let top = header_height(&framed, &picture);
        assert!(top >= 3 * line_height(1), "{top}");
        for y in 0..40 {
            for x in 0..300 {
                assert_eq!(framed.get_pixel(x, top + y).0, [9, 99, 199]);
            }
        }
        // The swatches are drawn.
        let header = |c: [u8; 3]| (0..top).any(|y| (0..300).any(|x| framed.get_pixel(x, y).0 == c));
        assert!(header([255, 0, 0]) && header([0, 255, 0]));
    }

    #[test]
    fn an_outline_is_the_border_of_the_mask() {
        let mut img = RgbImage::new(20, 20);
        let mask: Vec<bool> = (0..400)
            .map(|i| (5..15).contains(&(i % 20)) && (5..15).contains(&(i / 20)))
            .collect();
        outline(&mut img, &mask, [255, 255, 255]);
        assert_eq!(img.get_pixel(5, 10).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(6, 10).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(10, 10).0, [0, 0, 0]); // the inside
        assert_eq!(img.get_pixel(2, 10).0, [0, 0, 0]); // the outside
    }
}
