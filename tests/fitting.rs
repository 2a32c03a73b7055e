//! Round trips of the fit (METHOD §5 steps 7-9) on the committed sample photos.

mod common;
#[path = "common/fit_helpers.rs"]
mod fit_helpers;

use fit_helpers::*;
use streaklight::samples;

fn describe(outcome: &streaklight::fitting::FitOutcome, origin: glam::DVec3) {
    for l in &outcome.lights {
        let c = l.corner_left_bottom_world(origin);
        eprintln!(
            "light {:?}: corner ({:.4}, {:.4}, {:.4}) size {:.4} x {:.4} L {:?} edges {:?} hit {:.2}",
            l.streak_ids, c.x, c.y, c.z, l.width(), l.height(), l.radiance, l.edges, l.plane.hit_fraction
        );
    }
    eprintln!(
        "skipped {:?} warnings {:?} timings {:?}",
        outcome.skipped, outcome.warnings, outcome.timings
    );
}

#[test]
fn dev_table1() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let out = fit_photo(&scene, &photo);
    describe(&out, scene.origin);
    let _ = samples::table1_light();
}

#[test]
fn dev_table3() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table3.png");
    let out = fit_photo(&scene, &photo);
    describe(&out, scene.origin);
}
