//! Estimating the water's gloss (`streaklight::fitting::gloss`) on the committed sample photos
//! of Table 1's light over water of gloss 200, 500 and 1000, against the gloss they were
//! rendered with. Run in release mode: each estimate is a handful of joint fits.

mod common;

use std::time::Instant;

use common::pipeline::{
    convert_options, observations, sample_photo, sample_photo_path, sample_scene, sample_scenes_in,
    water,
};
use streaklight::fitting::gloss::{estimate_gloss, GlossEstimate, GlossSearch, SEARCH_SAMPLES};
use streaklight::fitting::joint::JointOptions;
use streaklight::fitting::{EdgeSide, EdgeStatus, FitOptions, StreakObservation};
use streaklight::photo_in::Photo;
use streaklight::samples;
use streaklight::scene_in::Scene;
use streaklight::Error;

/// The gloss search from the scene's own gloss with seed `seed`, its final fit at the search's
/// samples (as `fit --gloss auto` runs it).
fn estimate_seeded(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    search: &GlossSearch,
    seed: u64,
) -> streaklight::Result<GlossEstimate> {
    estimate_with(scene, photo, water, streaks, search, seed, true)
}

/// [`estimate_seeded`], the final fit's (and so the search's) regions close around whole
/// lamps' images or not (`JointOptions::close_regions`).
fn estimate_with(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    search: &GlossSearch,
    seed: u64,
    close_regions: bool,
) -> streaklight::Result<GlossEstimate> {
    let paper = FitOptions {
        seed,
        ..FitOptions::for_scene(scene)
    };
    let final_fit = JointOptions {
        samples: SEARCH_SAMPLES,
        close_regions,
        ..JointOptions::new(paper.model, seed)
    };
    estimate_gloss(
        scene, photo, water, streaks, &paper, None, &final_fit, search,
    )
}

/// Estimates the gloss of a sample photo, starting from the scene's own gloss (500).
fn estimate(scene: &Scene, photo_name: &str) -> (GlossEstimate, usize, f64) {
    let photo = sample_photo(photo_name);
    let water = water(scene, &photo);
    let streaks = observations(&photo, &water);
    let t = Instant::now();
    let found =
        estimate_seeded(scene, &photo, &water, &streaks, &GlossSearch::default(), 1).unwrap();
    (found, streaks.len(), t.elapsed().as_secs_f64())
}

/// Within 10 % of the rendered gloss, from the scene's gloss of 500 (so a factor 2.5 too
/// high for gloss200.png), with the minimum bracketed and one light. The third photo,
/// gloss1000.png (a factor 2 too low, two streaks the paper fit merges into one light), is
/// held through the converter (`gloss_auto_through_the_converter`). Measured: 201.4, 503.3
/// and 989.4.
#[test]
fn estimates_the_gloss_of_the_sample_photos() {
    let scene = sample_scene("scene.gltf", None);
    // The scene stores a roughness, so its gloss comes back as 500 to within rounding.
    assert!(
        (scene.water.gloss - 500.0).abs() < 0.01,
        "the search starts from the scene's gloss, {}",
        scene.water.gloss
    );
    let truth = samples::table1_light();
    let mut failures = Vec::new();
    for (photo, gloss, tolerance) in [("gloss200.png", 200.0f32, 0.1), ("table1.png", 500.0, 0.1)] {
        let (found, streaks, seconds) = estimate(&scene, photo);
        let error = found.gloss / gloss - 1.0;
        eprintln!(
            "{photo}: true e {gloss}, estimated {:.1} ({:+.1} %), sigma(ln e) {:?}, {} streak(s), \
             {:.1} s {:?}",
            found.gloss,
            100.0 * error,
            found.sigma_ln,
            streaks,
            seconds,
            found.timings
        );
        eprintln!("  evaluations (e, cost): {:?}", found.evaluations);
        for light in &found.lights {
            let c = light.corner_left_bottom_world(scene.origin);
            eprintln!(
                "  light: corner ({:.4}, {:.4}), {:.4} x {:.4}, L {:.3} (truth ({}, {}), {} x {}, \
                 L {})",
                c.x,
                c.y,
                light.width(),
                light.height(),
                light.radiance[0],
                truth.corner.x,
                truth.corner.y,
                truth.width,
                truth.height,
                truth.radiance[0]
            );
        }
        if !found.warnings.is_empty() {
            eprintln!("  warnings: {:?}", found.warnings);
        }
        if error.abs() >= tolerance {
            failures.push(format!("{photo}: estimated {} for {gloss}", found.gloss));
        }
        if found.sigma_ln.is_none() {
            failures.push(format!("{photo}: the minimum was not bracketed"));
        }
        if found.lights.len() != 1 {
            failures.push(format!("{photo}: {} lights", found.lights.len()));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// The estimate does not depend on where it starts: Table 3's photo (two lights over water
/// of gloss 500, one cut by the photo's border) from a scene whose material says e = 100 or
/// 2000 (5 and 4 times off, either side) gives e within 3 % of 500 both times, and the same two lights (their constrained
/// edges within 0.5 % of each light's size of the truth), no extra light. Measured here
/// from 100 and 2000: 499.7 and 511.6.
#[test]
fn the_gloss_and_the_lights_do_not_depend_on_the_start() {
    let truths = samples::table3_lights();
    let mut failures = Vec::new();
    for start in [100.0f32, 2000.0] {
        let scene = sample_scene("scene.gltf", Some(start));
        let (found, _, seconds) = estimate(&scene, "table3.png");
        eprintln!(
            "from e = {start}: {:.1} in {seconds:.1} s, {} light(s), warnings {:?}",
            found.gloss,
            found.lights.len(),
            found.warnings
        );
        if (found.gloss / 500.0 - 1.0).abs() >= 0.03 {
            failures.push(format!("from {start}: e = {}", found.gloss));
        }
        if found.lights.len() != truths.len() {
            failures.push(format!("from {start}: {} lights", found.lights.len()));
            continue;
        }
        for truth in &truths {
            let centre = (
                truth.corner.x + truth.width / 2.0,
                truth.corner.y + truth.height / 2.0,
            );
            let distance = |l: &streaklight::fitting::FittedLight| {
                let c = l.world_at(
                    scene.origin,
                    (l.u_min + l.u_max) / 2.0,
                    (l.v_min + l.v_max) / 2.0,
                );
                (c.x - centre.0).hypot(c.y - centre.1)
            };
            let Some(light) = found
                .lights
                .iter()
                .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            else {
                continue;
            };
            let (um, vm) = (
                (light.u_min + light.u_max) / 2.0,
                (light.v_min + light.v_max) / 2.0,
            );
            for side in EdgeSide::ALL {
                if !matches!(light.edges[side], EdgeStatus::Constrained { .. }) {
                    continue;
                }
                // The edge's place in the world, against the nearer of the truth's two
                // edges on that axis (the plane's u may run along -x).
                let (u, v) = match side {
                    EdgeSide::Left => (light.u_min, vm),
                    EdgeSide::Right => (light.u_max, vm),
                    EdgeSide::Bottom => (um, light.v_min),
                    EdgeSide::Top => (um, light.v_max),
                };
                let p = light.world_at(scene.origin, u, v);
                let (got, edges, size) = if matches!(side, EdgeSide::Left | EdgeSide::Right) {
                    let x = truth.corner.x;
                    (p.x, [x, x + truth.width], truth.width)
                } else {
                    let y = truth.corner.y;
                    (p.y, [y, y + truth.height], truth.height)
                };
                let error = edges
                    .iter()
                    .map(|e| (got - e).abs())
                    .fold(f64::MAX, f64::min);
                if error >= 0.005 * size {
                    failures.push(format!(
                        "from {start}: {side:?} edge at {got:.4}, truth {edges:?}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// Bad input is an error with a message, never a panic.
#[test]
fn refuses_bad_input() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let water = water(&scene, &photo);
    let options = GlossSearch::default();

    let none = estimate_seeded(&scene, &photo, &water, &[], &options, 1).unwrap_err();
    assert!(matches!(none, Error::NothingFound(_)), "{none}");
    assert!(none.to_string().contains("no streak"), "{none}");

    let streaks = observations(&photo, &water);
    let short = estimate_seeded(&scene, &photo, &water[1..], &streaks, &options, 1).unwrap_err();
    assert!(matches!(short, Error::Usage(_)), "{short}");

    for bad in [
        GlossSearch {
            min_gloss: 0.0,
            ..options
        },
        GlossSearch {
            max_gloss: 10.0,
            ..options
        },
        GlossSearch {
            min_gloss: f32::NAN,
            ..options
        },
        GlossSearch {
            tolerance_ln: 0.0,
            ..options
        },
        GlossSearch {
            max_evaluations: 2,
            ..options
        },
        GlossSearch {
            search_samples: 0,
            ..options
        },
    ] {
        let e = estimate_seeded(&scene, &photo, &water, &streaks, &bad, 1).unwrap_err();
        assert!(matches!(e, Error::Usage(_)), "{e}");
        eprintln!("refused: {e}");
    }
}

/// How much the estimate moves with the seed of the fits (their Monte Carlo noise, which
/// `sigma_ln` leaves out): `cargo test --release --test gloss -- --ignored --nocapture`.
/// Seeds from `GLOSS_SEEDS` (default "2 3"), photos from `GLOSS_PHOTOS` (default all three).
#[test]
#[ignore = "a measurement (minutes), not a check"]
fn seed_spread() {
    let scene = sample_scene("scene.gltf", None);
    let seeds = std::env::var("GLOSS_SEEDS").unwrap_or_else(|_| "2 3".into());
    let photos = std::env::var("GLOSS_PHOTOS")
        .unwrap_or_else(|_| "gloss200.png table1.png gloss1000.png".into());
    for photo_name in photos.split_whitespace() {
        let photo = sample_photo(photo_name);
        let water = water(&scene, &photo);
        let streaks = observations(&photo, &water);
        for seed in seeds.split_whitespace().map(|s| s.parse::<u64>().unwrap()) {
            let t = Instant::now();
            let found = estimate_seeded(
                &scene,
                &photo,
                &water,
                &streaks,
                &GlossSearch::default(),
                seed,
            )
            .unwrap();
            eprintln!(
                "{photo_name} seed {seed}: e {:.1}, sigma(ln e) {:?}, {} evaluations, {:.1} s",
                found.gloss,
                found.sigma_ln,
                found.evaluations.len(),
                t.elapsed().as_secs_f64()
            );
        }
    }
}

/// `fit --gloss auto` through the converter: the e = 1000 photo fitted from the scene's
/// e = 500 reports the estimated gloss (within 10 %, the minimum bracketed: no warning that
/// the search stopped short) and where it came from, and a light within 1 % of the truth;
/// `--gloss auto` with `--method paper` is refused.
#[test]
fn gloss_auto_through_the_converter() {
    use streaklight::convert::{convert, ConvertOptions};
    use streaklight::pipeline::{FitSettings, JointSettings, Method};
    use streaklight::progress::Reporter;
    let dir = sample_scenes_in("gloss-auto");
    let lines = std::sync::Mutex::new(Vec::new());
    let record = |line: &str| lines.lock().unwrap().push(line.to_string());
    let options = ConvertOptions {
        fit: FitSettings {
            method: Method::Joint(JointSettings::estimating_gloss()),
            ..FitSettings::default()
        },
        progress: Reporter::new(&record),
        ..convert_options(&dir, sample_photo_path("gloss1000.png"), "out.gltf")
    };
    // The library cannot express the paper's method with a gloss estimate; the command line
    // refuses the pair.
    let refused = std::process::Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .arg("fit")
        .arg(&options.scene)
        .arg(&options.photo)
        .arg("-o")
        .arg(&options.output)
        .args(["--exposure", "0.1", "--method", "paper", "--gloss", "auto"])
        .output()
        .expect("running streaklight");
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && stderr.contains("--gloss auto"),
        "{stderr}"
    );
    assert!(
        !dir.join("out.gltf").exists(),
        "a refused run writes nothing"
    );
    let report = convert(&options).expect("fit with --gloss auto").report;
    eprintln!(
        "gloss {} ({}), lights {:?}",
        report.settings.gloss,
        report.settings.gloss_source,
        report
            .lights
            .iter()
            .map(|l| (l.corner_left_bottom, l.width, l.height, l.radiance[0]))
            .collect::<Vec<_>>()
    );
    assert!(
        (report.settings.gloss / 1000.0 - 1.0).abs() < 0.1,
        "estimated e = {}",
        report.settings.gloss
    );
    assert!(report.settings.gloss_source.contains("estimated"));
    assert!(
        !report
            .warnings
            .iter()
            .any(|w| w.contains("gloss estimate lies at") || w.contains("gloss search stopped")),
        "{:?}",
        report.warnings
    );
    // The search told each of its fits, and the final one, as they started.
    let lines = lines.lock().unwrap().clone();
    let searched = lines
        .iter()
        .filter(|l| l.starts_with("gloss search: joint fit "))
        .count();
    assert!(searched >= 3, "{lines:?}");
    // The first fit's trace, the search's long step, is told as it goes: between its
    // announcement and the second fit's, the trace of its search samples.
    let first = lines
        .iter()
        .position(|l| l.starts_with("gloss search: joint fit 1 "))
        .expect("the first fit announced");
    let second = lines
        .iter()
        .position(|l| l.starts_with("gloss search: joint fit 2 "))
        .expect("the second fit announced");
    let search_samples = streaklight::fitting::gloss::GlossSearch::default().search_samples;
    assert!(
        lines[first..second]
            .iter()
            .any(|l| l.starts_with("joint fit: tracing the footprints")
                && l.contains(&format!("{search_samples} samples each"))),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l
            == &format!(
                "gloss search: final joint fit at e = {:.0}",
                report.settings.gloss
            )),
        "{lines:?}"
    );
    // The final fit reads what a fit of a given gloss reads; the search's own fits more.
    assert_eq!(
        report.settings.joint_samples,
        Some(streaklight::fitting::joint::DEFAULT_JOINT_SAMPLES)
    );
    assert_eq!(report.lights.len(), 1);
    let light = &report.lights[0];
    let truth = samples::table1_light();
    let c = light.corner_left_bottom;
    for (got, want) in [
        (c[0], truth.corner.x),
        (c[0] + light.width, truth.corner.x + truth.width),
        (c[1], truth.corner.y),
        (c[1] + light.height, truth.corner.y + truth.height),
    ] {
        assert!(
            (got - want).abs() < 0.01 * truth.width,
            "edge {got} vs {want}"
        );
    }
    assert!(
        (light.radiance[0] - 20.0).abs() < 0.2,
        "{:?}",
        light.radiance
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A light on its lamp's whole image searches close around the image in every fit of the
/// search, as in a fit of a given gloss (`JointOptions::close_regions`), and the estimate is
/// the one the wide region gives. On Table 1 the close region (the image grown by 5 % of its
/// 3 m side) has about a quarter of the wide one's area on the wall (the start grown by 1.25
/// times half its side: 3.3^2 against 6.75^2 m^2), so the search's final fit reads fewer than
/// 0.4 times the wall pixels seen directly, and no more water pixels (the streak's box bounds
/// them either way). Measured: 7 482 direct pixels against 26 622, 19 654 water pixels
/// against 24 768; the gloss 503.3 against 503.0 (within 0.5 % asked), the light within a
/// millimetre and 0.1 % of radiance of the wide one's.
#[test]
fn a_whole_lamp_holds_the_search_close_to_its_image() {
    let scene = sample_scene("scene.gltf", None);
    let photo = sample_photo("table1.png");
    let water = water(&scene, &photo);
    let streaks = observations(&photo, &water);
    let search = GlossSearch::default();
    let run = |close: bool| estimate_with(&scene, &photo, &water, &streaks, &search, 1, close);
    let (close, wide) = (run(true).unwrap(), run(false).unwrap());
    let direct = |e: &GlossEstimate| e.pixels - e.modelled.len();
    eprintln!(
        "close: e {:.1}, {} water and {} direct pixels; wide: e {:.1}, {} and {}",
        close.gloss,
        close.modelled.len(),
        direct(&close),
        wide.gloss,
        wide.modelled.len(),
        direct(&wide)
    );
    assert!(
        (direct(&close) as f64) < 0.4 * direct(&wide) as f64,
        "{} direct pixels read close around the image, {} with the wide region",
        direct(&close),
        direct(&wide)
    );
    assert!(close.modelled.len() <= wide.modelled.len());
    assert!(
        (close.gloss / wide.gloss - 1.0).abs() < 0.005,
        "e {} close, {} wide",
        close.gloss,
        wide.gloss
    );
    assert_eq!((close.lights.len(), wide.lights.len()), (1, 1));
    let (a, b) = (&close.lights[0], &wide.lights[0]);
    for side in EdgeSide::ALL {
        let (ea, eb) = (a.rect().edge(side), b.rect().edge(side));
        assert!((ea - eb).abs() < 1e-3, "{side:?}: {ea} close, {eb} wide");
    }
    assert!(
        (a.radiance[0] / b.radiance[0] - 1.0).abs() < 1e-3,
        "radiance {} close, {} wide",
        a.radiance[0],
        b.radiance[0]
    );
}
