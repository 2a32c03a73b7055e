//! The command line in a pipeline: exit codes that tell "no light found" from errors and from
//! usage errors, the `--json` summary against its schema, the report of a refused run,
//! several photos of one scene in one run, `--quiet`, checked numeric options, `--help`'s
//! examples and exit codes, and shell completions.

mod common;

use std::path::{Path, PathBuf};

use common::cli::run_cli_code as run;
use common::cli::{arg, fit_args};
use common::dirs::listing;
use common::fit_case::{self, SIDE};
use common::json::{read_json, schema_validator};
use serde_json::Value;

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|a| a.to_string()).collect()
}

/// The good case (scene, photo), rendered once per test binary.
fn good_case() -> (PathBuf, PathBuf) {
    static CASE: std::sync::OnceLock<(PathBuf, PathBuf)> = std::sync::OnceLock::new();
    CASE.get_or_init(|| fit_case::good_case(&common::temp_dir("cli-pipeline-case")))
        .clone()
}

/// The one JSON line on stdout, checked against `schema/summary.schema.json`.
fn summary(stdout: &str) -> Value {
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "one line on stdout: {stdout}");
    valid(
        serde_json::from_str(lines[0]).unwrap(),
        "summary.schema.json",
    )
}

/// `value`, checked against `schema/SCHEMA`.
fn valid(value: Value, schema: &str) -> Value {
    let errors: Vec<String> = schema_validator(schema)
        .iter_errors(&value)
        .map(|e| format!("{e} at {}", e.instance_path))
        .collect();
    assert!(errors.is_empty(), "{errors:?}: {value}");
    value
}

fn valid_report(path: &Path) -> Value {
    valid(read_json(path), "report.schema.json")
}

#[test]
fn a_good_fit_exits_0_and_its_json_summary_lists_lights_warnings_and_files() {
    let (scene, photo) = good_case();
    let dir = common::temp_dir("cli-json-good");
    let (out, report) = (dir.join("out.gltf"), dir.join("report.json"));
    let mut args = fit_args(&scene, &photo, &out, &report, &["--json"]);
    args.extend(strings(&["--debug-dir", &arg(&dir.join("debug"))]));
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, 0, "{stderr}");
    let s = summary(&stdout);
    assert_eq!(
        (s["status"].as_str(), s["exit_code"].as_u64()),
        (Some("ok"), Some(0))
    );
    let report = valid_report(&report);
    assert_eq!(
        s["lights"].as_array().unwrap().len(),
        report["lights"].as_array().unwrap().len()
    );
    assert!(!s["lights"].as_array().unwrap().is_empty());
    for (light, full) in s["lights"]
        .as_array()
        .unwrap()
        .iter()
        .zip(report["lights"].as_array().unwrap())
    {
        assert_eq!(light["name"], full["name"]);
        assert_eq!(light["width"], full["width"]);
        assert_eq!(light["uncertainty"], full["uncertainty"]);
    }
    let warned: Vec<&Value> = s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| &w["message"])
        .collect();
    let reported: Vec<&Value> = report["warnings"].as_array().unwrap().iter().collect();
    assert_eq!(warned, reported);
    let files: Vec<PathBuf> = s["files_written"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| PathBuf::from(f.as_str().unwrap()))
        .collect();
    for f in [
        &out,
        &dir.join("report.json"),
        &dir.join("debug").join("index.html"),
    ] {
        assert!(files.contains(f), "{} not among {files:?}", f.display());
    }
    for f in &files {
        assert!(f.is_file(), "{} listed but not written", f.display());
    }
}

#[test]
fn no_light_found_exits_3_and_a_refused_run_reports_why() {
    let (scene, _) = good_case();
    let dir = common::temp_dir("cli-no-light");
    let black = dir.join("black.png");
    fit_case::uniform_png(&black, SIDE, SIDE, 0);
    let (out, report) = (dir.join("out.gltf"), dir.join("report.json"));
    let before = listing(&dir);
    let (code, stdout, stderr) = run(&fit_args(&scene, &black, &out, &report, &["--json"]));
    assert_eq!(code, 3, "{stderr}");
    let s = summary(&stdout);
    assert_eq!(s["status"], "no light found");
    assert_eq!(s["photos"][0]["exit_code"], 3);
    assert!(s["lights"].as_array().unwrap().is_empty());
    // Only the report is written, and it says why (and nothing else).
    let mut expected = before.clone();
    expected.push("report.json".into());
    expected.sort();
    assert_eq!(listing(&dir), expected);
    let refusal = valid_report(&report);
    assert_eq!(refusal["status"], "refused");
    let error = refusal["error"].as_str().unwrap();
    assert!(
        stderr.contains(&format!("error: {error}")),
        "{error} / {stderr}"
    );
    assert!(
        error.contains("--allow-empty"),
        "flags, not library names: {error}"
    );
    for absent in ["lights", "settings", "timings", "warnings"] {
        assert!(refusal.get(absent).is_none(), "{absent} in {refusal}");
    }
    assert_eq!(s["files_written"], serde_json::json!([arg(&report)]));

    // --allow-empty: success, and a full report saying no light was found.
    std::fs::remove_file(&report).unwrap();
    let (code, _, stderr) = run(&fit_args(&scene, &black, &out, &report, &["--allow-empty"]));
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(valid_report(&report)["status"], "no light found");
}

#[test]
fn errors_exit_1_and_usage_errors_exit_2() {
    let (scene, photo) = good_case();
    let dir = common::temp_dir("cli-exit-codes");
    let (out, report) = (dir.join("out.gltf"), dir.join("report.json"));
    // A missing photo: an error, and a report saying so.
    let (code, stdout, stderr) = run(&fit_args(
        &scene,
        &dir.join("missing.png"),
        &out,
        &report,
        &["--json"],
    ));
    assert_eq!(code, 1, "{stderr}");
    assert_eq!(summary(&stdout)["status"], "error");
    assert!(valid_report(&report)["error"]
        .as_str()
        .unwrap()
        .contains("missing.png"));
    // Values out of range are usage errors that say what is wrong, negative ones included.
    for (flag, value, words) in [
        ("--exposure", "-1", "greater than 0"),
        ("--exposure", "0", "greater than 0"),
        ("--gloss", "-5", "greater than 0"),
        ("--ior", "0.9", "greater than 1"),
        ("--nits-scale", "nan", "greater than 0"),
    ] {
        let mut args = fit_args(&scene, &photo, &out, &report, &[]);
        match args.iter().position(|a| a == flag) {
            Some(i) => args[i + 1] = value.into(),
            None => args.extend(strings(&[flag, value])),
        }
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 2, "{flag} {value}: {stderr}");
        assert!(
            stderr.contains(flag) && stderr.contains(words),
            "{flag} {value}: {stderr}"
        );
        assert!(!stderr.contains("unexpected argument"), "{stderr}");
    }
    let (code, _, _) = run(&strings(&["fit", "--no-such-option"]));
    assert_eq!(code, 2);
    // Options that do not go together: a usage error after parsing, in the summary too.
    let args = strings(&[
        "fit",
        &arg(&scene),
        &arg(&photo),
        &arg(&photo),
        "-o",
        &arg(&out),
        "--json",
    ]);
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, 2, "{stderr}");
    let s = summary(&stdout);
    assert_eq!(s["status"], "usage");
    assert!(s["error"].as_str().unwrap().contains("--out-dir"), "{s}");
}

#[test]
fn several_photos_of_one_scene_load_it_once_and_never_collide() {
    let (scene, photo) = good_case();
    let dir = common::temp_dir("cli-batch");
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    // Two photos with the same name, and a black one.
    std::fs::copy(&photo, a.join("night.png")).unwrap();
    std::fs::copy(&photo, b.join("night.png")).unwrap();
    fit_case::uniform_png(&dir.join("dark.png"), SIDE, SIDE, 0);
    let out = dir.join("lit");
    let args = strings(&[
        "fit",
        &arg(&scene),
        &arg(&a.join("night.png")),
        &arg(&b.join("night.png")),
        &arg(&dir.join("dark.png")),
        "--out-dir",
        &arg(&out),
        "--exposure",
        common::cli::EXPOSURE_ARG,
        "--samples",
        common::cli::SAMPLES_ARG,
        "--json",
    ]);
    let (code, stdout, stderr) = run(&args);
    // The dark photo has no light: the run's exit is the worst photo's.
    assert_eq!(code, 3, "{stderr}");
    assert_eq!(stderr.matches("load scene").count(), 1, "{stderr}");
    let s = summary(&stdout);
    let photos = s["photos"].as_array().unwrap();
    assert_eq!(photos.len(), 3);
    assert_eq!(
        photos
            .iter()
            .map(|p| p["exit_code"].as_u64().unwrap())
            .collect::<Vec<_>>(),
        [0, 0, 3]
    );
    assert_eq!(
        listing(&out),
        [
            "dark.report.json",
            "night-1.gltf",
            "night-1.report.json",
            "night-1.streaklight.bin",
            "night-2.gltf",
            "night-2.report.json",
            "night-2.streaklight.bin"
        ]
    );
    assert_eq!(
        valid_report(&out.join("dark.report.json"))["status"],
        "refused"
    );
    // The same photo gives the same lights in either slot.
    let l1 = valid_report(&out.join("night-1.report.json"))["lights"].clone();
    let l2 = valid_report(&out.join("night-2.report.json"))["lights"].clone();
    assert_eq!(l1, l2);
    // -o with several photos is refused before any work.
    let (code, _, stderr) = run(&strings(&[
        "fit",
        &arg(&scene),
        &arg(&photo),
        &arg(&photo),
        "-o",
        &arg(&dir.join("x.gltf")),
    ]));
    assert_eq!(code, 2, "{stderr}");
}

#[test]
fn quiet_keeps_only_warnings_and_verbose_adds_stage_times() {
    let (scene, photo) = good_case();
    let dir = common::temp_dir("cli-quiet");
    let (out, report) = (dir.join("out.gltf"), dir.join("report.json"));
    let (code, _, loud) = run(&fit_args(&scene, &photo, &out, &report, &[]));
    assert_eq!(code, 0, "{loud}");
    assert!(
        loud.contains("load scene") && loud.contains("wrote "),
        "{loud}"
    );
    let (code, _, quiet) = run(&fit_args(&scene, &photo, &out, &report, &["--quiet"]));
    assert_eq!(code, 0, "{quiet}");
    let warnings: Vec<&str> = loud
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .collect();
    assert_eq!(
        quiet.lines().collect::<Vec<_>>(),
        warnings,
        "quiet: {quiet}"
    );
    let (code, _, verbose) = run(&fit_args(&scene, &photo, &out, &report, &["--verbose"]));
    assert_eq!(code, 0, "{verbose}");
    assert!(verbose.contains("(load scene: "), "{verbose}");
    // Off a terminal the joint fit's counted work is told as lines with the time left.
    assert!(
        verbose.contains("joint fit: tracing the footprints"),
        "{verbose}"
    );
    assert!(verbose.contains(" s left"), "{verbose}");
}

#[test]
fn help_has_examples_and_exit_codes_and_completions_are_printed() {
    for args in [vec!["--help"], vec!["fit", "--help"]] {
        let (code, stdout, _) = run(&strings(&args));
        assert_eq!(code, 0);
        for words in [
            "Examples:",
            "Exit codes:",
            "3  no light found",
            "2  the command line is wrong",
        ] {
            assert!(stdout.contains(words), "{args:?} lacks {words:?}");
        }
    }
    let (_, fit_help, _) = run(&strings(&["fit", "--help"]));
    assert!(fit_help.contains("--out-dir") && fit_help.contains("--json"));
    for (shell, words) in [
        ("bash", "complete"),
        ("zsh", "#compdef"),
        ("fish", "complete -c streaklight"),
    ] {
        let (code, stdout, stderr) = run(&strings(&["completions", shell]));
        assert_eq!(code, 0, "{stderr}");
        assert!(
            stdout.contains(words) && stdout.contains("exposure"),
            "{shell}: {stdout}"
        );
    }
    let (code, _, _) = run(&strings(&["completions", "tcsh"]));
    assert_eq!(code, 2);
}
