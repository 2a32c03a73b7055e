//! `fit --debug-dir` on the Table 3 sample: pictures that explain themselves (titles, keys,
//! numbered streaks, the lights' reflections outlined, a signed residual), and an index.html
//! that headless Chromium shows with every picture and the report's numbers. Also the
//! report's honesty about Table 3's second light, whose streak runs off the photo.
//!
//! Needs Node, `npm ci --prefix tests/engines` and Debian's Chromium, which `scripts/test`
//! installs; without them the Chromium test fails and says so.

mod common;

use std::path::PathBuf;
use std::sync::OnceLock;

use common::cli::arg;
use common::json::{read_json, schema_validator};
use common::node::run_node;
use common::pipeline::{sample_photo_path, sample_scenes};
use serde_json::Value;

/// One fit of the Table 3 sample with a report and debug pictures: (folder, stderr).
fn table3() -> &'static (PathBuf, String) {
    static FIT: OnceLock<(PathBuf, String)> = OnceLock::new();
    FIT.get_or_init(|| {
        let dir = common::temp_dir("debug-page");
        let args = [
            "fit".to_owned(),
            arg(&sample_scenes().join("scene.gltf")),
            arg(&sample_photo_path("table3.png")),
            "--exposure".into(),
            "0.1".into(),
            "-o".into(),
            arg(&dir.join("lit.gltf")),
            "--report".into(),
            arg(&dir.join("report.json")),
            "--debug-dir".into(),
            arg(&dir.join("debug")),
        ];
        let (ok, _, stderr) = common::run_cli(&args);
        assert!(ok, "{stderr}");
        (dir, stderr)
    })
}

fn report() -> Value {
    read_json(&table3().0.join("report.json"))
}

fn picture(name: &str) -> image::RgbImage {
    let path = table3().0.join("debug").join(name);
    image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_rgb8()
}

fn count(
    img: &image::RgbImage,
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
    f: impl Fn([u8; 3]) -> bool,
) -> usize {
    let mut n = 0;
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            n += usize::from(f(img.get_pixel(x, y).0));
        }
    }
    n
}

#[test]
fn the_debug_page_shows_every_picture_and_light_in_chromium() {
    let (dir, _) = table3();
    let debug = dir.join("debug");
    let shot = dir.join("page.png");
    let seen = run_node(
        "debug_page_check.mjs",
        &[
            ("--dir", &debug),
            ("--report", &dir.join("report.json")),
            ("--screenshot", &shot),
        ],
        dir,
    );
    assert!(seen.contains("streaklight_light_1"), "{seen}");
    // The screenshot shows the page: light text on the dark background, and pictures.
    let page = image::open(&shot).unwrap().into_rgb8();
    assert!(
        page.height() > 1000,
        "a full-page screenshot: {:?}",
        page.dimensions()
    );
    let bright = count(&page, 0, 0, page.width(), page.height(), |p| {
        p.iter().all(|&c| c > 200)
    });
    assert!(bright > 1000, "{bright} bright pixels: is the text there?");
}

/// Every edge's status, pixel count, reason and uncertainty agree, on both lights; the
/// second light (its streak cut by the photo's border) is warned about on stderr and in the
/// report, naming its edges.
#[test]
fn the_report_is_consistent_and_warns_about_unconstrained_edges() {
    let report = report();
    let errors: Vec<String> = schema_validator("report.schema.json")
        .iter_errors(&report)
        .map(|e| format!("{} at {}", e, e.instance_path))
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(report["status"], "lights found");
    let lights = report["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 2);
    for light in lights {
        let name = light["name"].as_str().unwrap();
        let mut unconstrained = Vec::new();
        for side in ["left", "right", "bottom", "top"] {
            let edge = &light["edges"][side];
            let sigma = &light["uncertainty"][side];
            let reason = edge["reason"].as_str();
            match edge["status"].as_str().unwrap() {
                "constrained" => {
                    assert!(reason.is_none(), "{name} {side}: {edge}");
                    assert!(
                        edge["pixels"].as_u64().unwrap() > 0,
                        "{name} {side}: {edge}"
                    );
                    assert!(
                        sigma.as_f64().is_some_and(|s| s > 0.0),
                        "{name} {side}: {sigma}"
                    );
                }
                "unconstrained" => {
                    unconstrained.push(side);
                    assert!(
                        sigma.is_null(),
                        "{name} {side}: unconstrained with sigma {sigma}"
                    );
                    let reason = reason.unwrap_or_else(|| panic!("{name} {side}: no reason"));
                    // A reason that counts pixels counts the ones the report gives.
                    if let Some(rest) = reason.split("fitted from the other ").nth(1) {
                        let n: u64 = rest.split(',').next().unwrap().trim().parse().unwrap();
                        assert_eq!(edge["pixels"].as_u64(), Some(n), "{name} {side}: {edge}");
                    }
                    if reason.starts_with("only 0 ") {
                        assert_eq!(edge["pixels"].as_u64(), Some(0), "{name} {side}: {edge}");
                    }
                }
                other => panic!("{name} {side}: status {other}"),
            }
        }
        let warnings: Vec<&str> = report["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|w| w.as_str())
            .filter(|w| w.starts_with(&format!("{name}:")))
            .collect();
        if unconstrained.is_empty() {
            continue;
        }
        assert_eq!(warnings.len(), 1, "{name}: {warnings:?}");
        assert!(
            warnings[0].contains(&format!("its {} edge", unconstrained.join(", "))),
            "{name} has unconstrained {unconstrained:?}: {}",
            warnings[0]
        );
        assert!(
            table3().1.contains(&format!("warning: {}", warnings[0])),
            "not on stderr: {}",
            table3().1
        );
    }
    // Table 3's second light runs off the photo on the right: it must be among the warned.
    let light1 = &lights[1];
    assert_eq!(
        light1["edges"]["right"]["status"], "unconstrained",
        "{light1}"
    );
}

#[test]
fn the_pictures_are_titled_keyed_numbered_and_the_residual_is_signed() {
    let side = 600;
    for name in ["superpixels.png", "seeds.png", "streaks.png", "edges.png"] {
        let img = picture(name);
        assert_eq!(img.width(), side, "{name}");
        let header = img.height() - side;
        assert!(header >= 40, "{name}: a header of {header} px");
        // Light text in the dark header.
        let ink = count(&img, 0, 0, side, header, |p| p == [235, 235, 235]);
        assert!(ink > 100, "{name}: {ink} text pixels in the header");
    }
    // The streaks are numbered on the picture: text on a black box near each brightest pixel.
    let streaks = picture("streaks.png");
    let colour0 = streaklight::streaks::pictures::streak_colour(0);
    let header = streaks.height() - side;
    let labelled = count(&streaks, 0, header, side, side, |p| p == colour0);
    assert!(labelled > 0);

    let fit = picture(streaklight::debug_pictures::FIT_PICTURE);
    assert_eq!(fit.width(), 3 * side + 2 * 4, "three panels 4 px apart");
    let top = fit.height() - side;
    // The photo panel has each light's outline in its colour.
    for k in 0..2 {
        let c = streaklight::debug_pictures::light_colour(k);
        let n = count(&fit, 0, top, side, side, |p| p == c);
        assert!(n > 50, "light {k}'s outline: {n} pixels of {c:?}");
    }
    // The residual is signed: photo above and below the model, both on the water.
    let x0 = 2 * (side + 4);
    let red = count(&fit, x0, top, side, side, |p| p[0] > 60 && p[2] == 0);
    let blue = count(&fit, x0, top, side, side, |p| p[2] > 60 && p[0] == 0);
    assert!(red > 100 && blue > 100, "red {red}, blue {blue}");
    // The page shows every picture and names every light.
    let html = std::fs::read_to_string(table3().0.join("debug").join("index.html")).unwrap();
    for light in report()["lights"].as_array().unwrap() {
        assert!(html.contains(light["name"].as_str().unwrap()));
    }
    for name in [
        "superpixels.png",
        "seeds.png",
        "streaks.png",
        "edges.png",
        "fit-photo-render-difference.png",
    ] {
        assert!(
            html.contains(&format!("src=\"{name}\"")),
            "{name} not on the page"
        );
    }
}
