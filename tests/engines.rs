//! A real engine reads our lights. Babylon.js's own glTF loader (which imports
//! `EXT_lights_area`) loads a lit scene in headless Chromium; `tests/engines/babylon_check.mjs`
//! checks the lights it created against the report, and this test checks its screenshots. The
//! three.js example (`examples/threejs/`), served by its own `npm start` server with its own
//! three, does the same through its GLTFLoader plugin (`tests/engines/threejs_check.mjs`).
//!
//! Needs Node, `npm ci --prefix tests/engines`, `npm ci --prefix examples/threejs` and Debian's
//! Chromium, which `scripts/test` installs; without them the test fails and says so.
//!
//! The lit scene and its report are a real `fit` of the Table 3 sample photo with `--report`
//! ([`lit_scene_and_report`]): the Node scripts read only those two files.

mod common;

use common::node::run_node;

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use streaklight::samples;

/// One headless Chromium at a time: two software-rendering browsers on a 2-core machine
/// would each take twice as long.
static BROWSER: Mutex<()> = Mutex::new(());

/// Writes the sample scenes into `dir` and fits `scene.gltf` to the Table 3 photo with a
/// report; returns (input scene, lit scene, report).
fn lit_scene_and_report(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    samples::write_scenes(dir).expect("writing the sample scenes");
    let input = dir.join("scene.gltf");
    let output = dir.join("lit.gltf");
    let report = dir.join("report.json");
    // A real `fit` of the Table 3 sample photo: what Babylon must reproduce is what the
    // report says, whatever the fit's accuracy.
    let options = streaklight::convert::ConvertOptions {
        report: Some(report.clone()),
        exposure: samples::PHOTO_EXPOSURE,
        ..streaklight::convert::ConvertOptions::new(
            &input,
            Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/table3.png"),
            &output,
        )
    };
    let outcome = streaklight::convert::convert(&options).expect("fitting the Table 3 sample");
    assert_eq!(outcome.report.lights.len(), 2, "Table 3 has two lights");
    (input, output, report)
}

/// Mean of (r + g + b) / 3 over the pixels where `mask` is set, in 8-bit units.
fn mean_where(image: &image::RgbImage, mask: &[bool]) -> f64 {
    let (sum, n) = image
        .pixels()
        .zip(mask)
        .filter(|(_, &m)| m)
        .fold((0.0, 0usize), |(s, n), (p, _)| {
            (s + (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0, n + 1)
        });
    sum / n as f64
}

/// Share of the pixels where `mask` is set whose brightest channel is at least `level`.
fn share_at_least(image: &image::RgbImage, mask: &[bool], level: u8) -> f64 {
    let (hit, n) = image
        .pixels()
        .zip(mask)
        .filter(|(_, &m)| m)
        .fold((0usize, 0usize), |(h, n), (p, _)| {
            (h + usize::from(p[0].max(p[1]).max(p[2]) >= level), n + 1)
        });
    hit as f64 / n as f64
}

fn read_png(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("cannot read the screenshot {}: {e}", path.display()))
        .to_rgb8()
}

#[test]
fn babylon_reads_the_lights_and_lights_the_water() {
    let dir = common::temp_dir("engines-babylon");
    let (input, output, report) = lit_scene_and_report(&dir);
    let (lit_png, dark_png, mask_png) = (
        dir.join("lit.png"),
        dir.join("dark.png"),
        dir.join("water-mask.png"),
    );

    let started = Instant::now();
    let _one_browser = BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    run_node(
        "babylon_check.mjs",
        &[
            ("--gltf", &output),
            ("--report", &report),
            ("--screenshot", &lit_png),
            ("--dark-gltf", &input),
            ("--dark-screenshot", &dark_png),
            ("--mask-screenshot", &mask_png),
        ],
        &dir,
    );
    println!(
        "Babylon check took {:.1} s",
        started.elapsed().as_secs_f64()
    );

    let lit = read_png(&lit_png);
    let dark = read_png(&dark_png);
    let mask_image = read_png(&mask_png);
    assert_eq!(lit.dimensions(), dark.dimensions());
    assert_eq!(lit.dimensions(), mask_image.dimensions());
    // The mask is the water drawn flat white on black; anti-aliased edges count as half.
    let water: Vec<bool> = mask_image.pixels().map(|p| p[0] > 127).collect();
    let water_pixels = water.iter().filter(|&&m| m).count();
    let total = water.len();
    // The camera looks level from 0.2 m above the water, so the water fills the lower half
    // of the frame, less the strip beyond the wall.
    assert!(
        water_pixels > total / 4,
        "the water covers only {water_pixels} of {total} pixels in {}",
        mask_png.display()
    );

    let lit_mean = mean_where(&lit, &water);
    let dark_mean = mean_where(&dark, &water);
    let lit_share = share_at_least(&lit, &water, 8);
    println!(
        "water: {water_pixels} px; mean brightness lit {lit_mean:.2}/255, without our lights {dark_mean:.2}/255; \
         {:.0}% of it at >= 8/255",
        100.0 * lit_share
    );
    // Without our lights the scene has no light source at all (no environment, black
    // background), so its water must be black: then anything the lit render adds is our lights'
    // doing.
    assert!(
        dark_mean < 0.5,
        "the scene without our lights is not black where the water is (mean {dark_mean:.2}/255): the comparison would prove nothing"
    );
    // Our lights must visibly light the water. A light facing away from the water (the wrong
    // side) leaves it exactly black (tried by turning the light nodes round: mean 0), and a
    // light Babylon did not import too. 4/255 is four 8-bit steps, well clear of rounding and
    // dithering; Babylon 9.28 puts about 15/255 on this water (its area-light specular is weak
    // on dielectrics, see tests/engines/README.md), so the margin is not tight either way.
    assert!(
        lit_mean > dark_mean + 4.0,
        "the lit water (mean {lit_mean:.2}/255 in {}) is not clearly brighter than without our lights ({dark_mean:.2}/255): \
         lights facing away from the water, or not imported?",
        lit_png.display()
    );
    // Not black *where the water is*: most of the water, not a few bright pixels.
    assert!(
        lit_share > 0.5,
        "only {:.0}% of the water reaches 8/255 in {}",
        100.0 * lit_share,
        lit_png.display()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The three.js example's GLTFLoader plugin makes RectAreaLights that match the
/// report, and the example page lights the water with them.
#[test]
fn threejs_example_plugin_makes_matching_rect_area_lights() {
    let dir = common::temp_dir("engines-threejs");
    let (_input, output, report) = lit_scene_and_report(&dir);
    let shot = dir.join("threejs.png");
    let _one_browser = BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    run_node(
        "threejs_check.mjs",
        &[
            ("--gltf", &output),
            ("--report", &report),
            ("--screenshot", &shot),
        ],
        &dir,
    );
    // The camera looks level from just above the water, so the lower 40% of the frame is
    // water only (compare the Babylon test's mask); the example has no other light, so any
    // brightness there is our lights' doing (4/255: see the Babylon test).
    let image = read_png(&shot);
    let (w, h) = image.dimensions();
    let water: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |_| y >= h * 6 / 10))
        .collect();
    let mean = mean_where(&image, &water);
    println!("three.js: mean brightness of the lower 40% {mean:.2}/255");
    assert!(
        mean > 4.0,
        "the three.js example leaves the water black (mean {mean:.2}/255 in {})",
        shot.display()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
