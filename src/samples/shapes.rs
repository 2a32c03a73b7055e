//! Synthetic test images for the superpixel step (SLIC, `streaks::superpixels`): piecewise-
//! constant colour shapes (rectangles, discs, triangles) painted over a background, plus
//! Gaussian noise, with the true region of every pixel, so that a segmentation can be scored.
//! The SLIC tests and the `slic` benchmark use them.

use crate::random::Rng;

/// An image and the region every pixel belongs to.
pub struct Shapes {
    pub width: u32,
    pub height: u32,
    /// sRGB-encoded colours in [0, 1], multiples of 1/255 (as an 8-bit file holds them).
    pub srgb: Vec<[f32; 3]>,
    /// The true region of every pixel.
    pub truth: Vec<u32>,
}

impl Shapes {
    /// The image as 8-bit sRGB, as written to a file.
    pub fn rgb8(&self) -> image::RgbImage {
        let rgb: Vec<u8> = self
            .srgb
            .iter()
            .flat_map(|p| p.map(|c| (c * 255.0).round() as u8))
            .collect();
        image::RgbImage::from_raw(self.width, self.height, rgb).expect("one colour per pixel")
    }
}

/// The colour of region `r`: hues a golden angle apart and three lightness levels, so that no
/// two regions look alike.
fn region_colour(r: u32) -> [f32; 3] {
    let hue = (r as f32 * 0.618_034).fract() * 6.0;
    let level = [0.85, 0.55, 0.3][(r % 3) as usize];
    let chroma = 0.6 * level;
    let x = chroma * (1.0 - ((hue % 2.0) - 1.0).abs());
    let (r1, g1, b1) = match hue as u32 {
        0 => (chroma, x, 0.0),
        1 => (x, chroma, 0.0),
        2 => (0.0, chroma, x),
        3 => (0.0, x, chroma),
        4 => (x, 0.0, chroma),
        _ => (chroma, 0.0, x),
    };
    let m = level - chroma;
    [r1 + m, g1 + m, b1 + m]
}

/// Paints `shapes` random shapes on a `width` x `height` background and adds Gaussian noise of
/// `noise` (in [0, 1] units), all from `seed`.
pub fn shapes(width: u32, height: u32, shapes: u32, noise: f32, seed: u64) -> Shapes {
    let (w, h) = (width as usize, height as usize);
    let mut rng = Rng::new(seed, 0x5a4e);
    let mut truth = vec![0u32; w * h];
    let size = (width.min(height) as f32) * 0.25;
    for r in 1..=shapes {
        let cx = rng.next_f32() * width as f32;
        let cy = rng.next_f32() * height as f32;
        let a = size * (0.4 + rng.next_f32());
        let b = size * (0.4 + rng.next_f32());
        let kind = rng.next_u32() % 3;
        let angle = rng.next_f32() * std::f32::consts::TAU;
        let (s, c) = angle.sin_cos();
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
                let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
                let inside = match kind {
                    0 => u.abs() < a && v.abs() < b * 0.6,
                    1 => (u / a).powi(2) + (v / b).powi(2) < 1.0,
                    _ => v > -b * 0.5 && v < b && u.abs() < a * (b - v) / (1.5 * b),
                };
                if inside {
                    truth[y * w + x] = r;
                }
            }
        }
    }
    let mut noise_rng = Rng::new(seed, 0x0015e);
    let srgb = truth
        .iter()
        .map(|&r| {
            region_colour(r).map(|c| {
                let v = c + noise * noise_rng.next_gaussian() as f32;
                (v.clamp(0.0, 1.0) * 255.0).round() / 255.0
            })
        })
        .collect();
    Shapes {
        width,
        height,
        srgb,
        truth,
    }
}
