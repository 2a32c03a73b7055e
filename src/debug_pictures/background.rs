//! `background.png`: the smooth background measured on the photo and taken off it before
//! the lights were fitted, brightened to be seen, beside what the lights were fitted to.

use image::RgbImage;

use super::canvas::{side_by_side, with_header};
use super::srgb_image;
use crate::background::Background;
use crate::photo_in::Photo;

/// The file name of the picture.
pub const BACKGROUND_PICTURE: &str = "background.png";

/// The background (times the exposure and a gain that takes its brightest pixel to 0.5) and
/// the photo less it.
pub fn picture(photo: &Photo, background: &Background) -> RgbImage {
    let (w, h) = (photo.width, photo.height);
    let peak = background
        .pixels
        .iter()
        .flat_map(|p| p.iter().copied())
        .fold(0f32, f32::max)
        * photo.exposure;
    let gain = if peak > 0.0 { 0.5 / peak } else { 1.0 };
    let shown: Vec<[f32; 3]> = background
        .pixels
        .iter()
        .map(|p| p.map(|c| c * photo.exposure * gain))
        .collect();
    let m = background.water_mean;
    let left = with_header(
        &srgb_image(w, h, &shown),
        &format!(
            "Background: the sky's and the facades' smooth light, measured in {} of {} cells \
             away from the streaks and the lights (x exposure x {gain:.0}); mean on the water \
             {:.4} {:.4} {:.4} (radiance)",
            background.cells_measured, background.cells, m[0], m[1], m[2]
        ),
        &[],
    );
    let less = photo.less(&background.pixels);
    let linear: Vec<[f32; 3]> = less
        .radiance
        .iter()
        .map(|p| p.map(|c| c * photo.exposure))
        .collect();
    let right = with_header(
        &srgb_image(w, h, &linear),
        "The photo less the background (x exposure): what the lights were fitted to",
        &[],
    );
    side_by_side(&[left, right])
}
