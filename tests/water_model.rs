//! The water model a fit inverts (docs/method.md §10), chosen from the photo: the exact model
//! on a photo of the scene's own waves, the statistical model where the scene's water is not
//! the photo's (here: the same scene with its water flattened to a quad, as a game scene
//! holds it).

mod common;

use common::pipeline::{sample_photo, sample_scene};
use streaklight::pipeline::{self, FitSettings, WaterChoice};
use streaklight::progress::Reporter;
use streaklight::samples;
use streaklight::scene_in::Scene;
use streaklight::tracing::{Tracer, Triangle};
use streaklight::water_model::water_statistics;

/// The settings with the water model chosen from the photo.
fn auto() -> FitSettings {
    FitSettings {
        water: WaterChoice::Auto,
        ..FitSettings::default()
    }
}

/// `scene` with its water flattened onto its mean level (world y = 0), normals straight up.
fn flattened(mut scene: Scene) -> Scene {
    let level = -scene.origin.y as f32;
    for ((t, n), &w) in scene
        .triangles
        .iter_mut()
        .zip(scene.normals.iter_mut())
        .zip(&scene.is_water)
    {
        if w {
            for v in t.iter_mut() {
                v.y = level;
            }
            *n = [glam::Vec3::Y; 3];
        }
    }
    let triangles: Vec<Triangle> = scene
        .triangles
        .iter()
        .map(|&vertices| Triangle { vertices })
        .collect();
    scene.tracer = Tracer::new(&triangles);
    scene
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
/// here). Forcing the exact model is reported as forced.
///
/// Not asserted, because it does not hold yet: the light's height and radiance. From the
/// reflections alone the height trades against the slope variance along the view (4.08 m at
/// radiance 14 for a 3 m light of 20, the along variance half the mesh's), beyond 3 of the
/// reported sigmas (docs/method.md §10).
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
