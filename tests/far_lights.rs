//! Far lights: a light 1.2-1.5 m tall on a wall 16-18 m from the camera in a 16:9 photo,
//! where the lobe's footprint on the wall is about as large as the light (rendered here from
//! the sample setup with the wall moved back), and the harbour pair 40 m across the water out
//! of frame; fitted at the defaults, against the truth.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::fit_case::render_like_samples;
use common::pipeline::{sample_photo_path, sample_scenes};
use common::truth::{assert_light_within, assert_within_sigmas, nearest, RadianceBar::OfChannel};
use serde_json::{json, Value};
use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, JointSettings, Method};
use streaklight::report::Report;
use streaklight::samples::{self, harbour, SampleLight};

/// The photo's size: 16:9, with the samples' 600 rows.
const WIDTH: u32 = 1066;
const HEIGHT: u32 = 600;

/// `file` of the samples folder `dir` with the camera's aspect ratio 16:9 and the wall moved
/// to z = `wall_z`; with `light` as its only light when given (it must be a truth scene).
fn street(dir: &Path, file: &str, wall_z: f64, light: Option<&SampleLight>) -> Value {
    let text = std::fs::read_to_string(dir.join(file)).expect("sample scene");
    let mut doc: Value = serde_json::from_str(&text).expect("sample scene JSON");
    doc["cameras"][0]["perspective"]["aspectRatio"] = json!(WIDTH as f64 / HEIGHT as f64);
    for node in doc["nodes"].as_array_mut().expect("nodes") {
        if node["name"] == "Wall" {
            node["translation"] = json!([0.0, 0.0, wall_z]);
        }
        if let (Some(l), true) = (light, node["name"] == "light0") {
            // Centred on the light, 1 mm in front of the wall as written lights are.
            let c = l.center();
            node["translation"] = json!([c.x, c.y, wall_z + 0.001]);
        }
    }
    if let Some(l) = light {
        let peak = l.radiance.iter().cloned().fold(0.0, f64::max);
        let def = &mut doc["extensions"]["EXT_lights_area"]["lights"][0];
        def["intensity"] = json!(peak);
        def["color"] = json!(l.radiance.map(|c| c / peak));
        def["size"] = json!(l.height);
        def["rect"] = json!({ "aspect": l.width / l.height });
    }
    doc
}

/// The photo of far light `k` of [`far_lights`] on its wall, rendered as the samples are
/// (256 spp, exposure 0.1, seed 1) once per test binary into the shared sample scenes'
/// folder, and the scene to fit it against: (scene, photo). The light in the photo and the
/// one from the reflections alone read the same render.
fn street_photo(k: usize) -> &'static (PathBuf, PathBuf) {
    static PHOTOS: [OnceLock<(PathBuf, PathBuf)>; 2] = [OnceLock::new(), OnceLock::new()];
    PHOTOS[k].get_or_init(|| {
        let (wall_z, light) = &far_lights()[k];
        let dir = sample_scenes();
        let truth = dir.join(format!("street-{k}-truth.gltf"));
        let doc = street(dir, "table1-truth.gltf", *wall_z, Some(light));
        std::fs::write(&truth, doc.to_string()).expect("write the truth scene");
        let scene = dir.join(format!("street-{k}.gltf"));
        let doc = street(dir, "scene.gltf", *wall_z, None);
        std::fs::write(&scene, doc.to_string()).expect("write the scene");
        let photo = dir.join(format!("street-{k}.png"));
        render_like_samples(&truth, &photo, WIDTH, HEIGHT);
        (scene, photo)
    })
}

/// Far light `k`'s photo ([`street_photo`]) fitted at the defaults, with or without the
/// direct view.
fn fit_far_light(k: usize, direct_view: bool) -> Report {
    let (scene, photo) = street_photo(k);
    let fit = match FitSettings::default().method {
        Method::Joint(j) => Method::Joint(JointSettings { direct_view, ..j }),
        paper => paper,
    };
    let seen = if direct_view { "direct" } else { "reflections" };
    let options = ConvertOptions {
        exposure: samples::PHOTO_EXPOSURE,
        fit: FitSettings {
            method: fit,
            ..FitSettings::default()
        },
        ..ConvertOptions::new(
            scene.clone(),
            photo.clone(),
            sample_scenes().join(format!("street-{k}-{seen}-fit.gltf")),
        )
    };
    convert(&options).expect("fit").report
}

/// The two far lights: 1.5 x 1.2 m on a wall 16 m from the camera (z = -6), and 1.2 x 1.5 m
/// on a recessed facade 18 m away (z = -8), with its wall and its colour.
fn far_lights() -> [(f64, SampleLight); 2] {
    [
        (
            -6.0,
            SampleLight::new("street", [2.0, 1.5, -6.001], [1.5, 1.2], [20.0, 16.0, 10.0]),
        ),
        (
            -8.0,
            SampleLight::new(
                "facade",
                [-3.0, 2.0, -8.001],
                [1.2, 1.5],
                [12.0, 18.0, 24.0],
            ),
        ),
    ]
}

/// In the photo, each far light's direct image pins it: every edge within 1 % of its size
/// and every radiance channel within 1 % (measured on the street: 0.01 % and 0.3 %). From the
/// reflections alone the paper's estimate gave the street light 91 % too tall at 65 % of its
/// radiance.
#[test]
fn far_small_lights_in_the_photo_within_one_percent() {
    for (k, (_, light)) in far_lights().iter().enumerate() {
        let report = fit_far_light(k, true);
        assert_eq!(
            report.lights.len(),
            1,
            "{}: {:?}",
            light.name,
            report.warnings
        );
        assert_light_within("far", &report.lights[0], light, 0.01, OfChannel(0.01));
    }
}

/// Without the direct view (as for a light out of frame), the reflections alone tell the far
/// light's height and radiance only loosely: every error within 3 of its reported sigmas,
/// and the report warns that the uncertainty is large (measured on the street: top +3.6 %
/// at 0.4 sigma, radiance -5.2 % at 0.4 sigma, sigmas 8.6 % and 13.8 %).
#[test]
fn far_small_lights_from_the_reflections_alone_within_their_sigmas() {
    let (_, light) = &far_lights()[0];
    let report = fit_far_light(0, false);
    assert_eq!(report.lights.len(), 1, "{:?}", report.warnings);
    let l = &report.lights[0];
    let u = l.uncertainty.as_ref().expect("uncertainties");
    let c = l.corner_left_bottom;
    let errors = [
        (c[0] - light.corner.x, u.left),
        (c[0] + l.width - light.corner.x - light.width, u.right),
        (c[1] - light.corner.y, u.bottom),
        (c[1] + l.height - light.corner.y - light.height, u.top),
    ];
    for (k, (e, s)) in errors.iter().enumerate() {
        let s = s.unwrap_or_else(|| panic!("edge {k} has no sigma"));
        assert!(e.abs() < 3.0 * s, "edge {k}: {e} m against sigma {s}");
    }
    for ch in 0..3 {
        let e = l.radiance[ch] - light.radiance[ch];
        assert!(
            e.abs() < 3.0 * u.radiance[ch],
            "channel {ch}: {e} against sigma {}",
            u.radiance[ch]
        );
    }
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("large uncertainty")),
        "{:?}",
        report.warnings
    );
}

/// `fit` at the defaults of the out-of-frame photo of harbour layout `layout` against sample
/// scene `scene`: its report, with the water model it used held to `model` and one light per
/// truth light, and the layout's truth lights.
fn harbour_fit(scene: &str, layout: &str, model: &str) -> (Report, Vec<SampleLight>) {
    let dir = sample_scenes();
    let report = convert(&ConvertOptions {
        exposure: samples::PHOTO_EXPOSURE,
        ..ConvertOptions::new(
            dir.join(scene),
            sample_photo_path(&format!("harbour-{layout}-above.png")),
            dir.join(format!("harbour-{layout}-above-fit-{model}.gltf")),
        )
    })
    .expect("fit")
    .report;
    assert_eq!(report.water_model.model, model, "{:?}", report.water_model);
    // The paper's estimate that started the fit: 128 lobe samples a pixel under the exact
    // model; 512 under the statistical one out of frame, where every fit of the slope
    // search descends from it with only the reflections to place the lights.
    let start_samples = if model == "statistical" { 512 } else { 128 };
    assert_eq!(report.settings.samples, start_samples);
    // The lamps out of frame, the paper's first estimate at 32 samples is not kept, and the
    // automatic choice tests the exact model there first: over the photo's own waves the test
    // passes and the estimate is made again; over other waves the exact fit ends there.
    let stage = |name: &str| report.timings.iter().any(|t| t.stage.contains(name));
    if model == "exact" {
        assert!(
            stage("not kept, and the exact model tested there"),
            "{:?}",
            report.timings
        );
    }
    if scene.contains("other-waves") {
        assert!(
            stage("the exact model tested at the first estimate"),
            "{:?}",
            report.timings
        );
        assert!(!stage("joint footprints"), "{:?}", report.timings);
    }
    let truths = harbour::layouts()
        .into_iter()
        .find(|l| l.0 == layout)
        .expect("the layout")
        .2;
    assert_eq!(report.lights.len(), truths.len(), "{:?}", report.warnings);
    (report, truths)
}

/// Each truth light of an out-of-frame harbour fit has its own fitted light (the nearest, no
/// fitted light matched twice), seen by no direct pixel, with every error the report gives a
/// sigma for within 3 of it; with `warned`, the report says in words that its uncertainty is
/// large.
fn each_within_sigmas(report: &Report, truths: &[SampleLight], warned: bool) {
    let mut matched = Vec::new();
    for truth in truths {
        let light = nearest(&report.lights, truth);
        assert!(!matched.contains(&light.name), "{} twice", light.name);
        matched.push(light.name.clone());
        assert!(
            light.direct_pixels.is_none_or(|n| n == 0),
            "{} is seen directly",
            truth.name
        );
        assert_within_sigmas(light, truth, 3.0);
        assert!(
            !warned
                || report
                    .warnings
                    .iter()
                    .any(|w| w.contains(&light.name) && w.contains("large uncertainty")),
            "{}: {:?}",
            light.name,
            report.warnings
        );
    }
}

/// The harbour pair out of frame over the photo's own waves (`harbour-pair-above.png` on
/// `harbour-above.gltf`: the camera 2 m above the water, the lights 40 m away on the facade
/// above the photo's top): at that distance the lobe's spread on the wall is larger than the
/// lights, so each light's height trades against its radiance. Held: the exact model, two
/// lights, every error within 3 of its reported sigmas, and the report warning in words that
/// both lights' uncertainties are large (measured: within 1.8 sigmas; the orange light's top
/// 4.5 % of its height high at 0.8 sigma, its radiance 7.2 % low at 0.9 sigma; the blue
/// light's radiance 11.4 % low at 0.7 sigma).
#[test]
fn the_harbour_pair_out_of_frame_within_its_sigmas() {
    let (report, truths) = harbour_fit("harbour-above.gltf", "pair", "exact");
    each_within_sigmas(&report, &truths, true);
}

/// The harbour's three lights out of frame over the flat quad (`harbour-three-above.png` on
/// `harbour-above-flat.gltf`): from the reflections alone each light's height trades against
/// the waves' slope along the view, which the photo cannot tell apart, so what is held is
/// what the uncertainties say: the statistical model, three lights, one per truth, and every
/// error the report gives a sigma for within 3 of it (measured: the tall light's side edges
/// 21-24 % of its width off at 0.7 sigma the farthest; the warm light's radiance 40 % low at
/// 0.4 sigma: out of frame the radiance is not told from the height). The red light's start reaches down its wall to the
/// foot the photo shows dark; cut back from there it comes out 6 % dim, where left there it
/// came out 29 m tall at a seven-hundredth of its radiance, 42 sigmas off.
#[test]
fn the_three_lights_out_of_frame_over_a_flat_quad_within_their_sigmas() {
    let (report, truths) = harbour_fit("harbour-above-flat.gltf", "three", "statistical");
    each_within_sigmas(&report, &truths, false);
}

/// The harbour sign out of frame over the flat quad (`harbour-sign-above.png` on
/// `harbour-above-flat.gltf`): the photo's waves break the sign's streak into fragments, and
/// the nearest one, far down the streak, held more light than the expectation puts there. A
/// second light of the sign's colour 8 m above it on the facade (10.8 x 15.9 m) explained it;
/// the reflections alone cannot tell two lights stacked in one column from one, so the
/// weaker goes. Held: one light, every error within 3 of its sigmas (measured: the top edge
/// 81 % of the sign's height high and its radiance 44 % low, every error within 0.9 sigma), and
/// the report saying why the other light was dropped.
#[test]
fn the_sign_out_of_frame_over_a_flat_quad_is_one_light() {
    let (report, truths) = harbour_fit("harbour-above-flat.gltf", "sign", "statistical");
    assert_within_sigmas(&report.lights[0], &truths[0], 3.0);
    assert!(
        report.warnings.iter().any(|w| w.contains("one column")),
        "{:?}",
        report.warnings
    );
}

/// The harbour pair out of frame over the flat quad a game scene holds
/// (`harbour-pair-above.png` on `harbour-above-flat.gltf`): the two coloured lights of
/// different sizes from the reflections alone under the statistical model. Held: two lights,
/// one per truth, every error the report gives a sigma for within 3 of it, and the warning
/// that their uncertainties are large (measured: the orange light's bottom 55 % of its height
/// low at 1.2 sigmas and its radiance 58 % low at 2.4, its height traded against the waves'
/// slope along the view; the blue light's radiance 33 % high, within 0.2 sigma).
#[test]
fn the_pair_out_of_frame_over_a_flat_quad_within_its_sigmas() {
    let (report, truths) = harbour_fit("harbour-above-flat.gltf", "pair", "statistical");
    each_within_sigmas(&report, &truths, true);
}

/// The harbour sign out of frame over another realisation of the photo's waves
/// (`harbour-sign-above.png` on `harbour-above-other-waves.gltf`): the fine structure of the
/// scene's waves does not match the photo's, so the statistical model, chosen from the
/// reflections alone. Held: one light, every error within 3 of its sigmas (measured: the top
/// edge a sign's height too high and the radiance 39 % low, every error within 0.7 sigma).
#[test]
fn the_sign_out_of_frame_over_other_waves_within_its_sigmas() {
    let (report, truths) = harbour_fit("harbour-above-other-waves.gltf", "sign", "statistical");
    assert_eq!(
        report.water_model.chosen, "detected",
        "{:?}",
        report.water_model
    );
    assert_within_sigmas(&report.lights[0], &truths[0], 3.0);
}
