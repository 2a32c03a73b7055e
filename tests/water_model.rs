//! The water model a fit inverts (docs/method.md §10), chosen from the photo: the exact model
//! on a photo of the scene's own waves, the statistical model where the scene's water is not
//! the photo's (here: the same scene with its water flattened to a quad, as a game scene
//! holds it).

mod common;

use common::pipeline::{sample_photo, sample_scene};
use common::truth::{assert_within_sigmas, nearest};
use common::water::flattened;
use streaklight::pipeline::{self, FitSettings, WaterChoice};
use streaklight::progress::Reporter;
use streaklight::report::light_report;
use streaklight::samples;
use streaklight::samples::streak_slopes::{
    footprint, harbour_expectation, mesh_slope_variances, water_pixels,
};
use streaklight::water_model::water_statistics;

/// The settings with the water model chosen from the photo.
fn auto() -> FitSettings {
    FitSettings {
        water: WaterChoice::Auto,
        ..FitSettings::default()
    }
}

/// Table 1's photo was rendered from the scene's own water mesh: the fit keeps the exact model,
/// having measured that the fine structures match (0.86 when this was written; a photo of
/// other waves gives about 0).
#[test]
fn the_scenes_own_waves_keep_the_exact_model() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let lit = pipeline::fit(&scene, &photo, &auto(), Reporter::default()).unwrap();
    let used = &lit.water_model;
    assert_eq!((used.model, used.chosen), ("exact", "detected"));
    let c = used.fine_structure_correlation.unwrap();
    assert!(c > 0.6, "correlation {c}");
    assert!(used.reason.contains("matches"), "{}", used.reason);
    assert!(used.slopes.is_none());
    assert_eq!(lit.lights.len(), 1);
}

/// The same photo against the scene with its water a flat quad: no waves whose fine structure
/// could match, so the statistical model is chosen at once, and the report says the water is
/// flat; one light, its width within 3 % (the across slopes are
/// told well by the photo), the across slope variance within 15 % of the rendered mesh's plus
/// its microfacets' (2.24e-3 both when this was written), and uncertainties grown by the
/// residual's correlation (the glitter of a few long waves: 44 pixels per independent residual
/// here). Every edge (pinned by the light's direct image) and every radiance channel lies
/// within 3 of its reported sigmas: the radiance, which the direct image clipped in every
/// channel leaves to the reflections, comes out 7.5 % low, the photo's waves holding 9 % less
/// light than their expectation (the test below), and its sigma is held at 10 % of it at
/// least ([`streaklight::fitting::slopes::REALISATION_FLUX`]). Not all of that shortfall is
/// this photo's waves: over 16 other wave fields of the same ripples the fit's radiance came
/// out 5.2 % low on average, 1.9 % rms about that (`cargo bench --bench realisations`), so
/// the expectation close to the water holds about 5 % more light than such waves reflect.
/// Forcing the exact model is reported as forced.
#[test]
fn a_flat_quad_takes_the_statistical_model() {
    let waves = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let truth_stats = water_statistics(&waves, photo.width, photo.height).unwrap();
    let micro = 1.0 / (waves.water.gloss + 2.0);
    let truth_across = truth_stats.slope_variance[1] + micro;
    let flat = flattened(waves);
    let lit = pipeline::fit(&flat, &photo, &auto(), Reporter::default()).unwrap();
    let used = &lit.water_model;
    assert_eq!((used.model, used.chosen), ("statistical", "detected"));
    assert!(used.reason.contains("water is flat"), "{}", used.reason);
    assert_eq!(used.fine_structure_correlation, None, "{used:?}");
    let slopes = used.slopes.as_ref().unwrap();
    assert!(slopes.estimated);
    assert!(
        slopes.start_source.contains("flat"),
        "{}",
        slopes.start_source
    );
    assert!(
        (slopes.variance[1] / truth_across - 1.0).abs() < 0.15,
        "across {} vs {truth_across}",
        slopes.variance[1]
    );
    assert!(slopes.correlation_area.unwrap() > 4.0, "{slopes:?}");
    assert_eq!(lit.lights.len(), 1, "{:?}", lit.lights);
    let light = &lit.lights[0];
    let truth = samples::table1_light();
    assert!(
        (light.width() as f64 - truth.width).abs() < 0.03 * truth.width,
        "width {}",
        light.width()
    );
    let u = &lit.uncertainties[0];
    assert!(!u.radiance_seen, "{u:?}");
    let report = light_report(&flat, light, Some(u), "light".into());
    assert_within_sigmas(&report, &truth, 3.0);
    let forced = FitSettings {
        water: WaterChoice::Exact,
        ..FitSettings::default()
    };
    let lit = pipeline::fit(&flat, &photo, &forced, Reporter::default()).unwrap();
    assert_eq!(
        (lit.water_model.model, lit.water_model.chosen),
        ("exact", "forced")
    );
}

/// Table 3's two lamps over the flat quad: the whole one, and one the photo's right border
/// cuts, whose image sits exactly at the clip in the channels it lights (radiance 10 at
/// exposure 0.1). Held: the statistical model, one light per lamp, and every error within 3
/// of its reported sigmas (measured: at most 1.6). While the descent's edge profiles solved
/// the radiance without the clipped pixels, which then held it up only through their cost,
/// the cut lamp's bottom edge came out 1.6 mm high at 3.1 sigmas.
#[test]
fn a_lamp_held_at_the_clip_over_a_flat_quad_stays_within_its_sigmas() {
    let flat = flattened(sample_scene("scene.gltf", None));
    let photo = sample_photo("table3.png");
    let lit = pipeline::fit(&flat, &photo, &auto(), Reporter::default()).unwrap();
    assert_eq!(lit.water_model.model, "statistical");
    assert_eq!(lit.lights.len(), 2, "{:?}", lit.lights);
    let reports: Vec<_> = lit
        .lights
        .iter()
        .zip(&lit.uncertainties)
        .map(|(light, u)| light_report(&flat, light, Some(u), "light".into()))
        .collect();
    for truth in &samples::table3_lights() {
        assert_within_sigmas(nearest(&reports, truth), truth, 3.0);
    }
}

/// `gloss1000.png` over the flat quad with the material's gloss of 1000: the slope search
/// starts from the material's roughness, under half the photo's slopes along the view, and
/// climbs above its first proposal's reach after three fits. The fits after that share a
/// proposal grown to cover the first of them, rather than each tracing its own samples:
/// measured when this was written, two traces in the search and none in the final fit
/// (eight before, 3.4 s instead of 7.2 s). The lamp is found within 3 of its sigmas.
#[test]
fn a_search_beyond_its_proposal_traces_again_once() {
    let flat = flattened(sample_scene("scene.gltf", Some(1000.0)));
    let photo = sample_photo("gloss1000.png");
    let stages = std::sync::Mutex::new(Vec::new());
    let record = |line: &str| stages.lock().unwrap().push(line.to_string());
    let lit = pipeline::fit(&flat, &photo, &auto(), Reporter::new(&record)).unwrap();
    let stages = stages.into_inner().unwrap();
    assert_eq!(lit.water_model.model, "statistical");
    let traces = stages
        .iter()
        .filter(|s| s.contains("tracing the footprints"))
        .count();
    assert!(traces <= 3, "{traces} traces: {stages:#?}");
    assert_eq!(lit.lights.len(), 1, "{:?}", lit.lights);
    let report = light_report(
        &flat,
        &lit.lights[0],
        Some(&lit.uncertainties[0]),
        "light".into(),
    );
    assert_within_sigmas(&report, &samples::table1_light(), 3.0);
}

/// The smallest end-to-end case (the paper's geometry in miniature: camera 0.2 m above a flat
/// quad of gloss 500, a 3 m x 3 m light of radiance 20 on the wall 10 m away, a 160 x 160
/// photo at 4 samples per pixel) at the defaults: the water is flat, so the statistical model
/// is used, and the light comes out within 3 % of its size in every edge and 3 % in radiance.
/// From the reflections alone its height is not told at this grazing angle (the paper's
/// estimate starts it 11 m tall); its direct image, enclosed by the dark wall, settles it.
#[test]
fn a_small_flat_scene_at_the_defaults() {
    let dir = common::temp_dir("water-model-small-flat");
    let (scene_path, photo_path) = common::fit_case::good_case(&dir);
    let scene = streaklight::scene_in::load(&scene_path, &Default::default()).unwrap();
    let photo = streaklight::photo_in::load(&photo_path, common::fit_case::EXPOSURE).unwrap();
    let lit = pipeline::fit(&scene, &photo, &FitSettings::default(), Reporter::default()).unwrap();
    assert_eq!(
        lit.water_model.model, "statistical",
        "{:?}",
        lit.water_model
    );
    assert_eq!(lit.lights.len(), 1, "{:?}", lit.lights);
    let l = &lit.lights[0];
    // The truth (tests/common/fit_case.rs): x in [-1.5, 1.5], y in [2, 5] on the wall z = 0.
    let a = l.world_at(scene.origin, l.u_min, l.v_min);
    let b = l.world_at(scene.origin, l.u_max, l.v_max);
    for (name, got, truth) in [
        ("left", a.x.min(b.x), -1.5),
        ("right", a.x.max(b.x), 1.5),
        ("bottom", a.y.min(b.y), 2.0),
        ("top", a.y.max(b.y), 5.0),
    ] {
        assert!(
            (got - truth).abs() < 0.03 * 3.0,
            "{name} edge {got} against {truth}"
        );
    }
    for c in l.radiance {
        assert!((c / 20.0 - 1.0).abs() < 0.03, "radiance {c} against 20");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The statistical model's expected image against a photo of one wave field, with the true
/// lights and the waves' slope variances taken from their spectrum (not fitted): the harbour
/// pair out of frame (`harbour-pair-above.png`, rendered over the scene's own mesh, 64 rays
/// per pixel). Per light (each in its own half of the photo, read in its strongest channel):
/// the reflected flux within 4 % of the photo's and the streak's centroid within 6 pixels (a
/// sixth of the shorter streak's spread along the view, 34 pixels). Measured when this was
/// written: flux -0.0 % and +2.7 %, centroids 0.6 and 3.8 pixels off. The streaks' lengths
/// along the view (the rows' standard deviation) are where one realisation of the waves
/// departs from the expectation: the orange light's is 4.6 % longer
/// in the model, the blue light's 29 % longer, so a fit from the reflections alone, which
/// trades the lights' heights against the slope variance along the view, cannot recover both
/// heights (docs/method.md §10). The test holds that too, as the reason the out-of-frame
/// statistical fits are not yet usable: if a model change made the blue streak's expected
/// length match, that reason would have to be looked at again.
///
/// Why the blue streak is short: the water under it. Over each streak's footprint (the
/// pixels where the model's image passes 2 % of that streak's peak), the slopes of the mesh
/// the photo was rendered from (its shading normals, against the mean plane's axes, four
/// camera rays a pixel): along the view 3.25e-3 under the orange streak and 2.01e-3 under
/// the blue one (the spectrum's 3.6e-3 over the whole field), across 1.73e-3 and 1.90e-3
/// (1.6e-3). One realisation of a field of 0.15-3 m waves holds 38 % less slope variance
/// along the view under one streak than under the other, so no single pair of slope
/// variances gives both streaks their lengths, and one photo's estimate is a compromise
/// between them.
#[test]
fn the_expected_image_holds_the_photos_flux_and_centroids() {
    use streaklight::render::{render, RenderOptions};

    let scene = sample_scene("harbour-pair-above-truth.gltf", None);
    let photo = sample_photo("harbour-pair-above.png");
    let (w, h) = (photo.width, photo.height);
    let water = harbour_expectation(&scene, w, h).unwrap();
    let model = render(
        &scene,
        &RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: 64,
            water: Some(&water),
            ..Default::default()
        },
    )
    .unwrap();
    // Flux, centroid (column, row) and the rows' standard deviation of channel `ch` over
    // the columns `columns`.
    let moments = |img: &[[f32; 3]], ch: usize, columns: std::ops::Range<u32>| {
        let (mut s, mut sx, mut sy, mut syy) = (0.0f64, 0.0, 0.0, 0.0);
        for (i, p) in img.iter().enumerate() {
            let (x, y) = ((i as u32 % w) as f64, (i as u32 / w) as f64);
            if columns.contains(&(i as u32 % w)) {
                let v = p[ch] as f64;
                s += v;
                sx += v * x;
                sy += v * y;
                syy += v * y * y;
            }
        }
        let (cx, cy) = (sx / s, sy / s);
        (s, cx, cy, (syy / s - cy * cy).sqrt())
    };
    let mut lengths = Vec::new();
    for (name, ch, columns) in [("orange", 0, 0..w / 2), ("blue", 2, w / 2..w)] {
        let p = moments(&photo.radiance, ch, columns.clone());
        let m = moments(&model.pixels, ch, columns);
        let flux = m.0 / p.0 - 1.0;
        let off = (m.1 - p.1).hypot(m.2 - p.2);
        println!(
            "{name}: flux {:+.2} %, centroid {off:.2} pixels off, rows' sd {:.1} (photo {:.1})",
            100.0 * flux,
            m.3,
            p.3
        );
        assert!(flux.abs() < 0.04, "{name}: flux {:+.1} %", 100.0 * flux);
        assert!(off < 6.0, "{name}: centroid {off:.1} pixels off");
        lengths.push(m.3 / p.3 - 1.0);
    }
    assert!(lengths[0].abs() < 0.1, "orange length {:+.3}", lengths[0]);
    assert!(lengths[1] > 0.15, "blue length {:+.3}", lengths[1]);
    // The mesh's slope variances (along, across the view) over each streak's footprint.
    let mut under = Vec::new();
    for (name, ch, columns) in [("orange", 0, 0..w / 2), ("blue", 2, w / 2..w)] {
        let in_half = |i: usize| columns.contains(&(i as u32 % w));
        let pixels = footprint(&model.pixels, in_half, |p| p[ch], 0.02);
        let var = mesh_slope_variances(&scene, &water, &pixels, w, h).unwrap();
        println!(
            "{name}: the mesh's slope variances under the streak {:.2e} along, {:.2e} across",
            var[0], var[1]
        );
        under.push(var);
    }
    assert!(
        under[1][0] < 0.75 * under[0][0],
        "along the view: {:.2e} under the blue streak, {:.2e} under the orange",
        under[1][0],
        under[0][0]
    );
}

/// The statistical model's reflected rays leave the mean plane and count hits only above the
/// scene's highest crest, where no water triangle lies ahead: there the BVH over the other
/// triangles (`Scene::closest_hit_above_water`) must give the hit the whole scene's gives,
/// triangle and distance, for rays spread as a wave field's reflections are (the mirror
/// direction tilted by slopes of up to 0.15 either way) from every part of the harbour photo.
#[test]
fn reflected_rays_above_the_crests_meet_what_the_whole_scene_shows_them() {
    use glam::Vec3;
    use streaklight::random::Rng;
    use streaklight::water_model::{StatisticalSurface, WaterModel};

    let scene = sample_scene("harbour-other-waves.gltf", None);
    let (w, h) = (600, 600);
    let water = StatisticalSurface {
        surface: water_statistics(&scene, w, h).unwrap().surface,
        waves: [3e-3, 2e-3],
    };
    assert!(water.surface.crest > 0.0, "{:?}", water.surface);
    let mut rng = Rng::new(7, 0);
    let (mut rays, mut walls, mut grazing) = (0, 0, 0);
    for _ in 0..40_000 {
        let (x, y) = (rng.next_f32() * w as f32, rng.next_f32() * h as f32);
        let Some(p) = water.water_point(&scene, x, y, w, h) else {
            continue;
        };
        let mirror = p.normal * (2.0 * p.normal.dot(p.wo)) - p.wo;
        let tilt = Vec3::new(
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
        );
        let wi = (mirror + 0.3 * tilt).normalize();
        if wi.dot(p.face) <= 0.0 {
            continue;
        }
        rays += 1;
        let whole = scene
            .tracer
            .closest_hit(p.start, wi, p.tmin(wi), f32::INFINITY);
        assert_eq!(
            p.reflected_hit(&scene, wi, f32::INFINITY),
            whole,
            "{p:?} {wi}"
        );
        if let Some(hit) = whole {
            assert!(!scene.is_water[hit.triangle as usize], "{p:?} {wi} {hit:?}");
            walls += 1;
        }
        grazing += (wi.dot(p.face) < 0.05) as usize;
    }
    // Most rays reach the facades, and some leave the water within 3 degrees of it (where a
    // ray walks farthest under the crests).
    assert!(
        rays > 10_000 && walls * 2 > rays,
        "{rays} rays, {walls} on walls"
    );
    assert!(grazing > 100, "{grazing} grazing rays of {rays}");
}

/// The harbour sign (a warm white light whose direct image clips in every channel, so that
/// only its reflections give its radiance): the exact render over the photo's waves is the
/// photo, and the photo holds 5.4 % less light over the water than the statistical model's
/// expectation at the waves' own slope variances (3 % less at 0.7 times them, 3 % more at 1.4
/// times). One realisation of the waves, not the model, sets how far that radiance can be
/// trusted: the fit gives it 4.0 % low (README).
#[test]
fn the_signs_photo_holds_less_light_than_its_expectation() {
    use streaklight::render::{render_with_lights, RenderOptions};

    let scene = sample_scene("harbour-sign-truth.gltf", None);
    let photo = sample_photo("harbour-sign.png");
    let (w, h) = (photo.width, photo.height);
    let on_water = water_pixels(&scene, w, h);
    let flux = |img: &[[f32; 3]]| -> f64 {
        img.iter()
            .zip(&on_water)
            .filter(|(_, &on)| on)
            .map(|(p, _)| (p[0] + p[1] + p[2]) as f64)
            .sum()
    };
    let water = harbour_expectation(&scene, w, h).unwrap();
    let options = RenderOptions {
        width: w,
        height: h,
        samples_per_pixel: 64,
        ..Default::default()
    };
    let exact = render_with_lights(&scene, &scene.area_lights, &options).unwrap();
    let expected = render_with_lights(
        &scene,
        &scene.area_lights,
        &RenderOptions {
            water: Some(&water),
            ..options
        },
    )
    .unwrap();
    let own = flux(&exact.pixels) / flux(&photo.radiance);
    let waves = flux(&photo.radiance) / flux(&expected.pixels);
    println!("exact over the photo's waves / photo {own:.4}, photo / expected {waves:.4}");
    assert!((own - 1.0).abs() < 0.015, "{own}");
    assert!((0.92..0.97).contains(&waves), "{waves}");
}

/// The quick test ahead of the exact fit (`water_model::clearly_wavy`): a quarter of the
/// statistics' camera rays and the seen normals' own mean as the plane. On both sample wave
/// meshes its slope variances lie within 15 % of [`water_statistics`]'s on each axis
/// (measured when this was written: within 5 %), so a mesh it calls clearly wavy (three
/// times the flatness threshold) is not flat by the full statistics; on a flat quad it never
/// calls the water wavy, whatever the threshold.
#[test]
fn a_clearly_wavy_mesh_is_told_by_a_quarter_of_the_rays() {
    use streaklight::water_model::clearly_wavy;
    let (w, h) = (600, 600);
    for name in ["scene.gltf", "harbour.gltf"] {
        let scene = sample_scene(name, None);
        let full = water_statistics(&scene, w, h).unwrap().slope_variance;
        for axis in 0..2 {
            // Over `factor` times the full variance on `axis` alone.
            let over = |factor: f32| {
                let mut threshold = [f32::INFINITY; 2];
                threshold[axis] = factor * full[axis] / 3.0;
                clearly_wavy(&scene, w, h, threshold)
            };
            assert!(
                over(0.85),
                "{name}, axis {axis}: under 0.85 of {:e}",
                full[axis]
            );
            assert!(
                !over(1.15),
                "{name}, axis {axis}: over 1.15 of {:e}",
                full[axis]
            );
        }
        let flat = flattened(scene);
        assert!(
            !clearly_wavy(&flat, w, h, [1e-12, 1e-12]),
            "{name} flattened"
        );
    }
}
