//! The signed residual of a fit, photo minus model, as a picture whose colours have a
//! printed scale: red where the photo is brighter than the model, blue where it is darker,
//! full colour at the scale (the 99th percentile of the residual's size over the water), black
//! at zero and off the water.

use image::{Rgb, RgbImage};

/// The residual picture's scale: the 99th percentile of |residual| over the `water` pixels
/// (linear units, as the photo times its exposure); at least a tiny positive value.
pub fn scale(residual: &[f32], water: &[bool]) -> f32 {
    let mut sizes: Vec<f32> = residual
        .iter()
        .zip(water)
        .filter(|(r, &w)| w && r.is_finite())
        .map(|(r, _)| r.abs())
        .collect();
    if sizes.is_empty() {
        return f32::MIN_POSITIVE;
    }
    let k = ((sizes.len() - 1) as f32 * 0.99).round() as usize;
    let (_, at, _) = sizes.select_nth_unstable_by(k, f32::total_cmp);
    at.max(f32::MIN_POSITIVE)
}

/// The colour of residual `r` at `scale`.
pub fn colour(r: f32, scale: f32) -> [u8; 3] {
    let t = (r.abs() / scale).clamp(0.0, 1.0);
    // sRGB-like ramp so that small residuals stay visible.
    let v = (t.sqrt() * 255.0).round() as u8;
    if r > 0.0 {
        [v, (v as f32 * 0.25) as u8, 0]
    } else {
        [0, (v as f32 * 0.45) as u8, v]
    }
}

/// The residual picture (`width` x `height`, row-major residuals, black off the water).
pub fn picture(residual: &[f32], water: &[bool], width: u32, height: u32, scale: f32) -> RgbImage {
    let mut img = RgbImage::new(width, height);
    for (i, px) in img.pixels_mut().enumerate() {
        if water[i] {
            *px = Rgb(colour(residual[i], scale));
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_99th_percentile_and_colours_are_signed() {
        let residual: Vec<f32> = (0..1000)
            .map(|i| if i % 2 == 0 { i as f32 } else { -(i as f32) })
            .collect();
        let mut water = vec![true; 1000];
        water[999] = false; // off the water: not counted
        let s = scale(&residual, &water);
        assert!((980.0..=990.0).contains(&s), "{s}");
        let up = colour(s, s);
        let down = colour(-s, s);
        assert_eq!(up[0], 255);
        assert_eq!(down[2], 255);
        assert!(up[2] == 0 && down[0] == 0);
        assert_eq!(colour(0.0, s), [0, 0, 0]);
        assert_eq!(colour(10.0 * s, s), up, "clipped at the scale");
        let img = picture(&residual, &water, 100, 10, s);
        assert_eq!(img.get_pixel(99, 9).0, [0, 0, 0]);
    }
}
