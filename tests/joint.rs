//! The joint refinement (issue 5) on the committed sample photos, against the truth lights of
//! `samples` (never against the fit's own output).

mod common;
#[path = "common/fit_helpers.rs"]
mod fit_helpers;

use fit_helpers::*;
use streaklight::fitting::joint::{fit_joint, JointOptions};
use streaklight::fitting::{fit_paper, FitOptions, FittedLight};
use streaklight::samples::{self, SampleLight};
use streaklight::water_mask::water_mask;

/// Per edge, the error as a fraction of the light's size along that edge's axis; and the
/// radiance error as a fraction of the largest channel.
fn errors(light: &FittedLight, truth: &SampleLight, origin: glam::DVec3) -> ([f64; 4], f64) {
    let c = light.corner_left_bottom_world(origin);
    let (w, h) = (light.width() as f64, light.height() as f64);
    let edges = [
        (c.x - truth.corner.x) / truth.width,
        (c.x + w - truth.corner.x - truth.width) / truth.width,
        (c.y - truth.corner.y) / truth.height,
        (c.y + h - truth.corner.y - truth.height) / truth.height,
    ];
    let peak = truth.radiance.iter().cloned().fold(0.0, f64::max);
    let rad = (0..3)
        .map(|i| (light.radiance[i] as f64 - truth.radiance[i]).abs() / peak)
        .fold(0.0, f64::max);
    (edges, rad)
}

fn fit_both(photo_name: &str) -> (Vec<FittedLight>, Vec<FittedLight>, glam::DVec3) {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo(photo_name);
    let water = water_mask(&scene, photo.width, photo.height);
    let streaks = segment(&photo, &water, STREAK_THRESHOLD, 200);
    let options = FitOptions::for_scene(&scene);
    let paper = fit_paper(&scene, &photo, &water, &streaks, &options).unwrap();
    let joint = fit_joint(
        &scene,
        &photo,
        &water,
        &streaks,
        &paper.lights,
        &JointOptions::new(options.model, 1),
    )
    .unwrap();
    eprintln!(
        "joint: {} pixels, timings {:?}, sigma2 {:.3e}",
        joint.pixels, joint.timings, joint.residual_variance
    );
    for u in &joint.uncertainty {
        eprintln!("uncertainty {u:?}");
    }
    (paper.lights, joint.lights, scene.origin)
}

fn check(photo: &str, truths: &[SampleLight]) {
    let (paper, joint, origin) = fit_both(photo);
    assert_eq!(joint.len(), truths.len());
    for (k, truth) in truths.iter().enumerate() {
        let (pe, pr) = errors(&paper[k], truth, origin);
        let (je, jr) = errors(&joint[k], truth, origin);
        eprintln!(
            "{photo} light{k}: paper edges {:?} rad {:.4}; joint edges {:?} rad {:.4}",
            pe.map(|e| (e * 1e4).round() / 1e2),
            pr,
            je.map(|e| (e * 1e4).round() / 1e2),
            jr
        );
    }
    for (k, truth) in truths.iter().enumerate() {
        let (je, jr) = errors(&joint[k], truth, origin);
        for (side, e) in ["left", "right", "bottom", "top"].iter().zip(je) {
            assert!(
                e.abs() < 0.005,
                "{photo} light{k} {side} edge off by {:.3} %",
                100.0 * e
            );
        }
        assert!(
            jr < 0.01,
            "{photo} light{k} radiance off by {:.3} %",
            100.0 * jr
        );
    }
}

#[test]
fn joint_table1_within_half_a_percent() {
    check("table1.png", &[samples::table1_light()]);
}

#[test]
fn joint_table3_within_half_a_percent() {
    check("table3.png", &samples::table3_lights());
}

#[test]
#[ignore]
fn dev_from_truth() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let water = water_mask(&scene, photo.width, photo.height);
    let streaks = segment(&photo, &water, STREAK_THRESHOLD, 200);
    let options = FitOptions::for_scene(&scene);
    let paper = fit_paper(&scene, &photo, &water, &streaks, &options).unwrap();
    let truth = samples::table1_light();
    let mut start = paper.lights.clone();
    let pl = &start[0].plane;
    let a = pl.coords((truth.corner - scene.origin).as_vec3());
    let b = pl.coords(
        (truth.corner + glam::DVec3::new(truth.width, truth.height, 0.0) - scene.origin).as_vec3(),
    );
    start[0].u_min = a.x;
    start[0].v_min = a.y;
    start[0].u_max = b.x;
    start[0].v_max = b.y;
    start[0].radiance = [20.0; 3];
    let mut jo = JointOptions::new(options.model, 1);
    jo.sweeps = 0;
    let j0 = fit_joint(&scene, &photo, &water, &streaks, &start, &jo).unwrap();
    eprintln!(
        "truth rect, L solved: {:?} sigma2 {:.4e}",
        j0.lights[0].radiance, j0.residual_variance
    );
    jo.sweeps = 14;
    let j = fit_joint(&scene, &photo, &water, &streaks, &start, &jo).unwrap();
    let (e, r) = errors(&j.lights[0], &truth, scene.origin);
    eprintln!(
        "from truth: edges {:?} rad {r:.4} sigma2 {:.4e}",
        e, j.residual_variance
    );
}
