//! Helpers for the fitting tests: the sample scenes, the committed sample photos, and a simple
//! threshold segmentation standing in for the streak extraction.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use streaklight::fitting::{fit_paper, threshold_streaks, FitOptions, FitOutcome};
use streaklight::photo_in::{self, Photo};
use streaklight::samples;
use streaklight::scene_in::{self, LoadOptions, Scene};
use streaklight::water_mask::water_mask;

/// The sample scenes, written once per test binary.
pub fn sample_scenes() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir()
            .join("streaklight-tests")
            .join(format!("fit-samples-{}", std::process::id()));
        samples::write_scenes(&dir).unwrap();
        dir
    })
}

/// A committed sample photo (`samples/NAME`), decoded with the samples' exposure.
pub fn sample_photo(name: &str) -> Photo {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples")
        .join(name);
    photo_in::load(&path, samples::PHOTO_EXPOSURE).unwrap()
}

/// Loads sample scene `file`, with the gloss overridden when given.
pub fn sample_scene(file: &str, gloss: Option<f32>) -> Scene {
    let options = LoadOptions {
        gloss,
        ..Default::default()
    };
    scene_in::load(&sample_scenes().join(file), &options).unwrap()
}

/// Segments `photo` and fits it against `scene` with default options.
pub fn fit_photo(scene: &Scene, photo: &Photo) -> FitOutcome {
    let water = water_mask(scene, photo.width, photo.height);
    let streaks = threshold_streaks(photo, &water, STREAK_THRESHOLD, 200);
    fit_paper(
        scene,
        photo,
        &water,
        &streaks,
        &FitOptions::for_scene(scene),
    )
    .unwrap()
}

/// Fraction of the brightest water pixel above which a pixel belongs to a streak.
pub const STREAK_THRESHOLD: f32 = 0.1;
