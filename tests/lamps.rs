//! Lamps whose reflections merge into one streak while the lamps themselves are in the photo:
//! one light per lamp, each pinned by its own direct image, against the truth of a render.

mod common;

use common::pipeline::{convert_options, sample_photo_path, sample_scenes};
use streaklight::convert::convert;
use streaklight::report::{LightReport, Report};
use streaklight::samples::{self, SampleLight};

/// `streaklight fit` of a sample photo on the sample's lightless scene at the defaults.
fn fit(photo: &str) -> Report {
    convert(&convert_options(
        sample_scenes(),
        sample_photo_path(photo),
        &format!("{}-lamps-fit.gltf", photo.replace('.', "_")),
    ))
    .expect("fit")
    .report
}

/// The fitted light nearest `truth`'s centre.
fn nearest<'a>(lights: &'a [LightReport], truth: &SampleLight) -> &'a LightReport {
    let c = truth.center();
    let dist = |l: &LightReport| {
        let x = l.corner_left_bottom[0] + l.width / 2.0 - c.x;
        let y = l.corner_left_bottom[1] + l.height / 2.0 - c.y;
        x * x + y * y
    };
    lights
        .iter()
        .min_by(|a, b| dist(a).total_cmp(&dist(b)))
        .expect("a light")
}

/// An orange lamp under a blue one (`orange-blue.png`), both in the photo, their reflections
/// one streak. The
/// paper's estimate starts one light for the streak, and the lamps' direct images make it
/// two. Held: two lights, every edge within 2 % of the light's size and every radiance
/// channel within 3 % (measured: 0.03 % and 0.9 %), with no warning of lights the photo
/// tells apart only weakly (each is pinned by its own image) and no dropped light. Without
/// the direct images' starts the fit gave one light on the orange lamp, its red 61 % low,
/// and dropped a second.
#[test]
fn an_orange_lamp_under_a_blue_one_gives_two_lights() {
    let truths = samples::orange_and_blue_lights();
    let report = fit("orange-blue.png");
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    assert!(
        report
            .warnings
            .iter()
            .all(|w| !w.contains("whose reflections overlap") && !w.contains("was dropped")),
        "{:?}",
        report.warnings
    );
    for truth in &truths {
        let light = nearest(&report.lights, truth);
        let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
        eprintln!(
            "{}: edges {edges:?} radiance {:?}",
            truth.name, light.radiance
        );
        assert!(
            edges.iter().all(|e| e.abs() < 0.02),
            "{}: {edges:?}",
            truth.name
        );
        for ch in 0..3 {
            let want = truth.radiance[ch];
            assert!(
                (light.radiance[ch] - want).abs() < 0.03 * want,
                "{} channel {ch}: {} against {want}",
                truth.name,
                light.radiance[ch]
            );
        }
    }
}

/// The stacked sample (two white lamps 0.8 m apart, one streak), both lamps in the photo: at
/// the defaults each light is pinned by its own lamp's image, so no refit over every pixel
/// and no warning of lights told apart only weakly. Held: every edge and the radiance within
/// 1 % (measured: 0.15 % and 0.3 %; from the reflections alone, `tests/joint.rs`, the facing
/// edges are about 5 % rms off and the upper light's radiance up to 14 %).
#[test]
fn stacked_lamps_in_the_photo_are_two_lights_from_the_start() {
    let report = fit("stacked.png");
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    assert_eq!(
        report.settings.joint_pixels.as_deref(),
        Some("checkerboard")
    );
    assert!(
        report
            .warnings
            .iter()
            .all(|w| !w.contains("whose reflections overlap")),
        "{:?}",
        report.warnings
    );
    for truth in &samples::stacked_lights() {
        let light = nearest(&report.lights, truth);
        let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
        eprintln!(
            "{}: edges {edges:?} radiance {:?}",
            truth.name, light.radiance
        );
        assert!(
            edges.iter().all(|e| e.abs() < 0.01),
            "{}: {edges:?}",
            truth.name
        );
        for ch in 0..3 {
            let want = truth.radiance[ch];
            assert!(
                (light.radiance[ch] - want).abs() < 0.01 * want,
                "{} channel {ch}: {} against {want}",
                truth.name,
                light.radiance[ch]
            );
        }
    }
}
