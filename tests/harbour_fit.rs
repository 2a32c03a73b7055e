//! The harbour pair (docs/method.md §10; README, "Sample photos") fitted at the defaults: over
//! the photo's own waves the exact model is kept, over another realisation of the same waves
//! the statistical model is chosen, and both give the two lights (an orange 4 x 2 m and a blue
//! 3 x 1.5 m light 40 m from a camera 2 m above the water; their direct images clip some
//! channels, not others) within 3 % of their size in every edge and 3 % of their radiance in
//! every channel (the statistical-water issue's bar; measured: 0.10 % and 0.5 % exact, 0.08 %
//! and 0.6 % statistical).

mod common;

use common::pipeline::{sample_photo, sample_scene};
use streaklight::fitting::FittedLight;
use streaklight::pipeline::{self, FitSettings, Lit};
use streaklight::progress::Reporter;
use streaklight::samples::harbour;
use streaklight::scene_in::Scene;

/// Every truth light of the pair has one fitted light whose edges are within 3 % of its size
/// and whose radiance is within 3 % per channel; no other light.
fn assert_pair(scene: &Scene, lit: &Lit) {
    let layouts = harbour::layouts();
    let truths = &layouts.iter().find(|l| l.0 == "pair").unwrap().2;
    assert_eq!(lit.lights.len(), truths.len(), "{:?}", lit.lights);
    let bounds = |l: &FittedLight| {
        let a = l.world_at(scene.origin, l.u_min, l.v_min);
        let b = l.world_at(scene.origin, l.u_max, l.v_max);
        [a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y)]
    };
    for t in truths {
        let want = [
            t.corner.x,
            t.corner.x + t.width,
            t.corner.y,
            t.corner.y + t.height,
        ];
        let centre = |b: [f64; 4]| ((b[0] + b[1]) / 2.0, (b[2] + b[3]) / 2.0);
        let (tx, ty) = centre(want);
        let fitted = lit
            .lights
            .iter()
            .min_by(|a, b| {
                let d = |l: &FittedLight| {
                    let (x, y) = centre(bounds(l));
                    (x - tx).hypot(y - ty)
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
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
        for c in 0..3 {
            let error = fitted.radiance[c] as f64 / t.radiance[c] - 1.0;
            assert!(
                error.abs() < 0.03,
                "{}: radiance {:?} against {:?}",
                t.name,
                fitted.radiance,
                t.radiance
            );
        }
    }
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

#[test]
fn other_waves_take_the_statistical_model() {
    let scene = sample_scene("harbour-other-waves.gltf", None);
    let photo = sample_photo("harbour-pair.png");
    let lit = pipeline::fit(&scene, &photo, &FitSettings::default(), Reporter::default()).unwrap();
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
    assert!(used.slopes.as_ref().unwrap().estimated);
    assert_pair(&scene, &lit);
}
