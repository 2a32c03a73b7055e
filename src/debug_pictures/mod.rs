//! The pictures `fit --debug-dir` writes, each explaining itself: titled panels, colour keys,
//! streak and light numbers, the fitted lights' reflections outlined on the photo, the signed
//! residual with its scale; and `index.html`, which shows every picture beside the report's
//! numbers.
//!
//! | file | what |
//! |---|---|
//! | `background` | the measured background beside the photo less it |
//! | `font` | the bitmap font of the pictures' text |
//! | `canvas` | headers with titles and keys, labels, outlines, panels side by side |
//! | `residual` | the signed residual's colours and scale |
//! | `html` | `index.html` |

pub mod background;
pub mod canvas;
pub mod font;
pub mod html;
pub mod residual;

use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};

use crate::convert::ConvertOptions;
use crate::optics::GaussianSlopes;
use crate::output_file::write_atomically;
use crate::photo_in::{linear_to_srgb, Photo};
use crate::pipeline::{light_name, Lit};
use crate::render::{self, RenderOptions};
use crate::report::Report;
use crate::scene_in::{AreaLight, Scene};
use crate::streaks::pictures::write_png;
use crate::water_model::{water_statistics, StatisticalSurface, WaterModel};
use crate::{streaks, Result};
use canvas::{label, outline, side_by_side, with_header, Key};
use html::Figure;

/// Colours of the fitted lights' outlines, by light number, reused in turn.
const LIGHT_COLOURS: [[u8; 3]; 6] = [
    [0, 255, 255],
    [255, 0, 255],
    [255, 255, 0],
    [0, 255, 0],
    [255, 128, 0],
    [255, 255, 255],
];

/// Camera rays per pixel of the re-render of all lights, and of each light alone for its
/// outline.
const MODEL_SPP: u32 = 64;
const OUTLINE_SPP: u32 = 16;

/// A light's reflection is outlined where its own re-render (smoothed) is above this fraction
/// of its brightest pixel.
pub const OUTLINE_LEVEL: f32 = 0.1;
/// The radius in pixels of the box blurs that smooth a light's re-render before its outline.
const OUTLINE_BLUR: usize = 6;

/// The colour of light `k`'s outline and label.
pub fn light_colour(k: usize) -> [u8; 3] {
    LIGHT_COLOURS[k % LIGHT_COLOURS.len()]
}

/// Writes the pictures and `index.html` into `dir` (created if missing); returns their paths.
pub fn write(
    dir: &Path,
    scene: &Scene,
    photo: &Photo,
    lit: &Lit,
    report: &Report,
    options: &ConvertOptions,
) -> Result<Vec<PathBuf>> {
    crate::output_file::create_dir_all(dir)?;
    let mut figures = Vec::new();
    let mut written = Vec::new();
    let captions = [
        "the superpixels the streaks are grown from (method §5 step 3)",
        "the seeds: bright superpixels the streaks grow from (step 4)",
        "the streaks found, numbered S0, S1, ... as in streaks.json and the report's streak_ids (step 5)",
        "each streak's edge pixels by side, from which the paper's estimate places each light's edges (step 6)",
    ];
    for ((name, img), caption) in streaks::pictures::pictures(photo, &lit.water, &lit.segmentation)
        .into_iter()
        .zip(captions)
    {
        let path = dir.join(name);
        write_png(&path, &img)?;
        written.push(path);
        figures.push(Figure {
            file: name.into(),
            caption: caption.into(),
        });
    }
    let json = dir.join(streaks::pictures::STREAKS_JSON);
    streaks::report::write_report(&json, &lit.segmentation, None, &options.fit.streaks)?;
    written.push(json);

    if let Some(b) = &lit.background {
        let path = dir.join(background::BACKGROUND_PICTURE);
        write_png(&path, &background::picture(photo, b))?;
        written.push(path);
        figures.push(Figure {
            file: background::BACKGROUND_PICTURE.into(),
            caption: "the night's smooth background (dim sky, lit facades and their \
                      reflections), measured away from the lights and taken off the photo \
                      before the fit, and the photo less it"
                .into(),
        });
    }

    let fit = fit_picture(scene, photo, lit, options)?;
    let path = dir.join(FIT_PICTURE);
    write_png(&path, &fit)?;
    written.push(path);
    figures.push(Figure {
        file: FIT_PICTURE.into(),
        caption: "the photo with the fitted lights' reflections outlined (L0, L1, ... as in the \
                  table above), the water re-rendered with the fitted lights, and their signed \
                  difference with its scale"
            .into(),
    });

    let index = dir.join(INDEX);
    write_atomically(&index, html::page(report, &figures).as_bytes())?;
    written.push(index);
    Ok(written)
}

/// The file name of the photo / model / residual picture.
pub const FIT_PICTURE: &str = "fit-photo-render-difference.png";
/// The file name of the page showing the pictures.
pub const INDEX: &str = "index.html";

/// Every file [`write()`] writes into its folder.
pub fn file_names() -> Vec<&'static str> {
    let mut names = streaks::pictures::PICTURE_NAMES.to_vec();
    names.extend([
        streaks::pictures::STREAKS_JSON,
        background::BACKGROUND_PICTURE,
        FIT_PICTURE,
        INDEX,
    ]);
    names
}

fn render_lights(
    scene: &Scene,
    lights: &[AreaLight],
    photo: &Photo,
    spp: u32,
    options: &ConvertOptions,
    water: Option<&dyn WaterModel>,
) -> Result<Vec<[f32; 3]>> {
    let image = render::render_with_lights(
        scene,
        lights,
        &RenderOptions {
            width: photo.width,
            height: photo.height,
            samples_per_pixel: spp,
            exposure: options.exposure,
            seed: options.fit.seed,
            shadowing: options.fit.shadowing,
            progress: options.progress,
            water,
            environment: None,
        },
    )?;
    Ok(image.pixels)
}

pub(crate) fn srgb_image(width: u32, height: u32, pixels: &[[f32; 3]]) -> RgbImage {
    let mut img = RgbImage::new(width, height);
    for (px, p) in img.pixels_mut().zip(pixels) {
        *px = Rgb(p.map(|c| (linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0).round() as u8));
    }
    img
}

/// One pass of a box blur of radius `r` along the rows or along the columns of `v`.
fn box_pass(v: &[f32], width: usize, r: usize, along_rows: bool) -> Vec<f32> {
    let height = v.len() / width.max(1);
    let (lines, len) = if along_rows {
        (height, width)
    } else {
        (width, height)
    };
    let at = |line: usize, k: usize| {
        if along_rows {
            line * width + k
        } else {
            k * width + line
        }
    };
    let mut out = vec![0f32; v.len()];
    for line in 0..lines {
        for k in 0..len {
            let (lo, hi) = (k.saturating_sub(r), (k + r).min(len - 1));
            let sum: f32 = (lo..=hi).map(|j| v[at(line, j)]).sum();
            out[at(line, k)] = sum / (hi - lo + 1) as f32;
        }
    }
    out
}

/// Where a light's own re-render `pixels` is above [`OUTLINE_LEVEL`] of its brightest, after
/// two box blurs of radius [`OUTLINE_BLUR`] (about a Gaussian): the envelope of the
/// reflection rather than each ripple's highlight.
fn reflection_mask(pixels: &[[f32; 3]], water: &[bool], width: u32) -> Vec<bool> {
    let w = width as usize;
    let mut value: Vec<f32> = pixels.iter().map(|p| (p[0] + p[1] + p[2]) / 3.0).collect();
    for _ in 0..2 {
        value = box_pass(&value, w, OUTLINE_BLUR, true);
        value = box_pass(&value, w, OUTLINE_BLUR, false);
    }
    let peak = value.iter().cloned().fold(0.0, f32::max);
    value
        .iter()
        .zip(water)
        .map(|(&b, &on_water)| on_water && peak > 0.0 && b > OUTLINE_LEVEL * peak)
        .collect()
}

/// The slope variance of the scene water's own microfacets (its gloss), per axis.
fn micro_variance(scene: &Scene) -> f32 {
    GaussianSlopes::from_gloss(scene.water.gloss).variance[0]
}

/// The statistical water the fit used, as the renderer takes it (its microfacets are the
/// scene's gloss, the waves carry the rest of the fitted slope variances); `None` when the
/// fit used the exact water.
fn statistical_water(scene: &Scene, photo: &Photo, lit: &Lit) -> Option<StatisticalSurface> {
    let slopes = lit.water_model.slopes.as_ref()?;
    let surface = water_statistics(scene, photo.width, photo.height)?.surface;
    let micro = micro_variance(scene);
    Some(StatisticalSurface {
        surface,
        waves: slopes.variance.map(|v| (v - micro).max(0.0)),
    })
}

/// The photo with the lights' reflections outlined, the model, and the signed residual, side
/// by side, each titled.
fn fit_picture(
    scene: &Scene,
    photo: &Photo,
    lit: &Lit,
    options: &ConvertOptions,
) -> Result<RgbImage> {
    let (width, height) = (photo.width, photo.height);
    let water = &lit.water;
    let area: Vec<AreaLight> = lit
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| l.area_light(light_name(i)))
        .collect();
    options.progress.stage(&format!(
        "debug pictures: the water re-rendered with the {} fitted light(s)",
        area.len()
    ));
    let statistical = statistical_water(scene, photo, lit);
    let water_model = statistical.as_ref().map(|w| w as &dyn WaterModel);
    let model = render_lights(scene, &area, photo, MODEL_SPP, options, water_model)?;
    let photo_linear: Vec<[f32; 3]> = photo
        .radiance
        .iter()
        .map(|p| p.map(|c| c * options.exposure))
        .collect();
    // The model is the lights' reflections plus the background the fit took off the photo.
    let background = |i: usize| {
        lit.background
            .as_ref()
            .map_or([0.0; 3], |b| b.pixels[i].map(|c| c * options.exposure))
    };
    let model: Vec<[f32; 3]> = model
        .iter()
        .zip(water)
        .enumerate()
        .map(|(i, (m, &w))| {
            if w {
                let b = background(i);
                [m[0] + b[0], m[1] + b[1], m[2] + b[2]]
            } else {
                [0.0; 3]
            }
        })
        .collect();

    let mut photo_panel = srgb_image(width, height, &photo_linear);
    let mut keys = Vec::new();
    for (k, light) in area.iter().enumerate() {
        options.progress.stage(&format!(
            "debug pictures: the reflection of light {k} alone, for its outline"
        ));
        let alone = render_lights(
            scene,
            std::slice::from_ref(light),
            photo,
            OUTLINE_SPP,
            options,
            water_model,
        )?;
        let mask = reflection_mask(&alone, water, width);
        let colour = light_colour(k);
        outline(&mut photo_panel, &mask, colour);
        if let Some(top) = mask.iter().position(|&m| m) {
            let (x, y) = ((top as u32 % width) as i64, (top as u32 / width) as i64);
            label(&mut photo_panel, x, y - 22, &format!("L{k}"), colour);
        }
        keys.push(Key::new(colour, format!("L{k}: {}", light.name)));
    }
    let photo_panel = with_header(
        &photo_panel,
        &format!(
            "Photo x exposure {}; outlined: where each fitted light's reflection is above {:.0} % of its peak",
            options.exposure,
            100.0 * OUTLINE_LEVEL
        ),
        &keys,
    );
    let plus_background = if lit.background.is_some() {
        ", plus the background"
    } else {
        ""
    };
    let model_title = match &statistical {
        None => format!(
            "Model: the water re-rendered with the fitted lights ({MODEL_SPP} rays per \
             pixel){plus_background}"
        ),
        Some(w) => format!(
            "Model: the expected image of the fitted lights over waves of slope variance \
             {:.2e} along, {:.2e} across (statistical water, {MODEL_SPP} rays per \
             pixel){plus_background}",
            w.waves[0] + micro_variance(scene),
            w.waves[1] + micro_variance(scene)
        ),
    };
    let model_panel = with_header(&srgb_image(width, height, &model), &model_title, &[]);
    let residual: Vec<f32> = photo_linear
        .iter()
        .zip(&model)
        .zip(water)
        .map(|((p, m), &w)| {
            if w {
                (p[0] + p[1] + p[2] - m[0] - m[1] - m[2]) / 3.0
            } else {
                0.0
            }
        })
        .collect();
    let scale = residual::scale(&residual, water);
    let residual_panel = with_header(
        &residual::picture(&residual, water, width, height, scale),
        &format!(
            "Residual photo - model (mean of R, G, B; linear, x exposure); full colour at +-{scale:.4}, \
             the 99th percentile of its size on the water"
        ),
        &[
            Key::new(residual::colour(scale, scale), format!("+{scale:.4} photo brighter")),
            Key::new(residual::colour(-scale, scale), format!("-{scale:.4} photo darker")),
            Key::new([0, 0, 0], "0, or not water"),
        ],
    );
    let mut panels = vec![photo_panel, model_panel, residual_panel];
    // Under the statistical model, the other model's image beside it: what the scene's own
    // water would reflect (its glints are where its waves put them, not the photo's).
    if statistical.is_some() {
        options.progress.stage(
            "debug pictures: the scene's own water with the fitted lights (the exact model)",
        );
        let exact = render_lights(scene, &area, photo, MODEL_SPP, options, None)?;
        let exact: Vec<[f32; 3]> = exact
            .iter()
            .zip(water)
            .map(|(m, &w)| if w { *m } else { [0.0; 3] })
            .collect();
        panels.push(with_header(
            &srgb_image(width, height, &exact),
            &format!(
                "Not used: the scene's own water mesh with the same lights (the exact model, \
                 {MODEL_SPP} rays per pixel); the report's water_model says why"
            ),
            &[],
        ));
    }
    Ok(side_by_side(&panels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_outline_is_the_smoothed_envelope_of_a_reflection() {
        // A 60 x 40 bright block with dark stripes (ripples) in a 100 x 100 picture.
        let w = 100;
        let pixels: Vec<[f32; 3]> = (0..w * w)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let inside = (20..80).contains(&x) && (30..70).contains(&y) && y % 4 != 0;
                [if inside { 1.0 } else { 0.0 }; 3]
            })
            .collect();
        let mask = reflection_mask(&pixels, &vec![true; w * w], w as u32);
        // Whole rows of the block, stripes included, are inside; far outside is not.
        assert!(
            (30..70).all(|y| mask[y * w + 50]),
            "a stripe cut the envelope"
        );
        assert!(!mask[5 * w + 5] && !mask[50 * w + 95]);
        // The blur of a constant is the constant.
        let flat = box_pass(&[2.0; 12], 4, 1, false);
        assert!(flat.iter().all(|&v| (v - 2.0).abs() < 1e-6));
    }
}
