//! Pictures of every stage of the streak extraction, for a person to check at a glance.
//!
//! - `superpixels.png`: superpixel boundaries (yellow) over the photo;
//! - `seeds.png`: seed superpixels tinted cyan, seed points as red crosses (dropped ones
//!   magenta), over the darkened photo;
//! - `streaks.png`: each streak in its own colour over the darkened photo, with the water's
//!   outline in blue and the brightest pixel as a white cross;
//! - `edges.png`: streak edges by side: left red, right green, top blue, bottom yellow.
//!
//! Each is written under a title and a key of its colours, with every streak numbered as in
//! `streaks.json` ([`crate::debug_pictures::canvas`]).

use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};

use super::{Segmentation, StreakSide};
use crate::debug_pictures::canvas::{label, with_header, Key};
use crate::output_file::write_atomically;
use crate::photo_in::Photo;
use crate::{Error, Result};

/// Distinct colours for streaks (Kelly's colours of maximum contrast, the first ten after white
/// and black), reused in turn.
const PALETTE: [[u8; 3]; 10] = [
    [243, 195, 0],
    [135, 86, 146],
    [243, 132, 0],
    [161, 202, 241],
    [190, 0, 50],
    [194, 178, 128],
    [0, 136, 86],
    [230, 143, 172],
    [0, 103, 165],
    [249, 147, 121],
];

/// The colour of streak `id` in the pictures.
pub fn streak_colour(id: usize) -> [u8; 3] {
    PALETTE[id % PALETTE.len()]
}

fn base(photo: &Photo, brightness: f32) -> RgbImage {
    let mut img = RgbImage::new(photo.width, photo.height);
    for (i, px) in img.pixels_mut().enumerate() {
        let c = photo.display[i];
        *px = Rgb(c.map(|v| (v.clamp(0.0, 1.0) * brightness * 255.0).round() as u8));
    }
    img
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, Rgb(c));
    }
}

fn cross(img: &mut RgbImage, x: u32, y: u32, c: [u8; 3]) {
    for d in -3i64..=3 {
        put(img, x as i64 + d, y as i64, c);
        put(img, x as i64, y as i64 + d, c);
    }
}

fn blend(px: &mut Rgb<u8>, c: [u8; 3], alpha: f32) {
    for (v, &target) in px.0.iter_mut().zip(&c) {
        *v = (*v as f32 * (1.0 - alpha) + target as f32 * alpha).round() as u8;
    }
}

/// Superpixel boundaries over the photo.
pub fn superpixels_picture(photo: &Photo, seg: &Segmentation) -> RgbImage {
    let mut img = base(photo, 1.0);
    for (i, b) in seg.superpixels.boundary().into_iter().enumerate() {
        if b {
            img.put_pixel(
                i as u32 % photo.width,
                i as u32 / photo.width,
                Rgb([255, 220, 0]),
            );
        }
    }
    img
}

/// Seed superpixels and seed points.
pub fn seeds_picture(photo: &Photo, seg: &Segmentation) -> RgbImage {
    let mut img = base(photo, 0.6);
    let mut is_seed = vec![false; seg.superpixels.count];
    for &s in &seg.seed_superpixels {
        is_seed[s as usize] = true;
    }
    for (i, px) in img.pixels_mut().enumerate() {
        if is_seed[seg.superpixels.labels[i] as usize] {
            blend(px, [0, 200, 255], 0.45);
        }
    }
    for p in &seg.seed_points {
        if !seg.seeds.contains(p) {
            cross(&mut img, p.x, p.y, [255, 0, 255]);
        }
    }
    for p in &seg.seeds {
        cross(&mut img, p.x, p.y, [255, 0, 0]);
    }
    img
}

/// Streaks in distinct colours, the water outline, and each streak's brightest pixel.
pub fn streaks_picture(photo: &Photo, water: &[bool], seg: &Segmentation) -> RgbImage {
    let mut img = base(photo, 0.4);
    let w = photo.width as usize;
    for (i, px) in img.pixels_mut().enumerate() {
        let (x, y) = (i % w, i / w);
        let edge_of_water = water[i]
            && ((x > 0 && !water[i - 1])
                || (x + 1 < w && !water[i + 1])
                || (y > 0 && !water[i - w])
                || (i + w < water.len() && !water[i + w]));
        if edge_of_water {
            *px = Rgb([40, 90, 255]);
        }
    }
    for s in &seg.streaks {
        let c = streak_colour(s.id);
        for &p in &s.pixels {
            blend(img.get_pixel_mut(p % photo.width, p / photo.width), c, 0.75);
        }
    }
    for s in &seg.streaks {
        cross(&mut img, s.brightest.0, s.brightest.1, [255, 255, 255]);
    }
    img
}

/// Streak edges by side.
pub fn edges_picture(photo: &Photo, seg: &Segmentation) -> RgbImage {
    let mut img = base(photo, 0.4);
    for s in &seg.streaks {
        // Drawn in this order: a pixel on several sides takes the last one's colour.
        let sides = [
            (StreakSide::Top, [60, 60, 255]),
            (StreakSide::Bottom, [255, 230, 0]),
            (StreakSide::Left, [255, 40, 40]),
            (StreakSide::Right, [40, 255, 40]),
        ];
        for (side, c) in sides {
            for &p in &s.edges[side] {
                img.put_pixel(p % photo.width, p / photo.width, Rgb(c));
            }
        }
    }
    img
}

/// Writes `img` to `path` as PNG, atomically.
pub fn write_png(path: &Path, img: &RgbImage) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::output(path, format!("cannot encode the picture: {e}")))?;
    write_atomically(path, &bytes)
}

/// Numbers every streak ("S0", "S1", ... as in `streaks.json`) beside its brightest pixel.
fn number_streaks(img: &mut RgbImage, seg: &Segmentation) {
    for s in &seg.streaks {
        let (x, y) = s.brightest;
        label(
            img,
            x as i64 + 6,
            y as i64 - 22,
            &format!("S{}", s.id),
            streak_colour(s.id),
        );
    }
}

/// The four pictures, titled, keyed and with the streaks numbered: (file name, picture).
pub fn pictures(
    photo: &Photo,
    water: &[bool],
    seg: &Segmentation,
) -> Vec<(&'static str, RgbImage)> {
    let mut streaks = streaks_picture(photo, water, seg);
    number_streaks(&mut streaks, seg);
    let mut edges = edges_picture(photo, seg);
    number_streaks(&mut edges, seg);
    let mut streak_keys: Vec<Key> = seg
        .streaks
        .iter()
        .map(|s| {
            Key::new(
                streak_colour(s.id),
                format!("S{}: {} px", s.id, s.pixels.len()),
            )
        })
        .collect();
    streak_keys.push(Key::new([40, 90, 255], "water's outline"));
    streak_keys.push(Key::new([255, 255, 255], "+ brightest pixel"));
    vec![
        (
            PICTURE_NAMES[0],
            with_header(
                &superpixels_picture(photo, seg),
                &format!(
                    "Superpixels (SLIC): {} over the photo",
                    seg.superpixels.count
                ),
                &[Key::new([255, 220, 0], "superpixel boundary")],
            ),
        ),
        (
            PICTURE_NAMES[1],
            with_header(
                &seeds_picture(photo, seg),
                &format!(
                    "Seeds: {} seed superpixels, {} seed points kept of {}",
                    seg.seed_superpixels.len(),
                    seg.seeds.len(),
                    seg.seed_points.len()
                ),
                &[
                    Key::new([0, 200, 255], "seed superpixel"),
                    Key::new([255, 0, 0], "+ seed point"),
                    Key::new([255, 0, 255], "+ dropped seed point"),
                ],
            ),
        ),
        (
            PICTURE_NAMES[2],
            with_header(
                &streaks,
                &format!(
                    "Streaks: {} found, numbered as in streaks.json",
                    seg.streaks.len()
                ),
                &streak_keys,
            ),
        ),
        (
            PICTURE_NAMES[3],
            with_header(
                &edges,
                "Streak edges by side (the pixels that place the lights' edges)",
                &[
                    Key::new([255, 40, 40], "left"),
                    Key::new([40, 255, 40], "right"),
                    Key::new([60, 60, 255], "top"),
                    Key::new([255, 230, 0], "bottom"),
                ],
            ),
        ),
    ]
}

/// The file names of the pictures [`write_pictures`] writes, in order.
pub const PICTURE_NAMES: [&str; 4] = ["superpixels.png", "seeds.png", "streaks.png", "edges.png"];

/// The file name of the streaks' JSON report (`segment`, `--debug-dir`).
pub const STREAKS_JSON: &str = "streaks.json";

/// Writes the four pictures into `dir` and returns their paths.
pub fn write_pictures(
    dir: &Path,
    photo: &Photo,
    water: &[bool],
    seg: &Segmentation,
) -> Result<Vec<PathBuf>> {
    let pictures = pictures(photo, water, seg);
    let mut paths = Vec::new();
    for (name, img) in &pictures {
        let path = dir.join(name);
        write_png(&path, img)?;
        paths.push(path);
    }
    Ok(paths)
}
