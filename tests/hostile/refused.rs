//! Class 3: a refused run leaves every output folder as it was: a bad output location is found
//! before any work, a failure after writing began removes what the run wrote (old outputs
//! stay), and `segment` with no streaks writes nothing.

use crate::common::cli::arg;
use crate::common::fit_case;
use crate::support::{case, fit, refused, run_with, temporaries};

#[test]
fn a_debug_folder_that_is_a_file_is_refused_before_any_work() {
    let c = case("hostile-debug-is-file");
    let out = c.dir.join("out.gltf");
    let not_a_folder = c.dir.join("debug");
    std::fs::write(&not_a_folder, b"a file").unwrap();
    let args = fit(
        &c.scene,
        &c.photo,
        &["-o", &arg(&out), "--debug-dir", &arg(&not_a_folder)],
    );
    let ran = refused(&args, &[], &[&c.dir], &["debug", "not a folder"]);
    // Before the scene is even loaded: no stage ran.
    assert!(ran.seconds < 1.0, "{} s", ran.seconds);
    // The output itself as the debug folder.
    let args = fit(
        &c.scene,
        &c.photo,
        &["-o", &arg(&out), "--debug-dir", &arg(&out)],
    );
    refused(&args, &[], &[&c.dir], &["out.gltf"]);
}

/// The debug pictures fail after the scene and its side file are written to temporaries (a
/// folder sits where a picture goes): nothing is left, and the old outputs are untouched.
#[test]
fn a_failure_after_writing_began_leaves_the_old_outputs() {
    let c = case("hostile-late-failure");
    let out = c.dir.join("out.gltf");
    let report = c.dir.join("report.json");
    let first = run_with(
        &fit(
            &c.scene,
            &c.photo,
            &["-o", &arg(&out), "--report", &arg(&report)],
        ),
        &[],
        60.0,
    );
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    let debug = c.dir.join("debug");
    std::fs::create_dir_all(debug.join("streaks.png")).unwrap();
    // (Without --report: a refused run's report is written on purpose.)
    let args = fit(
        &c.scene,
        &c.photo,
        &["-o", &arg(&out), "--debug-dir", &arg(&debug), "--seed", "9"],
    );
    refused(&args, &[], &[&c.dir], &["streaks.png"]);
    assert!(temporaries(&c.dir).is_empty());
}

/// The old behaviour wrote four pictures and streaks.json for a photo without streaks.
#[test]
fn segment_without_streaks_writes_nothing() {
    let c = case("hostile-segment-empty");
    let dark = c.dir.join("dark.png");
    fit_case::uniform_png(&dark, fit_case::SIDE, fit_case::SIDE, 3);
    let out = c.dir.join("segments");
    let args: Vec<String> = vec![
        "segment".into(),
        arg(&c.scene),
        arg(&dark),
        "--out-dir".into(),
        arg(&out),
    ];
    let ran = refused(&args, &[], &[&c.dir], &["no streak found"]);
    assert_eq!(ran.code, Some(3));
    assert!(!out.exists());
}

/// A batch folder that is a file is refused before any work.
#[test]
fn a_batch_folder_that_is_a_file_is_refused() {
    let c = case("hostile-batch-refused");
    let file = c.dir.join("file");
    std::fs::write(&file, b"x").unwrap();
    let args = fit(&c.scene, &c.photo, &["--out-dir", &arg(&file)]);
    let ran = refused(&args, &[], &[&c.dir], &["not a folder"]);
    assert!(ran.seconds < 1.0, "{} s", ran.seconds);
}
