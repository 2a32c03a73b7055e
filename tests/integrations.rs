//! streaklight's outputs through the real tools people put between it and their engine:
//! glTF-Transform (with and without `integrations/gltf-transform`), Blender (the `bpy` package,
//! with `integrations/blender`), and copying the outputs elsewhere. One real `fit` of the
//! Table 3 sample (paper method, for speed) feeds every test.
//!
//! Needs Node with `npm ci --prefix integrations/gltf-transform` and `--prefix tests/validator`,
//! and Python with `pip install bpy` (a version built for the machine's Python); `.ci/run`
//! installs them. Without them the tests fail and say what to install.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use common::gltf_check::{lights_by_name, load};
use common::validator::{assert_validator_clean, validator_errors, validator_problems};
use serde_json::Value;
use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, Method};
use streaklight::samples;
use streaklight::scene_out::{restore_lights, InputFiles};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The fit every test reads: (folder, input scene, lit .gltf, report).
struct Fit {
    dir: PathBuf,
    scene: PathBuf,
    lit: PathBuf,
    report: PathBuf,
}

fn fit() -> &'static Fit {
    static FIT: OnceLock<Fit> = OnceLock::new();
    FIT.get_or_init(|| {
        let dir = common::temp_dir("integrations");
        let input_dir = dir.join("in");
        std::fs::create_dir_all(&input_dir).unwrap();
        samples::write_scenes(&input_dir).expect("writing the sample scenes");
        let out = dir.join("out");
        std::fs::create_dir_all(&out).unwrap();
        let scene = input_dir.join("scene.gltf");
        let lit = out.join("lit.gltf");
        let report = out.join("report.json");
        let options = ConvertOptions {
            report: Some(report.clone()),
            exposure: samples::PHOTO_EXPOSURE,
            fit: FitSettings {
                method: Method::Paper,
                ..FitSettings::default()
            },
            ..ConvertOptions::new(&scene, Path::new(ROOT).join("samples/table3.png"), &lit)
        };
        let outcome = convert(&options).expect("fitting the Table 3 sample");
        assert_eq!(outcome.report.lights.len(), 2);
        Fit {
            dir,
            scene,
            lit,
            report,
        }
    })
}

/// Runs a program; panics with its output (and what to install) unless it succeeds.
fn run(program: &str, args: &[&Path], install: &str) -> String {
    let out = Command::new(program)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run `{program}` ({e}): {install}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "{program} {args:?} failed ({}):\n{text}\n(if something is missing: {install})",
        out.status
    );
    text
}

fn bytes_of(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn gltf_transform_keeps_every_light_and_never_writes_into_the_input() {
    let f = fit();
    let work = f.dir.join("gltf-transform");
    std::fs::create_dir_all(&work).unwrap();
    let water = f.scene.with_file_name("water.bin");
    let before = bytes_of(&water);
    let script = Path::new(ROOT).join("integrations/gltf-transform/test/pipeline.mjs");
    let log = run(
        "node",
        &[&script, &f.lit, &work],
        "install Node.js and run `npm ci --prefix integrations/gltf-transform`",
    );
    println!("{log}");
    for name in ["copy", "dedup", "prune", "optimize"] {
        let out = work.join(name).join(format!("{name}.gltf"));
        assert!(
            validator_errors(&out).is_empty(),
            "{}: {:?}",
            out.display(),
            validator_errors(&out)
        );
    }
    // glTF-Transform writes buffers back under their URIs: in the output's own folder, the
    // output's copies are what it may overwrite, never the input scene's water.bin. (On a
    // copy of the output's folder: the other tests read the output.)
    let own = f.dir.join("in-place");
    std::fs::create_dir_all(&own).unwrap();
    for entry in std::fs::read_dir(f.lit.parent().unwrap()).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, own.join(p.file_name().unwrap())).unwrap();
    }
    let cli = Path::new(ROOT)
        .join("integrations/gltf-transform/node_modules/@gltf-transform/cli/bin/cli.js");
    let (lit, opt) = (own.join("lit.gltf"), own.join("opt.gltf"));
    run(
        "node",
        &[
            &cli,
            Path::new("optimize"),
            &lit,
            &opt,
            Path::new("--simplify"),
            Path::new("false"),
        ],
        "npm ci --prefix integrations/gltf-transform",
    );
    assert_eq!(bytes_of(&water), before, "the input's water.bin changed");
}

#[test]
fn restore_lights_brings_back_what_stock_gltf_transform_dropped() {
    let f = fit();
    let work = f.dir.join("restore");
    std::fs::create_dir_all(&work).unwrap();
    let cli = Path::new(ROOT)
        .join("integrations/gltf-transform/node_modules/@gltf-transform/cli/bin/cli.js");
    let install = "install Node.js and run `npm ci --prefix integrations/gltf-transform`";
    let want = lights_by_name(&f.lit);
    assert_eq!(want.len(), 2);
    for command in ["copy", "optimize"] {
        // A folder each: glTF-Transform writes buffers under the names they had, so two of
        // its outputs in one folder would write the same files.
        let work = work.join(command);
        std::fs::create_dir_all(&work).unwrap();
        let stripped = work.join(format!("stock-{command}.gltf"));
        let mut args: Vec<&Path> = vec![&cli, Path::new(command), &f.lit, &stripped];
        if command == "optimize" {
            args.extend([Path::new("--simplify"), Path::new("false")]);
        }
        run("node", &args, install);
        assert!(
            lights_by_name(&stripped).is_empty(),
            "stock {command} kept the lights"
        );
        for ext in ["gltf", "glb"] {
            let restored = work.join(format!("restored-{command}.{ext}"));
            let summary = restore_lights(&stripped, &restored, InputFiles::Copy).unwrap();
            assert_eq!(summary.restored_nodes.len(), 2, "{command} -> {ext}");
            let got = lights_by_name(&restored);
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                // JavaScript writes 1.0 as 1: compare the values, not their spelling.
                let numeric = |v: &Value| -> Value {
                    serde_json::from_str(&v.to_string().replace(".0,", ",").replace(".0]", "]"))
                        .unwrap()
                };
                assert_eq!(
                    (&g.0, numeric(&g.1)),
                    (&w.0, numeric(&w.1)),
                    "{command}: light object"
                );
                for (a, b) in g.2.iter().chain(&g.3).zip(w.2.iter().chain(&w.3)) {
                    assert!(
                        (a - b).abs() <= 1e-6,
                        "{command}: {} frame {g:?} vs {w:?}",
                        g.0
                    );
                }
            }
            assert!(
                validator_errors(&restored).is_empty(),
                "{}",
                restored.display()
            );
        }
    }
    // Restoring a file whose lights are all there changes none of them.
    let again = work.join("again.gltf");
    let summary = restore_lights(&f.lit, &again, InputFiles::Copy).unwrap();
    assert_eq!(
        (summary.restored_nodes.len(), summary.already_present),
        (0, 2)
    );
    assert_eq!(lights_by_name(&again), want);
}

#[test]
fn blender_imports_exports_and_reimports_the_lights() {
    let f = fit();
    let work = f.dir.join("blender");
    std::fs::create_dir_all(&work).unwrap();
    let script = Path::new(ROOT).join("integrations/blender/tests/check_roundtrip.py");
    let log = run(
        "python3",
        &[&script, &f.lit, &f.report, &work],
        "pip install bpy (a version built for this Python)",
    );
    let checks: Vec<&str> = log.lines().filter(|l| l.starts_with("ok: ")).collect();
    println!("{}", checks.join("\n"));
    // 1 count + 7 per light + the quads + the re-import + 1 per light.
    assert!(checks.len() >= 19, "too few checks ran:\n{log}");
}

#[test]
fn outputs_are_self_contained_and_never_share_files() {
    let f = fit();
    let work = f.dir.join("contained");
    let moved = f.dir.join("moved");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&moved).unwrap();
    let photo = Path::new(ROOT).join("samples/table3.png");
    // x.gltf and x.glb in one folder, in turn: both stay valid.
    for ext in ["gltf", "glb"] {
        let options = ConvertOptions {
            exposure: samples::PHOTO_EXPOSURE,
            fit: FitSettings {
                method: Method::Paper,
                ..FitSettings::default()
            },
            ..ConvertOptions::new(&f.scene, &photo, work.join(format!("x.{ext}")))
        };
        convert(&options).unwrap();
    }
    assert_validator_clean(&work.join("x.gltf"));
    assert_validator_clean(&work.join("x.glb"));
    // The .glb alone in an empty folder: no error, no warning (no DATA_URI_GLB).
    std::fs::copy(work.join("x.glb"), moved.join("x.glb")).unwrap();
    assert!(validator_problems(&moved.join("x.glb")).is_empty());
    // The .gltf's folder copied elsewhere (without the input's folder) loads and validates.
    let copy = f.dir.join("copied-folder");
    std::fs::create_dir_all(&copy).unwrap();
    for entry in std::fs::read_dir(&work).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, copy.join(p.file_name().unwrap())).unwrap();
    }
    std::fs::remove_file(copy.join("x.glb")).unwrap();
    assert_validator_clean(&copy.join("x.gltf"));
    let doc = load(&copy.join("x.gltf"));
    for b in doc.json["buffers"].as_array().unwrap() {
        let uri = b["uri"].as_str().unwrap();
        assert!(
            uri.starts_with("data:") || !uri.contains('/'),
            "{uri} is not beside the output"
        );
    }
}
