//! Fitting a linear float (OpenEXR) photo against the same render as an 8-bit PNG: one render
//! of the Table 1 truth scene, written both ways, fitted both ways, each fit checked against
//! the truth (`samples::table1_light()`), and the EXR fit no worse than the PNG's.

mod common;

use std::path::Path;

use common::pipeline::{convert_options, sample_scenes_in};
use glam::Vec3;
use streaklight::convert::convert;
use streaklight::photo_in;
use streaklight::render::{render, RenderOptions};
use streaklight::report::LightReport;
use streaklight::samples::{self, SampleLight};
use streaklight::scene_in::{self, LoadOptions};

/// Fits `photo` against the sample scene in `dir` with the default method.
fn fit(dir: &Path, photo: &Path, output: &str) -> LightReport {
    let outcome = convert(&convert_options(dir, photo, output)).unwrap();
    assert_eq!(outcome.report.lights.len(), 1, "{}", photo.display());
    outcome.report.lights[0].clone()
}

/// Errors of a fit against the truth: the four edges (left, right, bottom, top) as fractions
/// of the light's width (= height), and the radiance per channel as a fraction of the truth.
struct Errors {
    edges: [f64; 4],
    radiance: [f64; 3],
}

impl Errors {
    fn of(light: &LightReport, truth: &SampleLight) -> Self {
        let c = light.corner_left_bottom;
        let got = [c[0], c[0] + light.width, c[1], c[1] + light.height];
        let want = [
            truth.corner.x,
            truth.corner.x + truth.width,
            truth.corner.y,
            truth.corner.y + truth.height,
        ];
        let size = truth.width.max(truth.height);
        Errors {
            edges: std::array::from_fn(|i| (got[i] - want[i]) / size),
            radiance: std::array::from_fn(|i| light.radiance[i] / truth.radiance[i] - 1.0),
        }
    }

    fn largest_edge(&self) -> f64 {
        self.edges.iter().map(|e| e.abs()).fold(0.0, f64::max)
    }

    fn largest_radiance(&self) -> f64 {
        self.radiance.iter().map(|e| e.abs()).fold(0.0, f64::max)
    }

    fn print(&self, name: &str, light: &LightReport) {
        let pct = |v: &[f64]| {
            v.iter()
                .map(|e| format!("{:+.3} %", 100.0 * e))
                .collect::<Vec<_>>()
                .join(", ")
        };
        eprintln!(
            "{name}: corner ({:.4}, {:.4}), {:.4} x {:.4}, L {:.3?}; edge errors (left, right, \
             bottom, top) {} of the size; radiance errors {}",
            light.corner_left_bottom[0],
            light.corner_left_bottom[1],
            light.width,
            light.height,
            light.radiance,
            pct(&self.edges),
            pct(&self.radiance)
        );
    }
}

#[test]
fn exr_and_png_of_one_render_both_fit_table1_and_the_exr_is_no_worse() {
    let dir = sample_scenes_in("exr-fit");
    let scene = scene_in::load(&dir.join("table1-truth.gltf"), &LoadOptions::default()).unwrap();
    let options = RenderOptions {
        width: samples::PHOTO_SIZE,
        height: samples::PHOTO_SIZE,
        samples_per_pixel: 64,
        exposure: samples::PHOTO_EXPOSURE,
        seed: 1,
        ..Default::default()
    };
    let image = render(&scene, &options).unwrap();
    let (exr, png) = (dir.join("table1.exr"), dir.join("table1.png"));
    for path in [&exr, &png] {
        streaklight::photo_out::write(path, image.width, image.height, &image.pixels).unwrap();
    }

    // The EXR is read as linear and unclipped: at the centre of the directly seen light the
    // value (radiance times exposure, 2) is above 1 and gives back the radiance, 20, where the
    // PNG clips.
    let truth = samples::table1_light();
    let centre = truth.center() - scene.origin;
    let (px, py) = scene
        .camera
        .project(
            Vec3::new(centre.x as f32, centre.y as f32, centre.z as f32),
            image.width,
            image.height,
        )
        .unwrap();
    let exr_photo = photo_in::load(&exr, samples::PHOTO_EXPOSURE).unwrap();
    let png_photo = photo_in::load(&png, samples::PHOTO_EXPOSURE).unwrap();
    assert!(exr_photo.is_linear_float && !png_photo.is_linear_float);
    let i = exr_photo.index(px as u32, py as u32);
    for (c, want) in exr_photo.radiance[i].iter().zip(truth.radiance) {
        assert!(
            c * samples::PHOTO_EXPOSURE > 1.0,
            "{:?}",
            exr_photo.radiance[i]
        );
        assert!(
            (*c as f64 / want - 1.0).abs() < 0.03,
            "{:?}",
            exr_photo.radiance[i]
        );
    }
    assert!(!exr_photo.clipped[i]);
    assert!(png_photo.clipped[i]);
    assert!(png_photo.radiance[i][0] <= 1.0 / samples::PHOTO_EXPOSURE + 1e-3);

    let exr_light = fit(&dir, &exr, "exr-lit.gltf");
    let png_light = fit(&dir, &png, "png-lit.gltf");
    let exr_errors = Errors::of(&exr_light, &truth);
    let png_errors = Errors::of(&png_light, &truth);
    exr_errors.print("EXR", &exr_light);
    png_errors.print("PNG", &png_light);

    for (name, e) in [("EXR", &exr_errors), ("PNG", &png_errors)] {
        assert!(
            // Three times the joint fit's own-sample rms on this light (tests/joint.rs).
            e.largest_edge() < 0.01,
            "{name}: an edge is off by {:.3} % of the size",
            100.0 * e.largest_edge()
        );
        assert!(
            e.largest_radiance() < 0.01,
            "{name}: the radiance is off by {:.3} %",
            100.0 * e.largest_radiance()
        );
    }
    assert!(
        exr_errors.largest_edge() <= png_errors.largest_edge() + 0.002,
        "EXR largest edge error {:.3} % vs PNG {:.3} %",
        100.0 * exr_errors.largest_edge(),
        100.0 * png_errors.largest_edge()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
