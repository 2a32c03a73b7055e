//! `streaklight fit` on bad input: a clear message naming what is wrong, a non-zero exit, no
//! panic, and no output and no temporary file left behind (only, with `--report`, the report
//! of the refusal). Also: a good run's
//! output passes the Khronos glTF-Validator, and runs are deterministic.
//!
//! Needs `node` and `npm ci --prefix tests/validator` for the validator checks (`scripts/test`
//! installs them).

mod common;

use std::path::{Path, PathBuf};

use common::cli::{arg, fit_args};
use common::dirs::listing;
use common::fit_case::{self, SIDE};
use common::json::read_json;
use common::{gltf_check, validator};
use serde_json::{json, Value};

fn run(args: &[String]) -> (bool, String) {
    let (ok, _, stderr) = common::run_cli(args);
    assert!(!stderr.contains("panicked"), "panic on {args:?}: {stderr}");
    (ok, stderr)
}

/// Runs `fit --allow-empty` and asserts success; returns its stderr.
fn fit_allowing_empty(scene: &Path, photo: &Path, out: &Path, report: &Path) -> String {
    let (ok, stderr) = run(&fit_args(scene, photo, out, report, &["--allow-empty"]));
    assert!(ok, "{stderr}");
    stderr
}

/// Runs `fit` on `scene` and `photo` into `dir/out.gltf` (report `dir/report.json`) and asserts
/// a failure whose message holds every one of `words`, with nothing written into `dir` (its
/// listing is unchanged).
fn expect_refusal(
    dir: &Path,
    scene: &Path,
    photo: &Path,
    extra: &[&str],
    words: &[&str],
) -> String {
    let out = dir.join("out.gltf");
    let report = dir.join("report.json");
    expect_refusal_to(dir, &fit_args(scene, photo, &out, &report, extra), words)
}

fn expect_refusal_to(dir: &Path, args: &[String], words: &[&str]) -> String {
    let before = listing(dir);
    let inputs: Vec<(PathBuf, Vec<u8>)> = before
        .iter()
        .map(|n| (dir.join(n), std::fs::read(dir.join(n)).unwrap_or_default()))
        .collect();
    let (ok, stderr) = run(args);
    assert!(!ok, "{args:?} should fail; stderr: {stderr}");
    // Shown with `--nocapture`: the messages the README's "Bad input" table quotes.
    eprintln!("refused: {}", stderr.trim_end());
    for w in words {
        assert!(
            stderr.contains(w),
            "the message of {args:?} lacks {w:?}: {stderr}"
        );
    }
    // The one file a refusal may write: the report it was asked for, saying why and nothing
    // else.
    let report = args
        .iter()
        .position(|a| a == "--report")
        .map(|i| PathBuf::from(&args[i + 1]));
    let new_file = |r: &PathBuf| {
        r.is_file()
            && r.parent() == Some(dir)
            && !before.contains(&r.file_name().unwrap().to_string_lossy().into_owned())
    };
    if let Some(report) = report.filter(new_file) {
        let refusal = read_json(&report);
        assert_eq!(refusal["status"], "refused", "{refusal}");
        let error = refusal["error"].as_str().unwrap();
        assert!(stderr.contains(error), "{error} / {stderr}");
        assert!(refusal.get("lights").is_none(), "{refusal}");
        std::fs::remove_file(&report).unwrap();
    }
    assert_eq!(
        listing(dir),
        before,
        "a refused run left files behind (output, report or temporary): {stderr}"
    );
    for (path, bytes) in inputs {
        assert_eq!(
            std::fs::read(&path).unwrap_or_default(),
            bytes,
            "{} was modified",
            path.display()
        );
    }
    stderr
}

/// The good case, shared by the tests of one binary run (rendering it takes a moment).
fn good_case() -> (PathBuf, PathBuf) {
    static CASE: std::sync::OnceLock<(PathBuf, PathBuf)> = std::sync::OnceLock::new();
    CASE.get_or_init(|| {
        let dir = common::temp_dir("fit-cli-good-case");
        fit_case::good_case(&dir)
    })
    .clone()
}

/// A fresh folder holding copies of the good scene and photo.
fn case_dir(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let (scene, photo) = good_case();
    let dir = common::temp_dir(name);
    std::fs::copy(&scene, dir.join("scene.gltf")).unwrap();
    std::fs::copy(&photo, dir.join("photo.png")).unwrap();
    let (scene, photo) = (dir.join("scene.gltf"), dir.join("photo.png"));
    (dir, scene, photo)
}

#[test]
fn good_input_fits_a_light_and_validates() {
    let (dir, scene, photo) = case_dir("fit-good");
    let out = dir.join("out.gltf");
    let report = dir.join("report.json");
    let (ok, stderr) = run(&fit_args(&scene, &photo, &out, &report, &[]));
    assert!(ok, "{stderr}");
    let r = read_json(&report);
    assert!(
        !r["lights"].as_array().unwrap().is_empty(),
        "no light fitted: {stderr}"
    );
    gltf_check::assert_keeps_everything(&scene, &out);
    validator::assert_validator_clean(&out);
    assert_eq!(
        listing(&dir),
        [
            "out.gltf",
            "out.streaklight.bin",
            "photo.png",
            "report.json",
            "scene.gltf"
        ]
    );
    // Each stage is announced as it starts, so a long run shows where it is.
    for stage in [
        "load scene",
        "streaks",
        "the paper's estimate",
        "joint fit of",
    ] {
        assert!(
            stderr.contains(stage),
            "no progress line {stage:?}: {stderr}"
        );
    }
    // Also as .glb, with two repeats (the second announced, the count in the report) and
    // every pixel of the region read.
    let glb = dir.join("out.glb");
    let (ok, stderr) = run(&fit_args(
        &scene,
        &photo,
        &glb,
        &report,
        &["--repeats", "2", "--joint-samples", "33", "--all-pixels"],
    ));
    assert!(ok, "{stderr}");
    assert!(stderr.contains("joint fit: repeat 2 of 2"), "{stderr}");
    let r = read_json(&report);
    assert_eq!(r["settings"]["repeats"], 2);
    // 33 asked, rounded to two halves of 2 x 2 camera rays times 2 x 2 lobe samples.
    assert_eq!(r["settings"]["joint_samples"], 32);
    assert_eq!(r["settings"]["joint_pixels"], "all");
    validator::assert_validator_clean(&glb);
}

#[test]
fn photo_problems_are_refused() {
    let (dir, scene, _) = case_dir("fit-photo");
    // The aspect ratio differs from the camera's (1.0) by 1.3 % (> 0.5 %).
    let wide = dir.join("wide.png");
    fit_case::uniform_png(&wide, 162, 160, 0);
    expect_refusal(
        &dir,
        &scene,
        &wide,
        &[],
        &["wide.png", "aspect ratio", "camera"],
    );
    // Within 0.5 % (0.4 %) passes that check, and then fails for want of streaks.
    let close = dir.join("close.png");
    fit_case::uniform_png(&close, 250, 249, 0);
    let msg = expect_refusal(&dir, &scene, &close, &[], &["close.png", "shows no streak"]);
    assert!(!msg.contains("aspect"), "{msg}");
    // No joint fit at all.
    expect_refusal(
        &dir,
        &scene,
        &close,
        &["--repeats", "0"],
        &["--repeats", "whole number from 1"],
    );
    expect_refusal(
        &dir,
        &scene,
        &close,
        &["--joint-samples", "0"],
        &["--joint-samples", "whole number from 1"],
    );
    // Missing.
    expect_refusal(
        &dir,
        &scene,
        &dir.join("missing.png"),
        &[],
        &["missing.png", "No such file"],
    );
    // Not an image at all.
    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"this is not a picture\n").unwrap();
    expect_refusal(
        &dir,
        &scene,
        &corrupt,
        &[],
        &["corrupt.png", "not a photo format"],
    );
    // A PNG cut in half.
    let (_, good_photo) = good_case();
    let bytes = std::fs::read(good_photo).unwrap();
    let truncated = dir.join("truncated.png");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    expect_refusal(
        &dir,
        &scene,
        &truncated,
        &[],
        &["truncated.png", "cannot decode"],
    );
    // Too small.
    let small = dir.join("small.png");
    fit_case::uniform_png(&small, 32, 32, 0);
    expect_refusal(
        &dir,
        &scene,
        &small,
        &[],
        &["small.png", "32 x 32", "at least 64 x 64"],
    );
    // An empty file.
    let empty = dir.join("empty.png");
    std::fs::write(&empty, b"").unwrap();
    expect_refusal(&dir, &scene, &empty, &[], &["empty.png"]);
}

#[test]
fn photos_without_streaks_are_refused_unless_allowed() {
    let (dir, scene, _) = case_dir("fit-nostreaks");
    for (name, value) in [("black.png", 0u8), ("grey.png", 128), ("clipped.png", 255)] {
        let photo = dir.join(name);
        fit_case::uniform_png(&photo, SIDE, SIDE, value);
        let msg = expect_refusal(&dir, &scene, &photo, &[], &["--allow-empty"]);
        assert!(
            msg.contains(name) && msg.contains("shows no streak"),
            "{msg}"
        );
        let expected = if value == 255 {
            "every water pixel is clipped"
        } else {
            "every water pixel has the same value"
        };
        assert!(msg.contains(expected), "{name}: {msg}");
    }
    // --allow-empty: success, and the scene written with nothing lost (and validator-clean).
    let out = dir.join("empty-out.gltf");
    let report = dir.join("empty-report.json");
    let stderr = fit_allowing_empty(&scene, &dir.join("black.png"), &out, &report);
    assert!(stderr.to_lowercase().contains("streak"), "{stderr}");
    gltf_check::assert_keeps_everything(&scene, &out);
    let (a, b) = (gltf_check::load(&scene), gltf_check::load(&out));
    assert_eq!(a.json, b.json, "no light, yet the scene changed");
    validator::assert_validator_clean(&out);
    let r = read_json(&report);
    assert_eq!(r["lights"], json!([]));
}

#[test]
fn nothing_for_the_light_to_hang_on() {
    let (dir, _, photo) = case_dir("fit-nowall");
    // Water only: remove the wall from the scene.
    let mut water_only = common::paper_setup(Some(fit_case::water_material()));
    water_only.json["scenes"][0]["nodes"] = json!([0, 1]);
    let scene = dir.join("wateronly.gltf");
    water_only.write_gltf(&scene);
    let msg = expect_refusal(&dir, &scene, &photo, &[], &["--allow-empty"]);
    assert!(msg.contains("geometry"), "{msg}");
    // Allowed empty: written unchanged, with the reason as a warning.
    let out = dir.join("allowed.gltf");
    let stderr = fit_allowing_empty(&scene, &photo, &out, &dir.join("allowed.json"));
    assert!(stderr.contains("geometry"), "{stderr}");
    assert_eq!(gltf_check::load(&scene).json, gltf_check::load(&out).json);
    validator::assert_validator_clean(&out);
}

#[test]
fn output_and_report_paths_are_checked_first() {
    let (dir, scene, photo) = case_dir("fit-paths");
    let report = dir.join("report.json");
    let out = dir.join("out.gltf");
    // Output over an input, also spelled differently.
    for (target, word) in [
        (scene.clone(), "scene.gltf"),
        (dir.join(".").join("scene.gltf"), "scene.gltf"),
    ] {
        let args = fit_args(&scene, &photo, &target, &report, &[]);
        expect_refusal_to(&dir, &args, &[word, "input"]);
    }
    // The photo as output: refused for its extension first, a .gltf named like the photo is
    // also refused when it is the photo.
    let photo_as_gltf = dir.join("photo.gltf");
    std::fs::copy(&scene, &photo_as_gltf).unwrap();
    let args = fit_args(&scene, &photo_as_gltf, &photo_as_gltf, &report, &[]);
    expect_refusal_to(&dir, &args, &["photo.gltf", "input"]);
    std::fs::remove_file(&photo_as_gltf).unwrap();
    let args = fit_args(&scene, &photo, &photo, &report, &[]);
    expect_refusal_to(&dir, &args, &["photo.png", ".gltf or .glb"]);
    // Output extensions we do not write.
    for bad in ["out.obj", "out.json", "out"] {
        let args = fit_args(&scene, &photo, &dir.join(bad), &report, &[]);
        expect_refusal_to(&dir, &args, &[bad, ".gltf or .glb"]);
    }
    // The report over an input or over the output.
    for target in [scene.clone(), photo.clone(), out.clone()] {
        let args = fit_args(&scene, &photo, &out, &target, &[]);
        let name = target.file_name().unwrap().to_str().unwrap().to_owned();
        expect_refusal_to(&dir, &args, &[name.as_str()]);
    }
    // An output folder that does not exist, and one that is a file.
    let missing = dir.join("no-such-folder").join("out.gltf");
    let args = fit_args(&scene, &photo, &missing, &report, &[]);
    expect_refusal_to(&dir, &args, &["no-such-folder", "does not exist"]);
    let args = fit_args(
        &scene,
        &photo,
        &out,
        &dir.join("nofolder").join("r.json"),
        &[],
    );
    expect_refusal_to(&dir, &args, &["nofolder", "does not exist"]);
    let args = fit_args(&scene, &photo, &photo.join("out.gltf"), &report, &[]);
    expect_refusal_to(&dir, &args, &["photo.png"]);
}

#[test]
fn read_only_output_folder_is_refused() {
    let (dir, scene, photo) = case_dir("fit-readonly");
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    let mut perms = std::fs::metadata(&ro).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&ro, perms).unwrap();
    // Root writes into read-only folders: then run the command as user `nobody` (setpriv).
    let probe = ro.join("probe");
    let as_root = std::fs::write(&probe, b"x").is_ok();
    let _ = std::fs::remove_file(&probe);
    let setpriv = Path::new("/usr/bin/setpriv");
    assert!(
        !as_root || setpriv.exists(),
        "running as root, and no /usr/bin/setpriv to run the command as another user: \
         scripts/test installs it (util-linux)"
    );
    {
        let before = listing(&dir);
        let args = fit_args(
            &scene,
            &photo,
            &ro.join("out.gltf"),
            &dir.join("report.json"),
            &[],
        );
        let refusal = |args: &[String]| {
            let bin = env!("CARGO_BIN_EXE_streaklight");
            let mut cmd = if as_root {
                let mut c = std::process::Command::new(setpriv);
                c.args(["--reuid=65534", "--regid=65534", "--clear-groups", bin]);
                c
            } else {
                std::process::Command::new(bin)
            };
            let o = cmd.args(args).output().unwrap();
            let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
            eprintln!("refused: {}", stderr.trim_end());
            assert!(!o.status.success(), "{stderr}");
            assert!(!stderr.contains("panicked"), "{stderr}");
            stderr
        };
        let stderr = refusal(&args);
        assert!(
            stderr.contains(&format!("{}/out.", ro.display()))
                && stderr.contains("Permission denied"),
            "{stderr}"
        );
        assert!(listing(&ro).is_empty(), "{stderr}");
        assert_eq!(listing(&dir), before, "{stderr}");

        // A read-only report folder: refused before the fit, so no scene is written without
        // its report (the scene's folder open to everyone, whoever runs the command).
        use std::os::unix::fs::PermissionsExt;
        let open = dir.join("open");
        std::fs::create_dir(&open).unwrap();
        std::fs::set_permissions(&open, std::fs::Permissions::from_mode(0o777)).unwrap();
        let before = listing(&dir);
        let args = fit_args(
            &scene,
            &photo,
            &open.join("out.gltf"),
            &ro.join("report.json"),
            &[],
        );
        let stderr = refusal(&args);
        assert!(
            stderr.contains("report.json") && stderr.contains("Permission denied"),
            "{stderr}"
        );
        assert!(listing(&ro).is_empty(), "{stderr}");
        assert!(listing(&open).is_empty(), "{stderr}");
        assert_eq!(listing(&dir), before, "{stderr}");
    }
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    // An output path that is a folder: refused before any work, nothing left behind.
    let taken = dir.join("taken.gltf");
    std::fs::create_dir(&taken).unwrap();
    let args = fit_args(&scene, &photo, &taken, &dir.join("report.json"), &[]);
    expect_refusal_to(&dir, &args, &["taken.gltf", "is a folder"]);
    assert!(listing(&taken).is_empty());
    // A report path that is a folder: refused before the scene is written.
    let args = fit_args(&scene, &photo, &dir.join("out.gltf"), &taken, &[]);
    expect_refusal_to(&dir, &args, &["taken.gltf", "is a folder"]);
}

/// The good scene with `edit` applied, as `name` in `dir`.
fn edited_scene(dir: &Path, name: &str, edit: impl FnOnce(&mut common::TestScene)) -> PathBuf {
    let mut t = common::paper_setup(Some(fit_case::water_material()));
    edit(&mut t);
    let path = dir.join(name);
    if name.ends_with(".glb") {
        t.write_glb(&path);
    } else {
        t.write_gltf(&path);
    }
    path
}

#[test]
fn scene_problems_are_refused() {
    let (dir, _, photo) = case_dir("fit-scene");
    // NaN vertex positions (here in the wall: its first vertex).
    let nan = edited_scene(&dir, "nan.gltf", |t| {
        let view =
            &t.json["bufferViews"][t.json["accessors"][3]["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        t.bin[offset..offset + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    });
    // The wall's two triangles share that vertex: both are left out, so the light has nothing
    // to hang on, and the refusal says why.
    expect_refusal(
        &dir,
        &nan,
        &photo,
        &[],
        &[
            "nan.gltf",
            "2 degenerate or non-finite (NaN",
            "left out",
            "add the geometry",
        ],
    );
    // A NaN in one water vertex only: those triangles are left out with a warning, the rest fits.
    let nan_water = edited_scene(&dir, "nanwater.gltf", |t| {
        let view =
            &t.json["bufferViews"][t.json["accessors"][0]["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        t.bin[offset..offset + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    });
    let out = dir.join("nanwater-out.gltf");
    let (ok, stderr) = run(&fit_args(
        &nan_water,
        &photo,
        &out,
        &dir.join("nanwater.json"),
        &[],
    ));
    assert!(ok, "{stderr}");
    assert!(stderr.contains("non-finite (NaN"), "{stderr}");
    gltf_check::assert_keeps_everything(&nan_water, &out);
    // The input's NaN is the validator's only complaint; the output adds none.
    validator::assert_no_new_problems(&nan_water, &out);
    for f in [
        "nanwater-out.gltf",
        "nanwater-out.streaklight.bin",
        "nanwater.json",
    ] {
        std::fs::remove_file(dir.join(f)).unwrap();
    }
    // The camera below the water surface.
    let under = edited_scene(&dir, "under.gltf", |t| {
        t.json["nodes"][0]["translation"] = json!([0.0, -0.5, 10.0]);
    });
    expect_refusal(
        &dir,
        &under,
        &photo,
        &[],
        &["under.gltf", "below the water"],
    );
    // An accessor that reaches past its buffer view (and buffer).
    let short = edited_scene(&dir, "short.gltf", |t| {
        t.json["accessors"][0]["count"] = json!(1_000_000);
    });
    expect_refusal(
        &dir,
        &short,
        &photo,
        &[],
        &["short.gltf", "accessor 0", "past the end"],
    );
    // A buffer file shorter than its byteLength.
    let t = common::paper_setup(Some(fit_case::water_material()));
    let ext = dir.join("ext.gltf");
    t.write_gltf_external(&ext, "ext.bin");
    let bin = std::fs::read(dir.join("ext.bin")).unwrap();
    std::fs::write(dir.join("ext.bin"), &bin[..bin.len() - 100]).unwrap();
    expect_refusal(&dir, &ext, &photo, &[], &["ext.gltf", "too short"]);
    // A truncated .glb.
    let glb = edited_scene(&dir, "whole.glb", |_| {});
    let bytes = std::fs::read(&glb).unwrap();
    let cut = dir.join("cut.glb");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    expect_refusal(&dir, &cut, &photo, &[], &["cut.glb", "truncated"]);
    // Not a glTF, and missing.
    let junk = dir.join("junk.gltf");
    std::fs::write(&junk, b"\x00\x01 junk").unwrap();
    expect_refusal(&dir, &junk, &photo, &[], &["junk.gltf", "not a glTF"]);
    expect_refusal(
        &dir,
        &dir.join("gone.gltf"),
        &photo,
        &[],
        &["gone.gltf", "No such file"],
    );
}

/// The report without its timings (the only part allowed to differ between runs).
fn report_without_timings(path: &Path) -> Value {
    let mut r = read_json(path);
    r.as_object_mut().unwrap().remove("timings");
    // The output's path differs by the run's folder.
    r["files"].as_object_mut().unwrap().remove("output");
    r
}

#[test]
fn same_seed_same_bytes_whatever_the_thread_count() {
    let (dir, _, photo) = case_dir("fit-determinism");
    // An external .bin input, so the output has a .bin of its own too.
    let scene = dir.join("ext.gltf");
    common::paper_setup(Some(fit_case::water_material())).write_gltf_external(&scene, "ext.bin");
    let mut outputs = Vec::new();
    for (name, threads, seed) in [("a", "1", "1"), ("b", "2", "1"), ("c", "2", "2")] {
        let sub = dir.join(name);
        std::fs::create_dir(&sub).unwrap();
        let out = sub.join("out.gltf");
        let report = sub.join("report.json");
        let args = fit_args(&scene, &photo, &out, &report, &["--seed", seed]);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_streaklight"))
            .args(&refs)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let files = listing(&sub);
        assert!(files.iter().any(|f| f.ends_with(".bin")), "{files:?}");
        validator::assert_validator_clean(&out);
        gltf_check::assert_keeps_everything(&scene, &out);
        let bytes: Vec<(String, Vec<u8>)> = files
            .iter()
            .filter(|f| *f != "report.json")
            .map(|f| (f.clone(), std::fs::read(sub.join(f)).unwrap()))
            .collect();
        outputs.push((bytes, report_without_timings(&report)));
    }
    assert_eq!(
        outputs[0].0, outputs[1].0,
        "1 vs 2 threads: output files differ"
    );
    assert_eq!(outputs[0].1, outputs[1].1, "1 vs 2 threads: reports differ");
    assert_ne!(
        outputs[1].0, outputs[2].0,
        "seeds 1 and 2 gave identical outputs"
    );
    assert_ne!(outputs[1].1["lights"], outputs[2].1["lights"]);
}

/// `--debug-dir` writes the segment pictures and, side by side, the photo, the water
/// re-rendered with the fitted lights and their signed difference: the re-render is lit where
/// the photo's streak is, and the difference has the sign of photo minus model.
#[test]
fn debug_dir_shows_photo_render_and_difference() {
    let dir = common::temp_dir("fit-debug");
    let (scene, photo) = fit_case::good_case(&dir);
    let debug = dir.join("debug");
    let out = dir.join("out.gltf");
    let report = dir.join("report.json");
    let mut args = fit_args(&scene, &photo, &out, &report, &[]);
    args.push("--debug-dir".into());
    args.push(arg(&debug));
    let (ok, stderr) = run(&args);
    assert!(ok, "{stderr}");
    for name in [
        "superpixels.png",
        "seeds.png",
        "streaks.png",
        "edges.png",
        "streaks.json",
    ] {
        assert!(debug.join(name).is_file(), "{name} missing");
    }
    assert!(debug.join("index.html").is_file(), "index.html missing");
    let img = image::open(debug.join("fit-photo-render-difference.png"))
        .unwrap()
        .into_rgb8();
    // Titled panels 4 px apart, their pictures aligned at the bottom: three, and a fourth
    // because this flat scene is fitted with the statistical model (the report says so): the
    // scene's own water (the exact model) with the same lights.
    let statistical = read_json(&report)["water_model"]["model"] == "statistical";
    assert!(statistical, "the flat quad takes the statistical model");
    assert_eq!(img.width(), 4 * SIDE + 12);
    assert!(img.height() > SIDE, "titles above the panels");
    let top = img.height() - SIDE;
    let at = |k: u32, x: u32, y: u32| img.get_pixel(k * (SIDE + 4) + x, top + y).0;
    let lin = |p: [u8; 3]| -> f64 {
        p.iter()
            .map(|&c| streaklight::photo_in::srgb_to_linear(c as f32 / 255.0) as f64)
            .sum::<f64>()
            / 3.0
    };
    // Off every light's outline (the fit may split the streak into several lights).
    let outlines: Vec<[u8; 3]> = (0..6)
        .map(streaklight::debug_pictures::light_colour)
        .collect();
    // Sum of each panel's linear values over the lower (water) half: sums of sRGB-encoded
    // values would favour the less noisy re-render (the encoding is concave).
    let panel = |k: u32| -> f64 {
        let mut sum = 0.0;
        for y in SIDE / 2..SIDE {
            for x in 0..SIDE {
                if !outlines.contains(&at(0, x, y)) {
                    sum += lin(at(k, x, y));
                }
            }
        }
        sum
    };
    let (photo_sum, render_sum) = (panel(0), panel(1));
    assert!(photo_sum > 0.0);
    // The exact model's image of the same lights carries about the same reflected light as
    // the statistical one (the flat quad's lobe is the start the slopes were estimated from).
    let exact_sum = panel(3);
    assert!(
        (exact_sum / render_sum - 1.0).abs() < 0.5,
        "exact {exact_sum}, statistical {render_sum}"
    );
    // The re-render carries the fitted light's reflection (this low-quality case fits a
    // different rectangle, so only its presence is checked).
    assert!(
        render_sum > 0.25 * photo_sum,
        "photo {photo_sum}, re-render {render_sum}"
    );
    // The third panel is the signed difference of the first two: red where the photo is
    // brighter, blue where it is darker (checked where the difference is clear of 8-bit
    // rounding, off the light's outline).
    let (mut checked, mut agree) = (0, 0);
    for y in SIDE / 2..SIDE {
        for x in 0..SIDE {
            if outlines.contains(&at(0, x, y)) {
                continue;
            }
            let d = lin(at(0, x, y)) - lin(at(1, x, y));
            if d.abs() < 0.02 {
                continue;
            }
            let r = at(2, x, y);
            checked += 1;
            if (d > 0.0 && r[0] > 0 && r[2] == 0) || (d < 0.0 && r[2] > 0 && r[0] == 0) {
                agree += 1;
            }
        }
    }
    assert!(checked > 100, "{checked} pixels with a clear difference");
    assert!(agree as f64 > 0.95 * checked as f64, "{agree} of {checked}");
}
