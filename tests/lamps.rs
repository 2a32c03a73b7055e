//! Lamps whose reflections merge into one streak, against the truth of a render: in the
//! photo, one light per lamp, each pinned by its own direct image; out of frame, the streak's
//! light split from the reflections and their colours alone.

mod common;

use std::path::{Path, PathBuf};

use common::fit_case::render_like_samples;
use common::pipeline::{convert_options, sample_photo_path, sample_scenes};
use common::truth::{assert_light_within, assert_within_sigmas, nearest, RadianceBar::*};
use streaklight::convert::{convert, ConvertOptions};
use streaklight::report::Report;
use streaklight::samples;

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

/// An orange lamp under a blue one (`orange-blue.png`), both in the photo, their reflections
/// one streak. The paper's estimate starts one light for the streak, and the lamps' direct
/// images make it two. Held: two lights, every edge within 2 % of the light's size and every radiance
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
        assert_light_within("in the photo", light, truth, 0.02, OfChannel(0.03));
        // Orange (24, 12, 3) and blue (4, 10, 24) at exposure 0.1 leave blue and red unclipped.
        assert_eq!(light.radiance_seen, Some(true), "{}", truth.name);
    }
}

/// The orange and blue lamps over the flat quad a game scene holds (`scene-flat.gltf`): the
/// statistical model's paper estimate starts one light for the streak, which its placing trims
/// to the orange lamp's image; the blue lamp, above it, is looked for around the estimate's
/// whole start, not the trimmed light alone, and starts a light of its own. Held: the
/// statistical model, two lights, every edge within 1 % of the light's size and every
/// radiance channel within 3 % (measured: 0.1 % and 1.1 %; before the lamps were looked for
/// around the whole start the fit gave one light, its red 34 % low, and the slope search ran
/// to its limits); and every error within 3 of its reported sigmas (measured: at most 2.4;
/// the orange lamp's bottom edge, which its image measures in blue, 0.3, where it was 5.9
/// while the water pixels helped place it).
#[test]
fn an_orange_lamp_under_a_blue_one_over_a_flat_quad_gives_two_lights() {
    let truths = samples::orange_and_blue_lights();
    let dir = sample_scenes();
    let report = convert(&ConvertOptions {
        exposure: samples::PHOTO_EXPOSURE,
        ..ConvertOptions::new(
            dir.join("scene-flat.gltf"),
            sample_photo_path("orange-blue.png"),
            dir.join("orange-blue-flat-lamps-fit.gltf"),
        )
    })
    .expect("fit")
    .report;
    assert_eq!(report.water_model.model, "statistical");
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    assert!(
        report.warnings.iter().all(|w| !w.contains("limit")),
        "{:?}",
        report.warnings
    );
    for truth in &truths {
        let light = nearest(&report.lights, truth);
        assert_light_within("over a flat quad", light, truth, 0.01, OfChannel(0.03));
        assert_within_sigmas(light, truth, 3.0);
    }
}

/// The stacked sample (two white lamps 0.8 m apart, one streak), both lamps in the photo: at
/// the defaults each light is pinned by its own lamp's image, so no refit over every pixel
/// (the fit reads one water pixel of each 2 x 2 block, as where every lamp's image pins its
/// light) and no warning of lights told apart only weakly. Held: every edge and the radiance within
/// 1 % (measured: 0.15 % and 0.3 %; from the reflections alone the facing
/// edges are 4-5 % rms off over 20 seeds and the radiances up to 11 %: BENCHMARKS.md).
#[test]
fn stacked_lamps_in_the_photo_are_two_lights_from_the_start() {
    let report = fit("stacked.png");
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    assert_eq!(
        report.settings.joint_pixels.as_deref(),
        Some("one water pixel of each 2 x 2 block")
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
        assert_light_within("stacked", light, truth, 0.01, OfChannel(0.01));
    }
}

/// `file` of the samples folder `dir` with its camera pitched down by `degrees`, written
/// beside it as `name`.
fn pitched_down(dir: &Path, file: &str, degrees: f64, name: &str) -> PathBuf {
    let text = std::fs::read_to_string(dir.join(file)).expect("sample scene");
    let mut doc: serde_json::Value = serde_json::from_str(&text).expect("sample scene JSON");
    let half = -degrees.to_radians() / 2.0;
    for node in doc["nodes"].as_array_mut().expect("nodes") {
        if node.get("camera").is_some() {
            node["rotation"] = serde_json::json!([half.sin(), 0.0, 0.0, half.cos()]);
        }
    }
    let path = dir.join(name);
    std::fs::write(&path, doc.to_string()).expect("write the scene");
    path
}

/// The orange and blue lamps out of frame: the camera pitched 27.5 degrees down, so that the
/// photo shows their one streak of two colours and neither lamp. The fit then splits the
/// streak's light from the reflections alone, where each pixel's colour says how much of it
/// each lamp lit. Held: two lights, neither seen directly, every edge within 1 % of its
/// light's size and every radiance channel within 1.2 % of its own value, every error the
/// report gives a sigma for within 3 of them, and the warning that the reflections alone tell
/// such lights apart only weakly (measured: edges within 0.4 %, channels within 0.7 %, every
/// error within 2.2 sigmas). The channel bound is the descent's after a split: stopped at its
/// sweep limit while still creeping along the valley where the blue light's height trades
/// against its radiance, it left that light 0.6 % too tall and its channels 0.9-2.0 % low
/// (fit seeds 1-4: 1.3-2.2 % in the worst channel, 0.6-0.7 % with the pattern moves that
/// carry it along; docs/decisions.md). Read by least squares alone, the blue lamp's weak
/// red (3 of its 20, under the orange lamp's 20) came out 3.0 % low at 3.4 sigmas: the
/// orange lamp's modelled tail over the pixels they share was taken from it.
#[test]
fn orange_and_blue_lamps_out_of_frame_are_split_by_their_colours() {
    let dir = sample_scenes();
    let truth = pitched_down(
        dir,
        "orange-blue-truth.gltf",
        27.5,
        "orange-blue-down-truth.gltf",
    );
    let scene = pitched_down(dir, "scene.gltf", 27.5, "scene-down.gltf");
    let photo = dir.join("orange-blue-down.png");
    render_like_samples(&truth, &photo, samples::PHOTO_SIZE, samples::PHOTO_SIZE);
    let report = convert(&ConvertOptions {
        exposure: samples::PHOTO_EXPOSURE,
        ..ConvertOptions::new(scene, photo, dir.join("orange-blue-down-fit.gltf"))
    })
    .expect("fit")
    .report;
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("whose reflections overlap")),
        "{:?}",
        report.warnings
    );
    for truth in &samples::orange_and_blue_lights() {
        let light = nearest(&report.lights, truth);
        assert!(
            light.direct_pixels.is_none_or(|n| n == 0),
            "{} is seen directly",
            truth.name
        );
        assert_eq!(light.radiance_seen, Some(false), "{}", truth.name);
        assert_light_within("out of frame", light, truth, 0.01, OfChannel(0.012));
        assert_within_sigmas(light, truth, 3.0);
    }
}
