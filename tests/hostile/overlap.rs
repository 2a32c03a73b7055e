//! Class 1: no output lands on an input or on another output, however the path is spelled
//! (through a symlinked folder, an absolute URI, a name a picture would have), and the
//! refusal comes before any work.

use std::path::Path;

use crate::common::cli::arg;
use crate::support::{case, fit, refused};

#[test]
fn a_report_over_the_scenes_own_buffer_is_refused() {
    let c = case("hostile-report-on-buffer");
    let out = c.dir.join("out.gltf");
    let args = fit(
        &c.scene,
        &c.photo,
        &["-o", &arg(&out), "--report", &arg(&c.bin)],
    );
    let ran = refused(&args, &[], &[&c.dir], &["water.bin", "input"]);
    assert!(ran.seconds < 5.0, "refused after {} s", ran.seconds);
}

#[test]
fn a_report_over_the_outputs_own_side_file_is_refused() {
    let c = case("hostile-report-on-side-file");
    let out = c.dir.join("out.gltf");
    for side in ["out.buffer0.bin", "out.streaklight.bin"] {
        let report = c.dir.join(side);
        let args = fit(
            &c.scene,
            &c.photo,
            &["-o", &arg(&out), "--report", &arg(&report)],
        );
        refused(&args, &[], &[&c.dir], &[side, "same file"]);
    }
}

#[test]
fn a_photo_at_the_outputs_future_side_file_is_refused() {
    let c = case("hostile-photo-on-side-file");
    let photo = c.dir.join("out.buffer0.bin");
    std::fs::rename(&c.photo, &photo).unwrap();
    let out = c.dir.join("out.gltf");
    let args = fit(&c.scene, &photo, &["-o", &arg(&out)]);
    refused(&args, &[], &[&c.dir], &["out.buffer0.bin", "input"]);
}

/// A buffer whose URI reaches the output's future copy of it, through a symlinked folder or
/// spelled otherwise.
#[cfg(unix)]
#[test]
fn a_buffer_resolving_to_the_outputs_side_file_is_refused() {
    let c = case("hostile-buffer-via-link");
    let outdir = c.dir.join("out");
    std::fs::create_dir(&outdir).unwrap();
    std::fs::rename(&c.bin, outdir.join("lit.buffer0.bin")).unwrap();
    std::os::unix::fs::symlink(&outdir, c.dir.join("link")).unwrap();
    for uri in ["link/lit.buffer0.bin", "out/./lit.buffer0.bin"] {
        let mut doc: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&c.scene).unwrap()).unwrap();
        doc["buffers"][0]["uri"] = uri.into();
        std::fs::write(&c.scene, serde_json::to_vec(&doc).unwrap()).unwrap();
        let out = outdir.join("lit.gltf");
        let args = fit(&c.scene, &c.photo, &["-o", &arg(&out)]);
        refused(&args, &[], &[&c.dir], &["lit.buffer0.bin", "input"]);
    }
}

#[test]
fn a_debug_folder_holding_an_input_named_like_a_picture_is_refused() {
    let c = case("hostile-debug-holds-input");
    let debug = c.dir.join("debug");
    std::fs::create_dir(&debug).unwrap();
    let photo = debug.join("streaks.png");
    std::fs::rename(&c.photo, &photo).unwrap();
    let out = c.dir.join("out.gltf");
    let args = fit(
        &c.scene,
        &photo,
        &["-o", &arg(&out), "--debug-dir", &arg(&debug)],
    );
    refused(&args, &[], &[&c.dir], &["streaks.png", "input"]);
}

#[test]
fn segment_into_a_folder_holding_its_photo_under_a_picture_name_is_refused() {
    let c = case("hostile-segment-holds-input");
    let photo = c.dir.join("seeds.png");
    std::fs::rename(&c.photo, &photo).unwrap();
    let args: Vec<String> = vec![
        "segment".into(),
        arg(&c.scene),
        arg(&photo),
        "--out-dir".into(),
        arg(&c.dir),
        "--exposure".into(),
        "0.1".into(),
    ];
    refused(&args, &[], &[&c.dir], &["seeds.png", "input"]);
}

#[test]
fn render_over_a_buffer_of_its_scene_is_refused() {
    let c = case("hostile-render-on-buffer");
    let image = c.dir.join("render.png");
    std::fs::rename(&c.bin, &image).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&c.scene).unwrap()).unwrap();
    doc["buffers"][0]["uri"] = "render.png".into();
    std::fs::write(&c.scene, serde_json::to_vec(&doc).unwrap()).unwrap();
    let args: Vec<String> = vec![
        "render".into(),
        arg(&c.scene),
        "-o".into(),
        arg(&image),
        "--width".into(),
        "32".into(),
        "--spp".into(),
        "1".into(),
    ];
    refused(&args, &[], &[&c.dir], &["render.png", "input"]);
}

/// A batch whose two photos' debug folders, and a report and a picture, could only collide
/// when the paths are resolved: the same folder spelled two ways.
#[test]
fn outputs_that_are_one_file_spelled_two_ways_are_refused() {
    let c = case("hostile-outputs-collide");
    let out = c.dir.join("out.gltf");
    let debug = c.dir.join("debug");
    std::fs::create_dir(&debug).unwrap();
    let report = Path::new(&debug).join(".").join("index.html");
    let args = fit(
        &c.scene,
        &c.photo,
        &[
            "-o",
            &arg(&out),
            "--report",
            &arg(&report),
            "--debug-dir",
            &arg(&debug),
        ],
    );
    refused(&args, &[], &[&c.dir], &["index.html", "same file"]);
}
