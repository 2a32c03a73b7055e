//! Lamps whose reflections merge into one streak while the lamps themselves are in the photo:
//! one light per lamp, each pinned by its own direct image, against the truth of a render.

mod common;

use common::pipeline::{convert_options, sample_scenes};
use streaklight::convert::convert;
use streaklight::report::{LightReport, Report};
use streaklight::samples::{self, SampleLight};

/// The orange lamp under the blue one: lower corner (-2, 1, 0), 3 x 1.5 m, radiance
/// (20, 10, 2.5); upper corner (-2, 4, 0), 3 x 1.5 m, radiance (3, 7, 20). 1.5 m of dark wall
/// between them; over the sample's water (e = 500) their reflections make one streak.
fn orange_and_blue() -> [SampleLight; 2] {
    [
        SampleLight::new("orange", [-2.0, 1.0, 0.0], [3.0, 1.5], [20.0, 10.0, 2.5]),
        SampleLight::new("blue", [-2.0, 4.0, 0.0], [3.0, 1.5], [3.0, 7.0, 20.0]),
    ]
}

/// Writes a truth scene of the stacked sample's setup with `lights` instead of its own
/// (named `name`-truth.gltf in the samples folder), renders it as the samples are rendered,
/// and fits the photo on the sample's scene at the defaults.
fn render_and_fit(name: &str, lights: &[SampleLight]) -> Report {
    let dir = sample_scenes();
    let text = std::fs::read_to_string(dir.join("stacked-truth.gltf")).expect("stacked truth");
    let mut doc: serde_json::Value = serde_json::from_str(&text).expect("stacked truth JSON");
    let defs = doc["extensions"]["EXT_lights_area"]["lights"]
        .as_array_mut()
        .expect("the truth's lights");
    assert_eq!(defs.len(), lights.len());
    for (def, light) in defs.iter_mut().zip(lights) {
        let peak = light.radiance.iter().cloned().fold(0.0, f64::max);
        def["name"] = light.name.clone().into();
        def["intensity"] = peak.into();
        def["color"] = serde_json::json!(light.radiance.map(|c| c / peak));
        def["size"] = light.height.into();
        def["rect"] = serde_json::json!({ "aspect": light.width / light.height });
    }
    let nodes = doc["nodes"].as_array_mut().expect("nodes");
    let mut k = 0;
    for node in nodes.iter_mut() {
        if node
            .get("extensions")
            .is_some_and(|e| e.get("EXT_lights_area").is_some())
        {
            let c = lights[k].center();
            node["name"] = lights[k].name.clone().into();
            node["translation"] = serde_json::json!([c.x, c.y, c.z]);
            k += 1;
        }
    }
    let truth = format!("{name}-truth.gltf");
    std::fs::write(dir.join(&truth), doc.to_string()).expect("write the truth scene");
    let spec = samples::SampleScene {
        file: truth,
        ..samples::by_photo("stacked.png").expect("the stacked sample")
    };
    let rendered =
        samples::render_photo(dir, &spec, samples::PHOTO_SPP, Default::default()).expect("render");
    let photo = dir.join(format!("{name}.png"));
    streaklight::photo_out::write(&photo, rendered.width, rendered.height, &rendered.pixels)
        .expect("write the photo");
    convert(&convert_options(dir, photo, &format!("{name}-fit.gltf")))
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

/// An orange lamp under a blue one, both in the photo, their reflections one streak. The
/// paper's estimate starts one light for the streak, and the lamps' direct images make it
/// two. Held: two lights, every edge within 2 % of the light's size and every radiance
/// channel within 3 % (measured: 0.03 % and 0.9 %), with no warning of lights the photo
/// tells apart only weakly (each is pinned by its own image) and no dropped light. Without
/// the direct images' starts the fit gave one light on the orange lamp, its red 61 % low,
/// and dropped a second.
#[test]
fn an_orange_lamp_under_a_blue_one_gives_two_lights() {
    let truths = orange_and_blue();
    let report = render_and_fit("orange-blue", &truths);
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
    let report = convert(&convert_options(
        sample_scenes(),
        common::pipeline::sample_photo_path("stacked.png"),
        "stacked-lamps-fit.gltf",
    ))
    .expect("fit")
    .report;
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
