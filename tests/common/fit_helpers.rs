//! The fitting tests' stand-in for the streak extraction: a simple threshold segmentation, and
//! the paper fit of a photo segmented by it.

use streaklight::fitting::{fit_paper, threshold_streaks, FitOptions, FitOutcome};
use streaklight::photo_in::Photo;
use streaklight::scene_in::Scene;

use super::pipeline;

/// Segments `photo` and fits it against `scene` with default options.
pub fn fit_photo(scene: &Scene, photo: &Photo) -> FitOutcome {
    let water = pipeline::water(scene, photo);
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
