//! Benchmark: the fit against what a user would otherwise run, Mitsuba 3's LLVM backend
//! loading the same scene and rendering it once in a fresh process, measured side by side.
//!
//! `cargo bench --bench speed` fits the Table 1 photo at the defaults and with `--gloss auto`,
//! the stacked photo (two lights in one streak; with their lamps in frame as the photo shows
//! them, and from the reflections alone, `--no-direct-view`, as for lamps out of frame), and a 1920 x 1080 render of the Table 1
//! scene, each as a child process (`streaklight fit`, wall time and peak resident memory),
//! renders the Table 1 scene with Mitsuba at both sizes (mitsuba_render.py beside this file,
//! 64 spp, path depth 3, in a fresh process each time) and prints every figure, its ratio to
//! Mitsuba's whole process (spawn to exit: what a user waits for, and how the fits are timed;
//! the targets are judged on it), its ratio to Mitsuba's read + load + render timed inside
//! the process (stricter: no interpreter start, imports or exit), and the load average
//! around it.
//!
//! `cargo bench --bench speed -- --cost` instead measures how the default fit's time and
//! memory grow with the photo (600 x 600, 1920 x 1080, 4000 x 3000) and with the water mesh
//! (0.5 M, 2 M, 8 M triangles).
//!
//! `cargo bench --bench speed -- --water-models` fits the harbour photos (three layouts, their
//! lamps in frame) against the scene of the photo's own waves (the exact model), another
//! realisation of them and the flat quad (the statistical model), and the pair rendered at
//! 1920 x 1080 likewise, and prints each fit's time and memory against the exact fit's.
//!
//! Mitsuba is looked for in `$STREAKLIGHT_MITSUBA_PYTHON`, in the venv `target/mitsuba-venv`
//! and in `python3`; when none has it, the bench installs it there (`pip install mitsuba
//! numpy`, and Debian's `libllvm19` when no libLLVM 16 or newer is found, which the LLVM
//! variant needs) unless `SPEED_BENCH_NO_INSTALL=1`; when it cannot, it says why and runs
//! the fits alone. `SPEED_RUNS=N` sets the runs of Mitsuba and of the default fits (best of
//! N; default 3), `SPEED_LONG_RUNS=N` those of the `--gloss auto` and overlap fits (default
//! 1: each takes many times longer than the default fit).
//!
//! A photo that is not square is fitted with copies of the scenes whose camera has its aspect
//! ratio (the same vertical field of view), and Mitsuba renders that camera.

mod child;
mod mitsuba;
mod water_models;

use std::path::{Path, PathBuf};
use std::process::Command;

use streaklight::samples;

use child::{load_average, run, Measured};
use mitsuba::MitsubaRun;

const BIN: &str = env!("CARGO_BIN_EXE_streaklight");
const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// One fit's figures.
struct FitRun {
    measured: Measured,
    stages: Vec<(String, f64)>,
    lights: usize,
    /// The water model the fit used (the report's `water_model.model`).
    model: String,
}

/// The best of `runs` `streaklight fit SCENE PHOTO --exposure 0.1 EXTRA` as child processes.
fn fit(scene: &Path, photo: &Path, extra: &[&str], runs: usize, dir: &Path) -> FitRun {
    let out = dir.join("fit-out.gltf");
    let report = dir.join("fit-report.json");
    let mut best: Option<FitRun> = None;
    for _ in 0..runs {
        let _ = std::fs::remove_file(&out);
        let mut cmd = Command::new(BIN);
        cmd.arg("fit")
            .arg(scene)
            .arg(photo)
            .args(["--exposure", &samples::PHOTO_EXPOSURE.to_string(), "-o"])
            .arg(&out)
            .arg("--report")
            .arg(&report)
            .args(extra);
        let measured = run(&mut cmd, &dir.join("fit.log")).unwrap_or_else(|e| panic!("{e}"));
        let json: serde_json::Value = std::fs::read_to_string(&report)
            .ok()
            .and_then(|s| serde_json::from_str(&s).ok())
            .unwrap_or_default();
        let stages = json["timings"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|t| {
                        let stage = t["stage"].as_str().unwrap_or("?").to_owned();
                        (stage, t["seconds"].as_f64().unwrap_or(f64::NAN))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let lights = json["lights"].as_array().map_or(0, Vec::len);
        let model = json["water_model"]["model"]
            .as_str()
            .unwrap_or("?")
            .to_owned();
        if best
            .as_ref()
            .is_none_or(|b| measured.wall < b.measured.wall)
        {
            best = Some(FitRun {
                measured,
                stages,
                lights,
                model,
            });
        }
    }
    best.unwrap_or_else(|| panic!("SPEED_RUNS must be 1 or more"))
}

/// Renders `scene` to `photo` at `width` x `height` with streaklight (64 spp, the samples'
/// exposure), unless it is there already.
fn render_photo(scene: &Path, photo: &Path, (width, height): (u32, u32), dir: &Path) {
    if photo.exists() {
        return;
    }
    let mut cmd = Command::new(BIN);
    cmd.arg("render")
        .arg(scene)
        .arg("-o")
        .arg(photo)
        .args([
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
        ])
        .args(["--exposure", &samples::PHOTO_EXPOSURE.to_string(), "-q"]);
    let m = run(&mut cmd, &dir.join("render.log")).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "rendered {} ({width} x {height}, 64 spp) in {:.1} s",
        photo.display(),
        m.wall
    );
}

/// `scene.gltf` and `table1-truth.gltf` in `dir` for a `width` x `height` photo: copies whose
/// camera has the photo's aspect ratio (the same vertical field of view) when it is not square.
fn scenes_for(dir: &Path, size: (u32, u32)) -> (PathBuf, PathBuf) {
    (
        aspect_copy(dir, "scene", size),
        aspect_copy(dir, "table1-truth", size),
    )
}

/// `NAME.gltf` in `dir` for a `width` x `height` photo: the file itself when the photo is
/// square, otherwise a copy beside it whose cameras have the photo's aspect ratio (the same
/// vertical field of view).
fn aspect_copy(dir: &Path, name: &str, (width, height): (u32, u32)) -> PathBuf {
    let from = dir.join(format!("{name}.gltf"));
    if width == height {
        return from;
    }
    let to = dir.join(format!("{name}-{width}x{height}.gltf"));
    let text = std::fs::read_to_string(&from).unwrap_or_else(|e| panic!("{e}"));
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
    if let Some(cameras) = doc["cameras"].as_array_mut() {
        for camera in cameras {
            camera["perspective"]["aspectRatio"] = (width as f64 / height as f64).into();
        }
    }
    std::fs::write(&to, doc.to_string()).unwrap_or_else(|e| panic!("{e}"));
    to
}

fn load_text(m: &Measured) -> String {
    format!("{:.1}-{:.1}", m.load.0, m.load.1)
}

fn stage_text(stages: &[(String, f64)]) -> String {
    stages
        .iter()
        .filter(|(_, s)| *s >= 0.01)
        .map(|(n, s)| format!("{n} {s:.2}"))
        .collect::<Vec<_>>()
        .join("; ")
}

fn main() {
    let cost = std::env::args().any(|a| a == "--cost");
    let runs = |var: &str, default: usize| {
        std::env::var(var)
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(default)
    };
    let dir = std::env::temp_dir().join(format!("streaklight-bench-speed-{}", std::process::id()));
    samples::write_scenes(&dir).unwrap_or_else(|e| panic!("writing the sample scenes: {e}"));
    println!(
        "threads: {} (the machine's cores)",
        rayon::current_num_threads()
    );
    println!("load average at start: {:.2}", load_average());
    if cost {
        cost_table(&dir);
    } else if std::env::args().any(|a| a == "--water-models") {
        water_models::water_models(&dir, runs("SPEED_RUNS", 3));
    } else {
        speed(&dir, runs("SPEED_RUNS", 3), runs("SPEED_LONG_RUNS", 1));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// One fit of the speed run: its photo, its Mitsuba anchor (0: 600 x 600, 1: 1920 x 1080),
/// the target of its ratio and its runs.
struct Case<'a> {
    name: &'a str,
    scene: &'a Path,
    photo: &'a Path,
    extra: &'a [&'a str],
    anchor: usize,
    target: f64,
    runs: usize,
}

impl<'a> Case<'a> {
    fn new(
        name: &'a str,
        scene: &'a Path,
        photo: &'a Path,
        extra: &'a [&'a str],
        anchor: usize,
        target: f64,
        runs: usize,
    ) -> Self {
        Case {
            name,
            scene,
            photo,
            extra,
            anchor,
            target,
            runs,
        }
    }
}

/// The fits beside Mitsuba, with their ratios.
fn speed(dir: &Path, runs: usize, long_runs: usize) {
    let root = Path::new(ROOT);
    let (scene, truth) = scenes_for(dir, (600, 600));
    let (hd_scene, hd_truth) = scenes_for(dir, (1920, 1080));
    let table1 = root.join("samples/table1.png");
    let hd_photo = dir.join("table1-1920x1080.png");
    render_photo(&hd_truth, &hd_photo, (1920, 1080), dir);

    let mitsuba = mitsuba::find_mitsuba(&root.join("target/mitsuba-venv"));
    let anchors: Vec<Option<MitsubaRun>> = match &mitsuba {
        Ok(m) => {
            println!(
                "Mitsuba {} (llvm_ad_rgb) from {}{}",
                m.version,
                m.python.display(),
                m.libllvm
                    .as_ref()
                    .map(|l| format!(", DRJIT_LIBLLVM_PATH={}", l.display()))
                    .unwrap_or_default()
            );
            [(&truth, (600, 600)), (&hd_truth, (1920, 1080))]
                .into_iter()
                .map(
                    |(truth, size)| match mitsuba::render(m, truth, size, runs, dir) {
                        Ok(r) => Some(r),
                        Err(e) => {
                            println!("Mitsuba at {} x {}: failed: {e}", size.0, size.1);
                            None
                        }
                    },
                )
                .collect()
        }
        Err(why) => {
            println!("Mitsuba: not run, so no ratios: {why}");
            vec![None, None]
        }
    };
    if anchors.iter().any(Option::is_some) {
        println!(
            "\nMitsuba 3, table1-truth.gltf, {} spp, path depth {}, \
             best of {runs} fresh processes after a warm-up:\n",
            mitsuba::SPP,
            mitsuba::DEPTH
        );
        println!("| size | import | read glTF | load_dict (BVH) | render | read + load + render | process wall (the anchor) | peak MiB | load avg |");
        println!("|---|---|---|---|---|---|---|---|---|");
    }
    for (a, size) in anchors.iter().zip(["600 x 600", "1920 x 1080"]) {
        if let Some(a) = a {
            println!(
                "| {size} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | **{:.2}** | {:.0} | {} |",
                a.import,
                a.read,
                a.load,
                a.render,
                a.in_process(),
                a.anchor(),
                a.process.peak_mib,
                load_text(&a.process)
            );
        }
    }

    let stacked = root.join("samples/stacked.png");
    let cases = [
        Case::new(
            "default fit, table1.png",
            &scene,
            &table1,
            &[],
            0,
            0.5,
            runs,
        ),
        Case::new(
            "default fit, 1920 x 1080",
            &hd_scene,
            &hd_photo,
            &[],
            1,
            1.0,
            runs,
        ),
        Case::new(
            "`--gloss auto`, table1.png",
            &scene,
            &table1,
            &["--gloss", "auto"],
            0,
            1.0,
            long_runs,
        ),
        Case::new(
            "overlap fit, stacked.png (lamps in frame)",
            &scene,
            &stacked,
            &[],
            0,
            1.0,
            long_runs,
        ),
        Case::new(
            "overlap fit, stacked.png, `--no-direct-view` (as out of frame)",
            &scene,
            &stacked,
            &["--no-direct-view"],
            0,
            1.0,
            long_runs,
        ),
    ];
    println!("\nstreaklight fit, child processes (best of the runs):\n");
    println!(
        "| fit | runs | lights | wall s | peak MiB | load avg | / Mitsuba's process | \
         / its read + load + render | target (on the process) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut stages = Vec::new();
    for Case {
        name,
        scene,
        photo,
        extra,
        anchor,
        target,
        runs,
    } in cases
    {
        let f = fit(scene, photo, extra, runs, dir);
        let ratio = anchors[anchor]
            .as_ref()
            .map(|a| f.measured.wall / a.anchor());
        let strict = anchors[anchor]
            .as_ref()
            .map(|a| f.measured.wall / a.in_process());
        println!(
            "| {name} | {runs} | {} | {:.2} | {:.0} | {} | {} | {} | {} |",
            f.lights,
            f.measured.wall,
            f.measured.peak_mib,
            load_text(&f.measured),
            ratio.map_or("-".into(), |r| format!("**{r:.2}**")),
            strict.map_or("-".into(), |r| format!("{r:.2}")),
            match ratio {
                Some(r) if r <= target => format!("<= {target}: met"),
                Some(_) => format!("<= {target}: not met"),
                None => format!("<= {target}"),
            }
        );
        stages.push((name, stage_text(&f.stages)));
    }
    println!("\nstages of each best run (the report's timings, seconds):\n");
    for (name, s) in stages {
        println!("- {name}: {s}");
    }
}

/// How the default fit's time and memory grow with the photo and with the water mesh.
fn cost_table(dir: &Path) {
    println!("\ndefault fit of scene.gltf, one run each; photos rendered from table1-truth.gltf\n");
    println!("| photo | water triangles | wall s | peak MiB | load avg | stages |");
    println!("|---|---|---|---|---|---|");
    let grid = samples::water_grid();
    let base_triangles = 2 * grid.rows * grid.columns;
    for (w, h) in [(600, 600), (1920, 1080), (4000, 3000)] {
        let (scene, truth) = scenes_for(dir, (w, h));
        let photo = dir.join(format!("table1-{w}x{h}.png"));
        render_photo(&truth, &photo, (w, h), dir);
        let f = fit(&scene, &photo, &[], 1, dir);
        cost_row(&format!("{w} x {h}"), base_triangles, &f);
        let _ = std::fs::remove_file(&photo);
    }
    for factor in [2, 4] {
        let grid = samples::finer_water_grid(factor);
        let sub = dir.join(format!("mesh-{factor}"));
        samples::write_paper_scenes_on_grid(&sub, &["scene.gltf", "table1-truth.gltf"], &grid)
            .unwrap_or_else(|e| panic!("writing the scenes: {e}"));
        let photo = sub.join("table1.png");
        render_photo(&sub.join("table1-truth.gltf"), &photo, (600, 600), dir);
        let f = fit(&sub.join("scene.gltf"), &photo, &[], 1, dir);
        cost_row("600 x 600", 2 * grid.rows * grid.columns, &f);
        let _ = std::fs::remove_dir_all(&sub);
    }
}

fn cost_row(photo: &str, triangles: usize, f: &FitRun) {
    println!(
        "| {photo} | {:.2} M | {:.2} | {:.0} | {} | {} |",
        triangles as f64 / 1e6,
        f.measured.wall,
        f.measured.peak_mib,
        load_text(&f.measured),
        stage_text(&f.stages)
    );
}
