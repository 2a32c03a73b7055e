//! The joint refinement (`--method joint`, the default) through the whole pipeline (`convert`, real streak
//! extraction) on the committed sample photos, against the truth lights of `samples`, and
//! against the paper method on the same photo (never against the fit's own output).

mod common;

use common::json::{read_json, schema_validator};
use common::pipeline::fit_settings;
use common::pipeline::{
    convert_options, observations, sample_photo, sample_photo_path, sample_scene, sample_scenes,
    sample_scenes_in, water,
};
use streaklight::convert::{convert, ConvertOptions};
use streaklight::fitting::joint::{fit_joint, JointOptions, JointOutcome, PixelShare, StartGate};
use streaklight::pipeline::{FitSettings, JointSettings, Method};
use streaklight::report::{LightReport, Report};
use streaklight::samples::{self, SampleLight};
use streaklight::settings::Setting;

/// Per edge (left, right, bottom, top), the error as a fraction of the light's size along
/// that edge's axis; and the radiance error as a fraction of the largest channel.
fn errors(light: &LightReport, truth: &SampleLight) -> ([f64; 4], f64) {
    let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
    let peak = truth.radiance.iter().cloned().fold(0.0, f64::max);
    let rad = (0..3)
        .map(|i| (light.radiance[i] - truth.radiance[i]).abs() / peak)
        .fold(0.0, f64::max);
    (edges, rad)
}

/// The default joint fit without the direct view: the reflections alone, as for lamps out of
/// frame (in frame, each stacked lamp's direct image starts a light of its own, `tests/lamps.rs`,
/// and no split is needed).
fn reflections_only() -> Method {
    match Method::default() {
        Method::Joint(j) => Method::Joint(JointSettings {
            direct_view: false,
            ..j
        }),
        paper => paper,
    }
}

/// `streaklight fit` of a sample photo with a method; the report's lights.
fn fit(photo: &str, method: Method) -> Vec<LightReport> {
    fit_repeated(photo, method, 1)
}

/// [`fit`] with `repeats` independent joint fits averaged.
fn fit_repeated(photo: &str, method: Method, repeats: u32) -> Vec<LightReport> {
    fit_report(photo, method, repeats).lights
}

/// The whole report of [`fit_repeated`].
fn fit_report(photo: &str, method: Method, repeats: u32) -> Report {
    fit_report_options(photo, method, repeats, None)
}

/// [`fit_report`] with `--joint-samples` given or not.
fn fit_report_options(
    photo: &str,
    method: Method,
    repeats: u32,
    joint_samples: Option<u32>,
) -> Report {
    let tag = format!(
        "{}-{}-{repeats}-{joint_samples:?}",
        photo.replace('.', "_"),
        method.name()
    );
    let options = ConvertOptions {
        fit: fit_settings(method, repeats, joint_samples, false),
        ..convert_options(
            sample_scenes(),
            sample_photo_path(photo),
            &format!("{tag}.gltf"),
        )
    };
    let report = convert(&options).expect("fit").report;
    for l in &report.lights {
        eprintln!(
            "{photo} {}: corner {:?} {:.4} x {:.4} L {:?}",
            method.name(),
            l.corner_left_bottom,
            l.width,
            l.height,
            l.radiance
        );
    }
    report
}

/// How many standard deviations (the report's uncertainties) each edge and the radiance
/// (largest channel) are off the truth.
fn sigmas(light: &LightReport, truth: &SampleLight) -> ([f64; 4], f64) {
    let u = light
        .uncertainty
        .as_ref()
        .expect("the joint fit reports uncertainties");
    let (e, _) = errors(light, truth);
    let sd = [
        u.left.map(|s| s / truth.width),
        u.right.map(|s| s / truth.width),
        u.bottom.map(|s| s / truth.height),
        u.top.map(|s| s / truth.height),
    ];
    let edges = std::array::from_fn(|i| sd[i].map_or(0.0, |s| e[i].abs() / s));
    let ch = (0..3)
        .max_by(|&a, &b| truth.radiance[a].total_cmp(&truth.radiance[b]))
        .unwrap_or(0);
    let rad = (light.radiance[ch] - truth.radiance[ch]).abs() / u.radiance[ch];
    (edges, rad)
}

fn percent(e: [f64; 4]) -> [f64; 4] {
    e.map(|x| (x * 1e4).round() / 1e2)
}

/// The joint fit's error is mostly its own footprints' Monte Carlo noise and the photo's.
/// Measured through the whole pipeline with 8 seeds of the fit's samples on the committed
/// Table 3 photo (`cargo bench --bench spread`, BENCHMARKS.md), the root mean square errors
/// in % of the light's size, and the bounds held here, three times those (a fixed seed's
/// result is one draw; the bounds must not rest on a lucky one): light0 worst edge 0.07 %,
/// radiance 0.17 %: held to 0.5 %.
const LIGHT0_BOUND: f64 = 0.005;

/// Table 1 (one light, fully in the photo): every edge and the radiance within
/// [`LIGHT0_BOUND`], and the reported uncertainties cover the errors.
#[test]
fn joint_fits_table1() {
    let truth = samples::table1_light();
    let report = fit_report("table1.png", Method::default(), 1);
    // The lamp is in the photo, whole: its image pins the light, and the paper's estimate
    // that starts the fit reads 32 lobe samples a pixel, not 128.
    assert_eq!(report.settings.samples, 32);
    let joint = report.lights;
    let paper = fit("table1.png", Method::Paper);
    assert_eq!(joint.len(), 1);
    let (je, jr) = errors(&joint[0], &truth);
    let (pe, pr) = errors(&paper[0], &truth);
    eprintln!(
        "table1: joint edges % {:?} radiance {:.3} %; paper edges % {:?} radiance {:.3} %",
        percent(je),
        100.0 * jr,
        percent(pe),
        100.0 * pr
    );
    for (side, e) in ["left", "right", "bottom", "top"].iter().zip(je) {
        assert!(
            e.abs() < LIGHT0_BOUND,
            "{side} edge off by {:.3} %",
            100.0 * e
        );
    }
    assert!(jr < LIGHT0_BOUND, "radiance off by {:.3} %", 100.0 * jr);
    // The reported uncertainties (the curvature of the noise-corrected cost) cover the real
    // errors: over 8 seeds light0's errors are 0.5-1.3 sigma rms, at most 2.1.
    let (se, sr) = sigmas(&joint[0], &truth);
    eprintln!("table1: errors in sigmas {se:?}, radiance {sr:.2}");
    assert!(
        se.iter().all(|&x| x < 5.0) && sr < 5.0,
        "errors beyond 5 sigma: {se:?} {sr}"
    );
}

/// Table 3's light1, whose lamp the photo's right border cuts, from a start that overlaps
/// the lamp's direct image too little to be kept (fit seed 7: the paper's estimate 2.4 m tall
/// for 2, at L 6.9): the start is moved onto the image, but not cut at the border, where
/// the image is cut and not the lamp. Cut there, the light came out 0.77 m wide at 17 % too
/// much radiance, on 12 of fit seeds 1-32; kept, every seed's radiance is within 0.2 %.
#[test]
fn a_start_moved_onto_a_cut_image_keeps_its_extent_beyond_the_cut() {
    let truth = &samples::table3_lights()[1];
    let options = ConvertOptions {
        fit: FitSettings {
            seed: 7,
            ..fit_settings(Method::default(), 1, None, false)
        },
        ..convert_options(
            sample_scenes(),
            sample_photo_path("table3.png"),
            "table3-seed7.gltf",
        )
    };
    let report = convert(&options).expect("fit").report;
    let light = report
        .lights
        .iter()
        .find(|l| l.corner_left_bottom[0] > 2.0)
        .expect("light1");
    let (e, r) = errors(light, truth);
    eprintln!(
        "table3 seed 7: light1 {:.4} m wide, edges % {:?} radiance {:.3} %",
        light.width,
        percent(e),
        100.0 * r
    );
    // The photo sees the wall to x = 5.77 m: the light must reach beyond it.
    assert!(light.corner_left_bottom[0] + light.width > 6.0, "{light:?}");
    assert!(r < 0.01, "light1 radiance off by {:.3} %", 100.0 * r);
}

/// Table 3: light0 as Table 1's. Light1's streak runs out of the photo's right border (the
/// light spans x = 5..7 m, the photo sees the wall to x = 5.8 m), so its right edge is not
/// seen at all: the fit keeps it where the paper method put it (the lobes' farthest reach)
/// and reports it unconstrained. Its other edges and radiance are seen only through the
/// 40-70 pixel wide strip left of the border, where height and radiance trade against each
/// other, so the noise moves them more: rms over 8 seeds 0.05 % (left), 0.22 % (bottom),
/// 0.56 % (top), 0.59 % (radiance); held to three times that, as light0.
#[test]
fn joint_fits_table3() {
    let truths = samples::table3_lights();
    let report = fit_report("table3.png", Method::default(), 1);
    // Light1's lamp is cut by the frame: its reflections must place its edges, the fit
    // reads the checkerboard, and starts from the paper's estimate at 128 lobe samples a
    // pixel (its first try at 32 not kept).
    assert_eq!(
        report.settings.joint_pixels.as_deref(),
        Some("checkerboard")
    );
    assert_eq!(report.settings.samples, 128);
    // Two streaks, one light each: nothing to warn about overlapping reflections.
    assert!(
        report.warnings.iter().all(|w| !w.contains("overlap")),
        "{:?}",
        report.warnings
    );
    let joint = report.lights;
    assert_eq!(joint.len(), 2);
    let (e0, r0) = errors(&joint[0], &truths[0]);
    let (e1, r1) = errors(&joint[1], &truths[1]);
    eprintln!(
        "table3: light0 edges % {:?} radiance {:.3} %; light1 edges % {:?} radiance {:.3} %",
        percent(e0),
        100.0 * r0,
        percent(e1),
        100.0 * r1
    );
    for (side, e) in ["left", "right", "bottom", "top"].iter().zip(e0) {
        assert!(
            e.abs() < LIGHT0_BOUND,
            "light0 {side} edge off by {:.3} %",
            100.0 * e
        );
    }
    assert!(
        r0 < LIGHT0_BOUND,
        "light0 radiance off by {:.3} %",
        100.0 * r0
    );
    assert_eq!(joint[0].radiance[2], 0.0, "light0 has no blue");
    for (side, e, tol) in [
        ("left", e1[0], 0.0025),
        ("bottom", e1[2], 0.007),
        ("top", e1[3], 0.017),
    ] {
        assert!(
            e.abs() < tol,
            "light1 {side} edge off by {:.3} %",
            100.0 * e
        );
    }
    assert!(r1 < 0.018, "light1 radiance off by {:.3} %", 100.0 * r1);
    // Uncertainties: both lights' errors within 5 sigma. Over 8 seeds the largest is 1.8
    // sigma for light0 and 1.9 for light1 (`cargo bench --bench spread`, BENCHMARKS.md).
    let (s0, sr0) = sigmas(&joint[0], &truths[0]);
    let (s1, sr1) = sigmas(&joint[1], &truths[1]);
    eprintln!("table3: light0 errors in sigmas {s0:?} {sr0:.2}; light1 {s1:?} {sr1:.2}");
    assert!(
        s0.iter().all(|&x| x < 5.0) && sr0 < 5.0,
        "light0: {s0:?} {sr0}"
    );
    // (The unseen right edge has no sigma: `sigmas` gives it 0.)
    assert!(
        s1.iter().all(|&x| x < 5.0) && sr1 < 5.0,
        "light1: {s1:?} {sr1}"
    );
    let u1 = joint[1].uncertainty.as_ref().expect("uncertainty");
    assert!(u1.right.is_none(), "an unseen edge has no uncertainty");
    assert_eq!(joint[1].edges.right.status, "unconstrained");
}

/// Repeated joint fits of the stacked lights from the reflections alone (`--repeats 2`,
/// without the direct view): their mean, with the spread of
/// the 2 fits from independent samples added to the uncertainties. The lower light's error
/// through the overlap is a bias common to the fits (it grows into the overlap: top +10 %,
/// radiance 7 % off for seed 1), which no spread of them shows; it is the curvature of the
/// noise-corrected cost that reports it (the spread bench, BENCHMARKS.md). Held
/// here: every parameter of both lights that has a sigma within 6 of it for the default seed
/// (the facing edges the split made are unconstrained, with none); measured: 1.1 at most.
/// Two repeats rather than more: the spread is added the same way for any number, and each
/// repeat is a whole fit.
#[test]
fn repeated_fits_cover_the_stacked_errors() {
    let truths = samples::stacked_lights();
    // --joint-samples given: the user's choice stands (no refit over every pixel), and the
    // warning says which settings fit such lights more closely.
    let report = fit_report_options("stacked.png", reflections_only(), 2, Some(72));
    assert_eq!(
        report.settings.joint_pixels.as_deref(),
        Some("checkerboard")
    );
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.starts_with("streak 0 holds 2 lights")
                && w.contains(&format!(
                    "{}, {} 128",
                    Setting::AllPixels,
                    Setting::JointSamples
                ))),
        "{:?}",
        report.warnings
    );
    let mut joint = report.lights;
    assert_eq!(joint.len(), 2, "the joint fit splits the merged streak");
    joint.sort_by(|a, b| a.corner_left_bottom[1].total_cmp(&b.corner_left_bottom[1]));
    for (light, truth) in joint.iter().zip(&truths) {
        let (z, z_rad) = sigmas(light, truth);
        let (e, r) = errors(light, truth);
        eprintln!(
            "stacked x2: edges % {:?} radiance {:.3} %, sigmas {z:?} {z_rad:.2}",
            percent(e),
            100.0 * r
        );
        assert!(
            z.iter().chain([&z_rad]).all(|&s| s < 6.0),
            "errors beyond 6 sigma: {z:?} {z_rad}"
        );
        // Every edge but the two the cut made (which face each other) has a sigma.
        let u = light.uncertainty.as_ref().expect("uncertainty");
        assert!(
            [u.left, u.right].iter().all(|s| s.is_some()),
            "the side edges of a stacked light are seen"
        );
        assert_eq!(
            [u.bottom.is_some(), u.top.is_some()],
            [
                light.edges.bottom.status == "constrained",
                light.edges.top.status == "constrained"
            ],
        );
    }
}

/// The stacked lights over smoother water (`stacked1000.png`, e = 1000): their reflections
/// still merge into one streak (the paper method fits one light), but narrower lobes let the
/// photo pin the edges where the two lights meet. The split and the refit of lights that
/// share a streak are held here: the warning, what the report says the refit read, the
/// edges the cut made unconstrained and the outer ones the merged light's. Over e = 500
/// water (`stacked.png`) the photo tells the lights apart only weakly: through the whole
/// pipeline over fit seeds 1-20 the lower light's top is 4.4 % rms off and the upper one's
/// bottom 4.7 % (BENCHMARKS.md, "From the reflections alone"), and `repeated_fits_cover_the_stacked_errors` holds its fit. From the reflections alone (without the
/// direct view) and otherwise at the default settings, the joint fit, having split the streak, fits again over every pixel with 128 samples, and both lights
/// come out within about 2 % for every edge and the radiance: over fit seeds 1-8
/// (BENCHMARKS.md, `stacked1000.png` from the reflections alone) every error within 1.9 %
/// but the upper light's radiance on seed 4 (2.4 %), rms 1.2 % or less, each within 2.6 of
/// its sigma. Held here for seed 1 (measured: 1.1 % at most), with the report's sigmas and
/// the warning's wording.
#[test]
fn stacked_lights_over_smooth_water_within_two_percent() {
    let run = |method: Method| {
        let options = ConvertOptions {
            load: streaklight::scene_in::LoadOptions {
                gloss: Some(samples::STACKED_SMOOTH_GLOSS as f32),
                ..Default::default()
            },
            // The paper's estimate as the joint fit's start reads it, so that the outer
            // edges below compare with the edges the joint fit started from.
            fit: FitSettings {
                samples: Some(streaklight::fitting::DEFAULT_START_SAMPLES),
                ..fit_settings(method, 1, None, false)
            },
            ..convert_options(
                sample_scenes(),
                sample_photo_path("stacked1000.png"),
                &format!("stacked1000-{}.gltf", method.name()),
            )
        };
        convert(&options).expect("fit").report
    };
    let paper = run(Method::Paper);
    assert_eq!(paper.lights.len(), 1, "the paper sees one light");
    assert_eq!(paper.settings.joint_samples, None, "no joint fit ran");
    let report = run(reflections_only());
    // Lights sharing a streak are fitted again over every pixel with 128 samples, and the
    // report says what the final fit read.
    assert_eq!(report.settings.joint_pixels.as_deref(), Some("all"));
    assert_eq!(report.settings.joint_samples, Some(128));
    assert!(
        report
            .timings
            .iter()
            .any(|t| t.stage.starts_with("fit: joint refit of overlaps")),
        "{:?}",
        report.timings
    );
    // The user is told that the two lights of one streak are weakly told apart, once.
    let shared: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.starts_with("streak 0 holds 2 lights"))
        .collect();
    assert_eq!(shared.len(), 1, "{:?}", report.warnings);
    assert!(
        shared[0].contains("streaklight_light_0, streaklight_light_1")
            && shared[0].contains("reported uncertainties"),
        "{}",
        shared[0]
    );
    assert!(
        !shared[0].contains(&Setting::AllPixels.to_string()),
        "no advice to use the settings already used: {}",
        shared[0]
    );
    let mut joint = report.lights;
    assert_eq!(joint.len(), 2, "the joint fit splits the merged streak");
    joint.sort_by(|a, b| a.corner_left_bottom[1].total_cmp(&b.corner_left_bottom[1]));
    // The edges the cut made (the lower light's top, the upper one's bottom) are no streak's
    // edges, and without the lamps in view nothing else shows them: unconstrained, saying
    // why. The outer ones keep the merged light's streak-edge pixels.
    let merged = &paper.lights[0].edges;
    for edge in [&joint[0].edges.top, &joint[1].edges.bottom] {
        assert_eq!(edge.status, "unconstrained", "{edge:?}");
        assert!(
            edge.reason
                .as_deref()
                .is_some_and(|r| r.contains("faces another light")),
            "{edge:?}"
        );
    }
    for (edge, outer) in [
        (&joint[0].edges.bottom, &merged.bottom),
        (&joint[1].edges.top, &merged.top),
    ] {
        assert_eq!(edge.status, "constrained", "{edge:?}");
        assert_eq!(edge.pixels, outer.pixels, "{edge:?} {outer:?}");
    }
    for light in &joint {
        assert!(light.direct_pixels.is_none_or(|n| n == 0), "{light:?}");
    }
    for (light, truth) in joint.iter().zip(&samples::stacked_lights()) {
        let (e, r) = errors(light, truth);
        let (z, z_rad) = sigmas(light, truth);
        eprintln!(
            "stacked1000: edges % {:?} radiance {:.3} %, sigmas {z:?} {z_rad:.2}",
            percent(e),
            100.0 * r
        );
        assert!(
            e.iter().chain([&r]).all(|x| x.abs() < 0.02),
            "{}: edges {e:?} radiance {r}",
            truth.name
        );
        assert!(
            z.iter().chain([&z_rad]).all(|&s| s < 4.0),
            "errors beyond 4 sigma: {z:?} {z_rad}"
        );
    }
}

/// `fit --method joint` through the whole pipeline (real streak extraction) on the Table 1
/// sample: every edge and the radiance within [`LIGHT0_BOUND`], and a report with
/// uncertainties that matches the schema.
#[test]
fn joint_method_through_the_converter() {
    let dir = sample_scenes_in("joint-cli");
    let options = ConvertOptions {
        report: Some(dir.join("report.json")),
        fit: fit_settings(Method::default(), 1, None, false),
        ..convert_options(&dir, sample_photo_path("table1.png"), "out.gltf")
    };
    let outcome = convert(&options).expect("joint fit");
    assert_eq!(outcome.report.settings.method, "joint");
    assert_eq!(
        outcome.report.settings.joint_samples,
        Some(streaklight::fitting::joint::DEFAULT_JOINT_SAMPLES)
    );
    // The lamp's whole image is in the photo and pins every edge: the water pixels, which
    // give the radiance, are read one of each 2 x 2 block.
    assert_eq!(
        outcome.report.settings.joint_pixels.as_deref(),
        Some("one water pixel of each 2 x 2 block")
    );
    assert_eq!(outcome.report.lights.len(), 1);
    let light = &outcome.report.lights[0];
    let truth = samples::table1_light();
    let c = light.corner_left_bottom;
    let edges = [
        (c[0], truth.corner.x),
        (c[0] + light.width, truth.corner.x + truth.width),
        (c[1], truth.corner.y),
        (c[1] + light.height, truth.corner.y + truth.height),
    ];
    for (got, want) in edges {
        assert!(
            (got - want).abs() < LIGHT0_BOUND * truth.width,
            "edge {got} vs {want}"
        );
    }
    assert!(
        (light.radiance[0] - 20.0).abs() < LIGHT0_BOUND * 20.0,
        "{:?}",
        light.radiance
    );
    assert!(
        light.uncertainty.is_some(),
        "the joint fit reports uncertainties"
    );
    let report = read_json(&dir.join("report.json"));
    let validator = schema_validator("report.schema.json");
    assert!(validator.is_valid(&report));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two stacked lights 1.8 m apart instead of the sample's 0.8 m (rendered at 64 samples a
/// pixel, a noisier photo than the samples' 256: no easier for the bound held here): the
/// upper light's reflection is cut by the photo's lower border and seen mostly through its
/// blurred end. Its height is
/// then weakly told, but a light thinner than the samples' kernels must not win: a thin
/// light's coefficients are nearly all sample noise and the fit subtracts estimated noise
/// from its cost, so without the fit's smallest light (`smallest_light` in
/// src/fitting/joint.rs) the upper light of this render comes out 1 mm tall at 1400 times the
/// truth's radiance (19891). Held: every light at least 0.2 m tall (the truth's 1.0 and 1.4 m; the
/// kernels' typical full height here is about 0.28 m) and its radiance within 4 times the
/// truth's (14 and 16). Measured with the split's boundary search (seed 1): the upper light's
/// bottom, top and radiance +5 / -6 / +12 % off, the lower light's -1 / +2 / -2 %.
#[test]
fn stacked_lights_apart_never_become_a_sliver() {
    let dir = sample_scenes();
    let truth_path = dir.join("stacked-truth.gltf");
    let text = std::fs::read_to_string(&truth_path).expect("stacked truth scene");
    let mut doc: serde_json::Value = serde_json::from_str(&text).expect("stacked truth JSON");
    let upper = doc["nodes"]
        .as_array_mut()
        .expect("nodes")
        .iter_mut()
        .find(|n| n["name"] == "upper")
        .expect("the upper light's node");
    let y = upper["translation"][1].as_f64().expect("translation");
    upper["translation"][1] = serde_json::json!(y + 1.0);
    let apart = dir.join("stacked-apart-truth.gltf");
    std::fs::write(&apart, doc.to_string()).expect("write the scene");
    let spec = samples::SampleScene {
        file: "stacked-apart-truth.gltf".into(),
        ..samples::by_photo("stacked.png").expect("the stacked sample")
    };
    let rendered = samples::render_photo(dir, &spec, 64, Default::default()).expect("render");
    let photo = dir.join("stacked-apart.png");
    streaklight::photo_out::write(&photo, rendered.width, rendered.height, &rendered.pixels)
        .expect("write the photo");
    let report = convert(&convert_options(dir, photo, "stacked-apart-fit.gltf"))
        .expect("fit")
        .report;
    assert!(!report.lights.is_empty(), "no light found");
    // The two streaks the paper merged and the joint fit split again make one warning, not
    // one per streak.
    let overlap: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.contains("whose reflections overlap"))
        .collect();
    assert!(overlap.len() <= 1, "{overlap:?}");
    for l in &report.lights {
        eprintln!(
            "stacked apart: corner {:?} {:.4} x {:.4} L {:?}",
            l.corner_left_bottom, l.width, l.height, l.radiance
        );
        assert!(l.height > 0.2, "{} is {} m tall", l.name, l.height);
        assert!(
            l.radiance.iter().all(|&c| c < 64.0),
            "{} has radiance {:?}",
            l.name,
            l.radiance
        );
    }
}

/// A sample photo over `scene.gltf`, its water and streaks, and the paper fit's lights: the
/// start of the tests that call the joint fit directly.
struct PaperStart {
    scene: streaklight::scene_in::Scene,
    photo: streaklight::photo_in::Photo,
    water: Vec<bool>,
    observations: Vec<streaklight::fitting::StreakObservation>,
    model: streaklight::optics::ReflectionModel,
    paper: streaklight::fitting::FitOutcome,
}

impl PaperStart {
    /// The joint fit from the paper fit's lights with `options` (its model and seed 1 unless
    /// `options` says otherwise).
    fn fit<'a>(&self, options: impl FnOnce(JointOptions<'a>) -> JointOptions<'a>) -> JointOutcome {
        fit_joint(
            &self.scene,
            &self.photo,
            &self.water,
            &self.observations,
            &self.paper.lights,
            &options(JointOptions::new(self.model, 1)),
        )
        .expect("joint fit")
    }
}

fn paper_start(photo_name: &str) -> PaperStart {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo(photo_name);
    let water = water(&scene, &photo);
    let observations = observations(&photo, &water);
    let model = streaklight::optics::ReflectionModel::new(scene.water.gloss, scene.water.ior);
    let paper = streaklight::fitting::fit_paper(
        &scene,
        &photo,
        &water,
        &observations,
        &streaklight::fitting::FitOptions {
            samples: 256,
            seed: 1,
            model,
        },
    )
    .expect("paper fit");
    PaperStart {
        scene,
        photo,
        water,
        observations,
        model,
        paper,
    }
}

/// `--all-pixels`: the joint fit reads every pixel of its region instead of a checkerboard
/// half. On Table 1 the region then holds twice the pixels (the checkerboard keeps every
/// second one, so within a few pixels of its border), the lights stay within
/// [`LIGHT0_BOUND`], and the report says which pixels were read.
#[test]
fn all_pixels_reads_the_whole_region() {
    let start = paper_start("table1.png");
    // The region is chosen before the descent: the fits that count its pixels descend once
    // and try no split.
    let fit = |pixels: PixelShare| {
        start.fit(|o| JointOptions {
            pixels,
            sweeps: 1,
            split: false,
            ..o
        })
    };
    let (half, all) = (fit(PixelShare::Checkerboard), fit(PixelShare::All));
    let ratio = all.pixels as f64 / half.pixels as f64;
    assert!(
        (ratio - 2.0).abs() < 0.01,
        "{} pixels against {}",
        all.pixels,
        half.pixels
    );

    let report = convert(&ConvertOptions {
        fit: fit_settings(Method::default(), 1, None, true),
        ..convert_options(
            sample_scenes(),
            sample_photo_path("table1.png"),
            "table1-all-pixels.gltf",
        )
    })
    .expect("fit")
    .report;
    assert_eq!(report.settings.joint_pixels.as_deref(), Some("all"));
    assert_eq!(report.lights.len(), 1);
    let (e, r) = errors(&report.lights[0], &samples::table1_light());
    eprintln!(
        "table1, all pixels: edges % {:?} radiance {:.3} %",
        percent(e),
        100.0 * r
    );
    assert!(
        e.iter().all(|x| x.abs() < LIGHT0_BOUND) && r < LIGHT0_BOUND,
        "{e:?} {r}"
    );
}

/// The joint fit reports the lights it explained as two (`JointOutcome::splits`), and a fit
/// told them (`JointOptions::known_splits`, as the overlap refit is told the first fit's)
/// tries each only that way: on the stacked sample from the reflections alone, the one start
/// light is split one above the other; told so, the fit makes the same lights to the last
/// bit (the same samples: only the side-by-side trial is left out); told "side by side", it
/// never cuts the light the other way. Each long step of the split says what it does and
/// counts its work: the ways tried, the new light's own trace, the boundary's candidates.
/// Asked to end at its split (`JointOptions::end_at_split`), it reports that split and stops.
#[test]
fn a_known_split_is_tried_only_its_way() {
    use streaklight::fitting::joint::{Split, SplitWay};
    use streaklight::progress::{Progress, Reporter};
    /// A stage, with the counts of work reported under it: (done, total).
    type Stage = (String, Vec<(u64, u64)>);
    /// Every stage.
    #[derive(Default)]
    struct Record(std::sync::Mutex<Vec<Stage>>);
    impl Progress for Record {
        fn stage(&self, line: &str) {
            self.0.lock().unwrap().push((line.to_string(), Vec::new()));
        }
        fn advance(&self, done: u64, total: u64) {
            if let Some(last) = self.0.lock().unwrap().last_mut() {
                last.1.push((done, total));
            }
        }
    }
    let start = paper_start("stacked.png");
    assert_eq!(start.paper.lights.len(), 1, "the paper fit makes one light");
    let record = Record::default();
    let fit = |known: &[Split], progress: Reporter<'_>| {
        start.fit(|o| JointOptions {
            samples: 32,
            direct_view: false,
            known_splits: known,
            progress,
            ..o
        })
    };
    let fit_silently = |known: &[Split]| fit(known, Reporter::default());
    let free = fit(&[], Reporter::new(&record));
    let stacked = Split {
        light: 0,
        way: SplitWay::Stacked,
    };
    assert_eq!(free.splits, [stacked]);
    assert_eq!(free.lights.len(), 2);
    let stages = record.0.into_inner().unwrap();
    // The stage that starts with `prefix`, and its counts.
    let stage = |prefix: &str| {
        stages
            .iter()
            .find(|(line, _)| line.starts_with(prefix))
            .unwrap_or_else(|| panic!("no stage {prefix:?} in {stages:#?}"))
    };
    // Counted from 0 to the total, in order.
    let counted = |counts: &[(u64, u64)], total: u64| {
        counts.first() == Some(&(0, total))
            && counts.last() == Some(&(total, total))
            && counts.windows(2).all(|w| w[0].0 <= w[1].0)
    };
    let (_, ways) = stage("joint fit: the residual is structured");
    assert!(counted(ways, 2), "{ways:?}");
    let (line, traced) = stage("joint fit: the residual of light 0 is structured");
    assert!(line.contains("one above the other"), "{line}");
    assert!(
        counted(traced, traced.last().map_or(0, |c| c.1)),
        "{traced:?}"
    );
    assert!(traced.last().is_some_and(|c| c.1 > 1000), "{traced:?}");
    stage("joint fit: searching where lights 0 and 1 meet");
    let (line, candidates) = stage("joint fit: lights 0 and 1: descents from ");
    let n: u64 = line
        .trim_start_matches("joint fit: lights 0 and 1: descents from ")
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .expect("a count of candidates");
    assert!(n >= 1 && counted(candidates, n), "{line}: {candidates:?}");
    let fit = fit_silently;
    let told = fit(&[stacked]);
    assert_eq!(told.splits, free.splits);
    for (a, b) in told.lights.iter().zip(&free.lights) {
        assert_eq!(
            (a.rect(), a.radiance),
            (b.rect(), b.radiance),
            "the same lights"
        );
    }
    let side = Split {
        light: 0,
        way: SplitWay::SideBySide,
    };
    let other = fit(&[side]);
    assert!(
        other.splits.iter().all(|s| s.way == SplitWay::SideBySide),
        "{:?}",
        other.splits
    );
    // Asked to end at its first split (an overlap refit follows it), the fit reports the
    // same split, says that it ends there, and makes no light: no second sample set, no
    // boundary search, no descent after the split.
    assert!(!free.ended_at_split);
    let record = Record::default();
    let ended = start.fit(|o| JointOptions {
        samples: 32,
        direct_view: false,
        end_at_split: true,
        progress: Reporter::new(&record),
        ..o
    });
    assert!(ended.ended_at_split);
    assert_eq!(ended.splits, free.splits);
    assert!(ended.lights.is_empty() && ended.uncertainty.is_empty());
    let stages = record.0.into_inner().unwrap();
    let said = |prefix: &str| stages.iter().find(|(line, _)| line.starts_with(prefix));
    assert!(
        said("joint fit: the residual of light 0 is structured")
            .is_some_and(|(line, _)| line.ends_with("to be made again with the split known")),
        "{stages:#?}"
    );
    assert!(said("joint fit: searching where").is_none(), "{stages:#?}");
    assert!(
        said("joint fit: lights 0 and 1: descents").is_none(),
        "{stages:#?}"
    );
}

/// A start gate (`JointOptions::start_gate`, what the automatic choice of the water model
/// asks before it spends the exact fit's descent) is shown the start lights' expected image
/// and can end the fit there: no light, that image as the outcome's `modelled`. The image is
/// the start's, not the fit's: over the same pixels, the fitted lights explain more of the
/// photo than the paper's. A gate that lets the fit go on changes nothing of it.
#[test]
fn a_start_gate_ends_the_fit_before_its_descent() {
    use streaklight::pipeline::fine_structure_of;
    let start = paper_start("table1.png");
    let fit = |gate: Option<StartGate<'_>>| {
        start.fit(|o| JointOptions {
            samples: 32,
            start_gate: gate,
            ..o
        })
    };
    let seen = std::sync::Mutex::new(Vec::new());
    let stop = |image: &[(u32, [f32; 3])]| {
        *seen.lock().unwrap() = image.to_vec();
        false
    };
    let stopped = fit(Some(StartGate(&stop)));
    let shown = seen.into_inner().unwrap();
    assert!(stopped.stopped_at_start);
    assert!(stopped.lights.is_empty() && stopped.uncertainty.is_empty());
    assert!(!shown.is_empty());
    assert_eq!(stopped.modelled, shown);

    let go = |_: &[(u32, [f32; 3])]| true;
    let gated = fit(Some(StartGate(&go)));
    let plain = fit(None);
    assert!(!gated.stopped_at_start && !plain.stopped_at_start);
    assert_eq!(gated.lights, plain.lights);
    assert_eq!(gated.modelled, plain.modelled);

    let ids = |m: &[(u32, [f32; 3])]| m.iter().map(|p| p.0).collect::<Vec<_>>();
    assert_eq!(ids(&shown), ids(&plain.modelled));
    let explained = |m: &[(u32, [f32; 3])]| {
        fine_structure_of(&start.photo, start.scene.camera.yfov, m)
            .and_then(|f| f.explained)
            .unwrap()
    };
    let (at_start, fitted) = (explained(&shown), explained(&plain.modelled));
    eprintln!("explained: start {at_start:.3}, fitted {fitted:.3}");
    assert!(at_start < fitted, "start {at_start}, fitted {fitted}");
}

/// Table 1's light is in the photo, every edge crossed by pixels that see it: the fit reports
/// it seen whole, at its fitted rectangle; with the direct view off it is not. Its image
/// clips, next to a black wall, so each edge lies within a pixel's footprint on the wall:
/// 10 m x 2 tan(30 deg) / 600 = 1.92 cm at the wall's nearest point, up to 16 % more at the
/// light's far corner (the wall seen 22 degrees off the axis), and every edge's sigma is
/// bounded by that footprint over sqrt(3) (measured: 1.13-1.14 cm). Held at a rectangle 10 cm
/// higher (5 pixels at 10 m), a fit keeps that rectangle to the last digit, solves only the
/// radiance, and costs more than the free fit (the photo shows the lamp lower); its top and
/// bottom edges are not bounded by the image then (moved down a footprint, each agrees with
/// the photo better). `held` of another length than the start lights is not used.
#[test]
fn a_light_seen_whole_is_reported_and_can_be_held() {
    let start = paper_start("table1.png");
    let fit = |held: &[Option<streaklight::fitting::Rect>], direct_view: bool| {
        start.fit(|o| JointOptions {
            samples: 32,
            held,
            direct_view,
            ..o
        })
    };
    let free = fit(&[], true);
    assert_eq!(free.lights.len(), 1);
    let r = free.lights[0].rect();
    assert_eq!(free.seen_whole, vec![Some(r)]);
    assert_eq!(fit(&[], false).seen_whole, vec![None]);
    let footprint = 10.0 * 2.0 * 30f32.to_radians().tan() / 600.0;
    let u = &free.uncertainty[0];
    for side in streaklight::fitting::EdgeSide::ALL {
        let bound = u.image_bound[side].expect("bounded by the image");
        assert!(
            bound >= footprint / 3f32.sqrt() && bound <= 1.16 * footprint / 3f32.sqrt(),
            "{side:?}: {bound}"
        );
        assert!(u.edges[side].unwrap() <= bound, "{u:?}");
    }

    let higher = streaklight::fitting::Rect {
        v_min: r.v_min + 0.1,
        v_max: r.v_max + 0.1,
        ..r
    };
    let held = fit(&[Some(higher)], true);
    assert_eq!(held.lights.len(), 1);
    assert_eq!(held.lights[0].rect(), higher);
    let bound = held.uncertainty[0].image_bound;
    assert_eq!(
        (
            bound[streaklight::fitting::EdgeSide::Top],
            bound[streaklight::fitting::EdgeSide::Bottom]
        ),
        (None, None),
        "{bound:?}"
    );
    assert!(
        held.cost > free.cost,
        "held {} against free {}",
        held.cost,
        free.cost
    );
    let ignored = fit(&[Some(higher), None], true);
    assert_eq!(ignored.lights, free.lights);
}

/// Table 3's second lamp is cut by the photo's right border, and its reflections with it: its
/// right edge is not pinned by its image, and the photo does not tell it (no sigma, or one
/// larger than the light), while its other three edges are pinned. The fit reports it seen
/// whole all the same, as it does the whole lamp, so a search holds both rather than
/// descending the cut one at every evaluation (`JointOutcome::seen_whole`).
#[test]
fn a_lamp_the_frame_cuts_is_seen_whole_by_the_edges_the_photo_shows() {
    let start = paper_start("table3.png");
    let free = start.fit(|o| JointOptions { samples: 32, ..o });
    assert_eq!(free.lights.len(), 2, "{:?}", free.lights);
    let cut = (0..2)
        .max_by(|&a, &b| free.lights[a].u_min.total_cmp(&free.lights[b].u_min))
        .unwrap();
    let u = &free.uncertainty[cut];
    let width = free.lights[cut].u_max - free.lights[cut].u_min;
    use streaklight::fitting::EdgeSide;
    assert!(u.image_bound[EdgeSide::Right].is_none(), "{u:?}");
    assert!(u.edges[EdgeSide::Right].is_none_or(|s| s > width), "{u:?}");
    for side in [EdgeSide::Left, EdgeSide::Bottom, EdgeSide::Top] {
        assert!(u.image_bound[side].is_some(), "{side:?}: {u:?}");
    }
    let rects: Vec<_> = free.lights.iter().map(|l| Some(l.rect())).collect();
    assert_eq!(free.seen_whole, rects);
}

/// A light resumed near its optimum (`JointOptions::resume`) is descended from there, its
/// edges searched a fraction of a pixel's footprint around it, and ends where the fit from
/// the start ends: Table 1's light, resumed where the free fit put it and 3 cm (a footprint
/// and a half) higher, where its image no longer bounds its top and bottom and they search
/// wide, comes back to the free fit's rectangle within twice the descent's finest window
/// (1 mm, a 3000th of the 3 m light) on every edge; after one sweep from the free fit's
/// rectangle it is still there, while one sweep from the start leaves it further off. Held
/// wins where both are given.
#[test]
fn a_light_resumed_near_its_optimum_ends_where_the_free_fit_does() {
    let start = paper_start("table1.png");
    let fit = |held: &[Option<streaklight::fitting::Rect>],
               resume: &[Option<streaklight::fitting::Rect>]| {
        start.fit(|o| JointOptions {
            samples: 32,
            held,
            resume,
            ..o
        })
    };
    let free = fit(&[], &[]);
    assert_eq!(free.lights.len(), 1);
    let r = free.lights[0].rect();
    let finest = 3.0 / 3000.0;
    let higher = |dv: f32| streaklight::fitting::Rect {
        v_min: r.v_min + dv,
        v_max: r.v_max + dv,
        ..r
    };
    for dv in [0.0, 0.03] {
        let resumed = fit(&[], &[Some(higher(dv))]);
        assert_eq!(resumed.lights.len(), 1);
        let got = resumed.lights[0].rect();
        for (a, b) in [
            (got.u_min, r.u_min),
            (got.u_max, r.u_max),
            (got.v_min, r.v_min),
            (got.v_max, r.v_max),
        ] {
            assert!((a - b).abs() <= 2.0 * finest, "{dv}: {got:?} against {r:?}");
        }
    }
    // One sweep: resumed where the free fit ended, the light stays there; from the start
    // it does not get there.
    let one_sweep = |resume: &[Option<streaklight::fitting::Rect>]| {
        start
            .fit(|o| JointOptions {
                samples: 32,
                sweeps: 1,
                resume,
                ..o
            })
            .lights[0]
            .rect()
    };
    let off = |got: streaklight::fitting::Rect| {
        [
            got.u_min - r.u_min,
            got.u_max - r.u_max,
            got.v_min - r.v_min,
            got.v_max - r.v_max,
        ]
        .map(f32::abs)
        .into_iter()
        .fold(0.0, f32::max)
    };
    let (kept, from_start) = (off(one_sweep(&[Some(r)])), off(one_sweep(&[])));
    eprintln!("one sweep: resumed {kept}, from the start {from_start}");
    assert!(kept <= 2.0 * finest, "{kept}");
    assert!(from_start > 2.0 * finest, "{from_start}");
    let held = fit(&[Some(higher(0.1))], &[Some(higher(0.03))]);
    assert_eq!(held.lights[0].rect(), higher(0.1));
}
