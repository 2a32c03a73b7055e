//! The chain from the sample scenes and the committed sample photos to what the fitter sees:
//! the scenes (generated into a temporary folder, since their water mesh is not committed),
//! the photos, the water mask, the streaks, and `convert` options that fit a sample photo.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use streaklight::convert::ConvertOptions;
use streaklight::fitting::StreakObservation;
use streaklight::photo_in::{self, Photo};
use streaklight::pipeline::{FitSettings, JointSettings, Method};
use streaklight::samples;
use streaklight::scene_in::{self, LoadOptions, Scene};
use streaklight::streaks::{extract_streaks, Segmentation, StreakParams};
use streaklight::water_mask::water_mask;

/// The sample scenes, written once per test binary and shared by its tests.
pub fn sample_scenes() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| sample_scenes_in("sample-scenes"))
}

/// A fresh folder `name` holding the sample scenes, for a test that removes it afterwards.
pub fn sample_scenes_in(name: &str) -> PathBuf {
    let dir = super::temp_dir(name);
    samples::write_scenes(&dir).expect("sample scenes");
    dir
}

/// Loads sample scene `file`, with the gloss overridden when given.
pub fn sample_scene(file: &str, gloss: Option<f32>) -> Scene {
    let options = LoadOptions {
        gloss,
        ..Default::default()
    };
    scene_in::load(&sample_scenes().join(file), &options).unwrap()
}

/// The committed sample photo `samples/NAME`.
pub fn sample_photo_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("samples")
        .join(name)
}

/// A committed sample photo (`samples/NAME`), decoded with the samples' exposure.
pub fn sample_photo(name: &str) -> Photo {
    photo_in::load(&sample_photo_path(name), samples::PHOTO_EXPOSURE).unwrap()
}

/// The water mask of `scene` at the size of `photo`.
pub fn water(scene: &Scene, photo: &Photo) -> Vec<bool> {
    water_mask(scene, photo.width, photo.height)
}

/// The streak extraction with its default settings.
pub fn segment(photo: &Photo, water: &[bool]) -> Segmentation {
    extract_streaks(photo, water, &StreakParams::default()).unwrap()
}

/// The extracted streaks as the fitter sees them (as `convert` makes them).
pub fn observations(photo: &Photo, water: &[bool]) -> Vec<StreakObservation> {
    segment(photo, water)
        .streaks
        .iter()
        .map(|s| streaklight::pipeline::observation(s, photo.width))
        .collect()
}

/// `convert` options that fit `photo` against the sample scene `dir/scene.gltf` into
/// `dir/OUTPUT`, at the samples' exposure; everything else at its default.
pub fn convert_options(
    dir: &Path,
    photo: impl Into<PathBuf>,
    output: &str,
) -> ConvertOptions<'static> {
    ConvertOptions {
        exposure: samples::PHOTO_EXPOSURE,
        ..ConvertOptions::new(dir.join("scene.gltf"), photo, dir.join(output))
    }
}

/// Fit settings as `streaklight fit` makes them from `--method`, `--repeats`,
/// `--joint-samples` and `--all-pixels` (the joint settings' own defaults otherwise).
pub fn fit_settings(
    method: Method,
    repeats: u32,
    joint_samples: Option<u32>,
    all_pixels: bool,
) -> FitSettings {
    FitSettings {
        method: match method {
            Method::Paper => Method::Paper,
            Method::Joint(j) => Method::Joint(JointSettings {
                repeats,
                ..j.reading_chosen(joint_samples, all_pixels)
            }),
        },
        ..FitSettings::default()
    }
}
