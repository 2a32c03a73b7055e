//! The harbour layouts (docs/method.md §10; README, "Sample photos") fitted at the defaults
//! with their lamps in frame: over the photo's own waves the exact model is kept, over
//! another realisation of the same waves and over the flat quad a game scene holds the
//! statistical model is chosen, and every light (the pair: an orange 4 x 2 m and a blue
//! 3 x 1.5 m light 40 m from a camera 2 m above the water; three lights of different sizes
//! and colours; a warm white sign) comes out within 3 % of its size in every edge, and, where
//! its image leaves a channel unclipped, within 3 % of its radiance in every channel (the
//! statistical water's bar; measured on the pair: 0.10 % and 0.5 % exact, 0.06 % and 0.61 %
//! statistical). The lamps out of frame are `tests/far_lights.rs`'.

mod common;

use common::pipeline::{observations, sample_photo, sample_scene, water};
use streaklight::fitting::slopes::{water_with_total, MICROFACET_GLOSS, SLOPE_REALISATION_LN};
use streaklight::fitting::FittedLight;
use streaklight::photo_in::Photo;
use streaklight::pipeline::{self, FitSettings, Lit};
use streaklight::progress::Reporter;
use streaklight::render::{render_with_lights, RenderOptions};
use streaklight::samples::streak_slopes::lobe_under_streaks;
use streaklight::samples::{self, harbour};
use streaklight::scene_in::Scene;
use streaklight::water_model::water_statistics;

/// Every truth light of harbour layout `layout` has one fitted light whose edges are within
/// 3 % of its size; no other light. A light whose image shows some channel unclipped (the
/// pair's, the three lights') has its radiance read off the image: within 3 % per channel,
/// every channel's sigma under 2 % (measured: 0.3-0.5 %, the images' 8-bit rounding; it was
/// 12-24 % while the pixels clipped in any channel were left out, and the water's correlation
/// grew the image's share too), and the error within 3 of it. A light its image clips in
/// every channel (the warm white sign) has only the reflections to give its radiance, and one
/// realisation of the waves gives it no better than that realisation holds the expected
/// light (the sign's photo holds 5.4 % less than its expectation:
/// `tests/water_model.rs`, `the_signs_photo_holds_less_light_than_its_expectation`; over 16
/// other wave fields the fit's radiance scatters by 7.8 % rms, `cargo bench --bench
/// realisations`): held within 3 of its sigma (a sigma too small for that shortfall fails
/// there) and the sigma under 11 %, the realisations' floor of 10 % of the radiance fitted
/// (measured: 3.0-3.6 % low at sigma 9.6 %).
fn assert_layout(layout: &str, scene: &Scene, lit: &Lit) {
    let layouts = harbour::layouts();
    let truths = &layouts.iter().find(|l| l.0 == layout).unwrap().2;
    assert_eq!(lit.lights.len(), truths.len(), "{:?}", lit.lights);
    let bounds = |l: &FittedLight| {
        let a = l.world_at(scene.origin, l.u_min, l.v_min);
        let b = l.world_at(scene.origin, l.u_max, l.v_max);
        [a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y)]
    };
    let mut matched = Vec::new();
    for t in truths {
        let want = [
            t.corner.x,
            t.corner.x + t.width,
            t.corner.y,
            t.corner.y + t.height,
        ];
        let centre = |b: [f64; 4]| ((b[0] + b[1]) / 2.0, (b[2] + b[3]) / 2.0);
        let (tx, ty) = centre(want);
        let d = |l: &FittedLight| {
            let (x, y) = centre(bounds(l));
            (x - tx).hypot(y - ty)
        };
        let k = (0..lit.lights.len())
            .min_by(|&a, &b| d(&lit.lights[a]).total_cmp(&d(&lit.lights[b])))
            .unwrap();
        assert!(!matched.contains(&k), "{}: light {k} matched twice", t.name);
        matched.push(k);
        let (fitted, sigma) = (&lit.lights[k], &lit.uncertainties[k]);
        let got = bounds(fitted);
        for (k, name) in ["left", "right", "bottom", "top"].iter().enumerate() {
            let size = if k < 2 { t.width } else { t.height };
            let error = (got[k] - want[k]) / size;
            assert!(
                error.abs() < 0.03,
                "{}: {name} edge {:.4} against {:.4} ({:+.2} % of its size)",
                t.name,
                got[k],
                want[k],
                100.0 * error
            );
        }
        let (bar, sigma_bar) = if sigma.radiance_seen {
            (Some(0.03), 0.02)
        } else {
            (None, 0.11)
        };
        for c in 0..3 {
            let error = fitted.radiance[c] as f64 / t.radiance[c] - 1.0;
            assert!(
                bar.is_none_or(|bar| error.abs() < bar),
                "{}: radiance {:?} against {:?}",
                t.name,
                fitted.radiance,
                t.radiance
            );
            let sd = sigma.radiance[c] as f64;
            let off = fitted.radiance[c] as f64 - t.radiance[c];
            assert!(
                sd < sigma_bar * t.radiance[c] && off.abs() < 3.0 * sd,
                "{}: radiance {:?} against {:?}, sigma {:?} (seen: {})",
                t.name,
                fitted.radiance,
                t.radiance,
                sigma.radiance,
                sigma.radiance_seen
            );
        }
    }
}

/// The total slope variances (the lobe's whole, along and across the view) of the mesh harbour
/// layout `layout`'s photo was rendered from, where its streaks lie ([`lobe_under_streaks`]:
/// its shading normals' slopes over the union of the lights' footprints in the expected
/// image, each pixel counted once), plus the photo's microfacets (gloss
/// [`harbour::HARBOUR_GLOSS`]: 1 / (e + 2) a axis) less the statistical model's own
/// ([`MICROFACET_GLOSS`]), since the fit's variances are the whole lobe's less those. Made
/// once per layout.
fn mesh_under_streaks(layout: &str) -> [f64; 2] {
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, OnceLock};
    type Made = Mutex<HashMap<String, Arc<OnceLock<[f64; 2]>>>>;
    static MADE: OnceLock<Made> = OnceLock::new();
    // One cell per layout, taken under the lock and filled outside it: tests of other
    // layouts measure at the same time, tests of the same one wait for the first.
    let cell = MADE
        .get_or_init(Default::default)
        .lock()
        .unwrap()
        .entry(layout.to_string())
        .or_default()
        .clone();
    *cell.get_or_init(|| {
        let scene = sample_scene(&format!("harbour-{layout}-truth.gltf"), None);
        let photo = sample_photo(&format!("harbour-{layout}.png"));
        let total = lobe_under_streaks(
            &scene,
            photo.width,
            photo.height,
            harbour::HARBOUR_GLOSS,
            MICROFACET_GLOSS as f64,
        )
        .unwrap();
        println!(
            "{layout}: the mesh's slope variances under the streaks {:.3e} along, {:.3e} \
             across (the lobe's whole, less the model's microfacets)",
            total[0], total[1]
        );
        total
    })
}

/// The slope variances the fit `lit` of harbour layout `layout`'s photo (lamps in frame)
/// estimated, against [`mesh_under_streaks`]: along the view within 15 %; across within 15 %
/// or within its reported sigma (at least [`SLOPE_REALISATION_LN`], 0.43 in the logarithm:
/// over 16 realisations of the sign's waves the estimate across was that far off, rms).
/// Across the view a slope turns a reflection sideways by only twice the sine of the grazing
/// angle (3 degrees at 40 m from a camera 2 m above the water), so the streaks' widths are
/// mostly the lights' own and the variance across is told weakly. Measured (over the other
/// waves, over the flat quad; mesh 3.15e-3 along and 2.25e-3 across for the pair, 4.29e-3
/// and 1.81e-3 for the sign, 4.06e-3 and 2.16e-3 for the three lights): along -6.1 / -6.4 %
/// for the pair, -14.4 / -14.9 % for the sign, -1.7 / +2.5 % for the three lights; across
/// the pair +13.9 % / +19.1 %, the sign +25.1 % / -14.7 %, the three lights -6.0 / -10.7 %.
fn assert_slopes(layout: &str, lit: &Lit) {
    let mesh = mesh_under_streaks(layout);
    let slopes = lit.water_model.slopes.as_ref().unwrap();
    for (axis, name) in ["along", "across"].into_iter().enumerate() {
        let ratio = slopes.variance[axis] as f64 / mesh[axis];
        let sigma = slopes.sigma_ln[axis].map_or(0.0, |s| s as f64);
        let within = (ratio - 1.0).abs() < 0.15 || (axis == 1 && ratio.ln().abs() < sigma);
        assert!(
            within,
            "{layout}: slope variance {name} {:.3e} against the mesh's {:.3e} under the \
             streaks ({:+.1} %, sigma of its logarithm {sigma:.3})",
            slopes.variance[axis],
            mesh[axis],
            100.0 * (ratio - 1.0)
        );
    }
    assert!(
        (0..2).all(|a| slopes.sigma_ln[a].is_some_and(|s| s >= SLOPE_REALISATION_LN[a])),
        "{slopes:?}"
    );
}

/// [`assert_layout`] of the pair.
fn assert_pair(scene: &Scene, lit: &Lit) {
    assert_layout("pair", scene, lit);
}

/// `fit` at the defaults of harbour layout `layout`'s photo with its lamps in frame against
/// sample scene `scene`: the statistical model, chosen by the photo, the lights as
/// [`assert_layout`] holds them, and the slope variances as [`assert_slopes`] does.
fn statistical_in_frame(scene: &str, layout: &str) {
    let (_, lit) = statistical_fit(
        scene,
        &sample_photo(&format!("harbour-{layout}.png")),
        layout,
    );
    assert_slopes(layout, &lit);
}

/// `fit` at the defaults of `photo`, a photo of harbour layout `layout`, against sample scene
/// `scene`: the statistical model, chosen by the photo, and the lights as [`assert_layout`]
/// holds them; returns the scene and the fit.
fn statistical_fit(scene: &str, photo: &Photo, layout: &str) -> (Scene, Lit) {
    let fitting = sample_scene(scene, None);
    let lit = pipeline::fit(
        &fitting,
        photo,
        &FitSettings::default(),
        Reporter::default(),
    )
    .unwrap();
    let used = &lit.water_model;
    assert_eq!(
        (used.model, used.chosen),
        ("statistical", "detected"),
        "{used:?}"
    );
    assert_layout(layout, &fitting, &lit);
    (fitting, lit)
}

#[test]
fn the_photos_own_waves_keep_the_exact_model() {
    let scene = sample_scene("harbour.gltf", None);
    let photo = sample_photo("harbour-pair.png");
    let lit = pipeline::fit(&scene, &photo, &FitSettings::default(), Reporter::default()).unwrap();
    let used = &lit.water_model;
    assert_eq!((used.model, used.chosen), ("exact", "detected"), "{used:?}");
    assert_pair(&scene, &lit);
}

/// The exact model is tested at the paper's first estimate, on the streaks' pixels, and
/// found unrelated to the photo there. Both lamps are in the photo, so the slope search's fits
/// after its first hold them where that fit put them, and the final fit tries neither as two lights: each is one lamp's image.
/// Every light of the start lies on its lamp's whole image, so the start is the paper's
/// estimate at 128 lobe samples a pixel, not 512 (which out of frame it is:
/// `tests/far_lights.rs`).
#[test]
fn other_waves_take_the_statistical_model() {
    let scene = sample_scene("harbour-other-waves.gltf", None);
    let photo = sample_photo("harbour-pair.png");
    let stages = std::sync::Mutex::new(Vec::new());
    let record = |line: &str| stages.lock().unwrap().push(line.to_string());
    let lit = pipeline::fit(
        &scene,
        &photo,
        &FitSettings::default(),
        Reporter::new(&record),
    )
    .unwrap();
    let stages = stages.into_inner().unwrap();
    assert!(
        stages
            .iter()
            .any(|s| s.contains("2 light(s) seen whole in the photo held")),
        "{stages:#?}"
    );
    assert!(!stages.iter().any(|s| s.contains("as two")), "{stages:#?}");
    let used = &lit.water_model;
    assert_eq!(
        (used.model, used.chosen),
        ("statistical", "detected"),
        "{used:?}"
    );
    assert!(
        used.fine_structure_correlation.unwrap() < 0.2,
        "{}",
        used.reason
    );
    // So far from the photo already at the paper's first estimate of the lights (not kept:
    // the exact model over other waves puts a light off its lamp's image) that neither the
    // estimate at the full samples nor the exact joint fit is made.
    assert!(
        used.reason
            .contains("neither the full estimate nor the exact fit was made"),
        "{}",
        used.reason
    );
    let stage = |name: &str| lit.timings.iter().any(|(s, _)| s.contains(name));
    assert!(
        stage("the exact model tested at the first estimate"),
        "{:?}",
        lit.timings
    );
    assert!(!stage("fit: joint footprints"), "{:?}", lit.timings);
    assert!(used.slopes.as_ref().unwrap().estimated);
    assert_eq!(used.slopes.as_ref().unwrap().start_samples, 128);
    assert_pair(&scene, &lit);
    assert_slopes("pair", &lit);
}

/// With the gloss searched as well (`--gloss auto`), the exact model's gloss search takes
/// the automatic choice's start gate at its first fit: over the other waves it ends there,
/// asked once, with no estimate and no light, its start image unrelated to the photo (the
/// statistical fit that follows is `other_waves_take_the_statistical_model`'s).
#[test]
fn other_waves_end_a_gloss_search_at_its_first_fit() {
    use streaklight::fitting::gloss::{estimate_gloss, GlossSearch};
    use streaklight::fitting::joint::{JointOptions, ModelledPixel, StartGate};
    use streaklight::fitting::FitOptions;
    use streaklight::optics::ReflectionModel;
    use streaklight::pipeline::fine_structure_of;
    let scene = sample_scene("harbour-other-waves.gltf", None);
    let photo = sample_photo("harbour-pair.png");
    let water = water(&scene, &photo);
    let observations = observations(&photo, &water);
    let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
    let asked = std::sync::atomic::AtomicUsize::new(0);
    let gate = |image: &[ModelledPixel]| {
        asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        !fine_structure_of(&photo, scene.camera.yfov, image).is_some_and(|f| f.clearly_not_exact())
    };
    let estimate = estimate_gloss(
        &scene,
        &photo,
        &water,
        &observations,
        &FitOptions {
            samples: 256,
            seed: 1,
            model,
        },
        None,
        &JointOptions {
            start_gate: Some(StartGate(&gate)),
            ..JointOptions::new(model, 1)
        },
        &GlossSearch::default(),
    )
    .unwrap();
    assert!(estimate.stopped_at_start);
    assert_eq!(asked.into_inner(), 1);
    assert!(estimate.lights.is_empty() && estimate.evaluations.is_empty());
    let start = fine_structure_of(&photo, scene.camera.yfov, &estimate.modelled).unwrap();
    assert!(start.correlation.unwrap().abs() < 0.15, "{start:?}");
}

/// The slope variances of a lobe known exactly. The photo is the statistical model's expected
/// image of the pair over the harbour's flat quad with total slope variances of 3.3e-3 along
/// the view and 2.0e-3 across (the harbour chop's over the water the lights' reflections
/// lie on), rendered as linear floats; fitted at the defaults against the same quad, whose
/// material starts the search isotropic at 3.1e-3 (e = 321). Both variances come out within
/// 5 % (measured: 2.4 % and 1.7 % high, from an isotropic start off by 6 % and 55 %), and the
/// lights within 3 %. Over real waves one photo's estimate scatters far more (method §10):
/// the slopes of the few metres of water one streak reflects differ from the waves'.
#[test]
fn known_slope_variances_are_recovered_from_an_isotropic_start() {
    let smooth = sample_scene("harbour-flat.gltf", Some(MICROFACET_GLOSS));
    let lights = sample_scene("harbour-pair-truth.gltf", None).area_lights;
    let (width, height) = (600, 600);
    let stats = water_statistics(&smooth, width, height).unwrap();
    let truth = [3.3e-3, 2.0e-3];
    let water = water_with_total(stats.surface, truth);
    let options = RenderOptions {
        width,
        height,
        samples_per_pixel: 64,
        exposure: samples::PHOTO_EXPOSURE,
        water: Some(&water),
        ..Default::default()
    };
    let image = render_with_lights(&smooth, &lights, &options).unwrap();
    let photo = Photo::from_linear(width, height, image.pixels, samples::PHOTO_EXPOSURE);
    let scene = sample_scene("harbour-flat.gltf", None);
    let lit = pipeline::fit(&scene, &photo, &FitSettings::default(), Reporter::default()).unwrap();
    let used = &lit.water_model;
    assert_eq!(used.model, "statistical", "{used:?}");
    let slopes = used.slopes.as_ref().unwrap();
    eprintln!(
        "estimated {:?} from {:?}",
        slopes.variance, slopes.start_variance
    );
    for (axis, (&got, &want)) in slopes.variance.iter().zip(&truth).enumerate() {
        let error = got as f64 / want as f64 - 1.0;
        assert!(
            error.abs() < 0.05,
            "axis {axis}: {got} against {want} ({slopes:?})"
        );
    }
    assert_pair(&scene, &lit);
}

/// The pair over the flat quad a game scene holds (`harbour-flat.gltf`): no waves to match,
/// so the statistical model, and the lights within 3 % (measured: edges within 0.06 %,
/// radiances within 0.61 %).
#[test]
fn the_pair_over_a_flat_quad() {
    statistical_in_frame("harbour-flat.gltf", "pair");
}

/// The three lights of different sizes and colours in frame over another wave field and over
/// the flat quad: each within 3 % (measured: edges within 0.07 %, radiances within 0.62 %).
#[test]
fn three_lights_over_other_waves_and_a_flat_quad() {
    for scene in ["harbour-other-waves.gltf", "harbour-flat.gltf"] {
        statistical_in_frame(scene, "three");
    }
}

/// The warm white sign in frame over another wave field and over the flat quad: its image
/// clips every channel, so its edges come from the image (within 3 %; measured 0.4-0.6 %) and its
/// radiance from the reflections alone, within its sigma ([`assert_layout`]).
#[test]
fn the_sign_over_other_waves_and_a_flat_quad() {
    for scene in ["harbour-other-waves.gltf", "harbour-flat.gltf"] {
        statistical_in_frame(scene, "sign");
    }
}

/// The sign over the wave field of seed 13 of `cargo bench --bench realisations`, the field
/// of sixteen whose reflections hold the least of the sign's light: rendered as the sample
/// photos are and fitted against the flat quad at the defaults, the sign comes out one light
/// with its edges from its image, and its radiance, which only the reflections give, 20.0 %
/// low (measured). That is one realisation of the waves, not something the fit can see, so
/// its sigma must cover it: within 3 sigmas at the realisations' floor of 10 % of the
/// radiance fitted (2.5 sigmas; 4.9 at a floor of 5 %). The report's warning says what would
/// let the photo give the radiance.
#[test]
fn a_sign_over_waves_that_reflect_little_is_within_its_sigmas() {
    use streaklight::render::render;
    use streaklight::samples::realisation::write_over_waves;

    let dir = common::dirs::temp_dir("sign-over-seed-13");
    let truth = write_over_waves("harbour-sign-truth.gltf", 13, &dir).unwrap();
    let over = streaklight::scene_in::load(&truth, &Default::default()).unwrap();
    let image = render(
        &over,
        &RenderOptions {
            width: samples::PHOTO_SIZE,
            height: samples::PHOTO_SIZE,
            samples_per_pixel: samples::PHOTO_SPP,
            exposure: samples::PHOTO_EXPOSURE,
            ..Default::default()
        },
    )
    .unwrap();
    let png = dir.join("sign-13.png");
    streaklight::photo_out::write(&png, image.width, image.height, &image.pixels).unwrap();
    let photo = streaklight::photo_in::load(&png, samples::PHOTO_EXPOSURE).unwrap();
    let (fitting, lit) = statistical_fit("harbour-flat.gltf", &photo, "sign");
    let layouts = harbour::layouts();
    let truth = &layouts.iter().find(|l| l.0 == "sign").unwrap().2[0];
    let error = lit.lights[0].radiance[0] as f64 / truth.radiance[0] - 1.0;
    assert!(error < -0.1, "radiance {:+.1} %", 100.0 * error);
    // The report warns of the radiance's uncertainty, and says what would let the photo
    // give it: the lamp's image is in the photo, clipped in every channel.
    let report = streaklight::report::light_report(
        &fitting,
        &lit.lights[0],
        Some(&lit.uncertainties[0]),
        "sign".into(),
    );
    let warning = streaklight::report::light_warnings(&report).unwrap_or_default();
    assert!(
        warning.contains("large uncertainty")
            && warning.contains("clipped in every channel")
            && warning.contains("a shorter exposure"),
        "{warning}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
