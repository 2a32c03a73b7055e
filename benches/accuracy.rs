//! The accuracy table: every case of the paper's Tables 1-3 fitted by `streaklight fit` on the
//! committed sample photos, beside the truth and the paper's own results (method §6).
//! Run with `cargo bench --bench accuracy`; prints a Markdown table.

use std::path::{Path, PathBuf};

use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, Method};
use streaklight::samples;
use streaklight::scene_in::LoadOptions;

struct Case {
    name: &'static str,
    scene: &'static str,
    photo: &'static str,
    gloss: Option<f32>,
    /// Centre of the true light (x, y) on its wall: the fitted light nearest to it is the
    /// one reported (the joint fit may add lights, and orders them as it finds them).
    centre: (f64, f64),
    truth: &'static str,
    paper: &'static str,
}

fn options(dir: &Path, case: &Case, method: Method) -> ConvertOptions<'static> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    ConvertOptions {
        load: LoadOptions {
            gloss: case.gloss,
            ..Default::default()
        },
        exposure: samples::PHOTO_EXPOSURE,
        fit: FitSettings {
            method,
            ..FitSettings::default()
        },
        ..ConvertOptions::new(
            dir.join(case.scene),
            root.join("samples").join(case.photo),
            dir.join(format!("{}.gltf", case.name.replace([' ', ','], "_"))),
        )
    }
}

fn main() {
    let dir = std::env::temp_dir().join(format!("streaklight-accuracy-{}", std::process::id()));
    samples::write_scenes(&dir).expect("writing the sample scenes");
    let cases = [
        Case {
            name: "T1 light0, e=500",
            scene: "scene.gltf",
            photo: "table1.png",
            gloss: None,
            centre: (-2.5, 3.5),
            truth: "(-4, 2, 0), 3 x 3, L 20",
            paper: "(-3.9687, 1.99092, 0), 2.95216 x 3.04463, L 21.4182",
        },
        Case {
            name: "T1 light0, e=200 (wrong gloss)",
            scene: "scene.gltf",
            photo: "table1.png",
            gloss: Some(200.0),
            centre: (-2.5, 3.5),
            truth: "same",
            paper: "(-3.5585, 2.4205, 0), 2.15409 x 2.41417, L 22.9963",
        },
        Case {
            name: "T2 light0, wall at z=-3",
            scene: "table2-wall-minus3.gltf",
            photo: "table1.png",
            gloss: None,
            centre: (-3.25, 4.61),
            truth: "mirror geometry: (-5.2, 2.66, -3), 3.9 x 3.9",
            paper: "(-5.0552, 2.65204, -3), 3.67095 x 3.81414, L 22.3919",
        },
        Case {
            name: "T2 light0, wall at z=+3",
            scene: "table2-wall-plus3.gltf",
            photo: "table1.png",
            gloss: None,
            centre: (-1.75, 2.39),
            truth: "mirror geometry: (-2.8, 1.34, 3), 2.1 x 2.1",
            paper: "(-2.8414, 1.39481, 3), 2.20807 x 2.20612, L 20.8895",
        },
        Case {
            name: "T3 light0",
            scene: "scene.gltf",
            photo: "table3.png",
            gloss: None,
            centre: (-2.5, 3.5),
            truth: "(-4, 2, 0), 3 x 3, L (20, 20, 0)",
            paper: "as T1, L (21.4182, 21.4182, 21.4182)",
        },
        Case {
            name: "T3 light1",
            scene: "scene.gltf",
            photo: "table3.png",
            gloss: None,
            centre: (6.0, 3.0),
            truth: "(5, 2, 0), 2 x 2, L (10, 10, 0)",
            paper: "(5.0145, 1.99256, 0), 1.99571 x 2.01065, L (7.41385, 7.41385, 0.037866)",
        },
        Case {
            name: "gloss200 (e = 200 given)",
            scene: "scene.gltf",
            photo: "gloss200.png",
            gloss: Some(200.0),
            centre: (-2.5, 3.5),
            truth: "(-4, 2, 0), 3 x 3, L 20",
            paper: "-",
        },
        Case {
            name: "gloss1000 (e = 1000 given)",
            scene: "scene.gltf",
            photo: "gloss1000.png",
            gloss: Some(1000.0),
            centre: (-2.5, 3.5),
            truth: "(-4, 2, 0), 3 x 3, L 20",
            paper: "-",
        },
        Case {
            name: "stacked, lower light",
            scene: "scene.gltf",
            photo: "stacked.png",
            gloss: None,
            centre: (-0.5, 1.7),
            truth: "(-2, 1.2, 0), 3 x 1, L 16",
            paper: "-",
        },
        Case {
            name: "stacked, upper light",
            scene: "scene.gltf",
            photo: "stacked.png",
            gloss: None,
            centre: (-0.5, 3.7),
            truth: "(-2, 3, 0), 3 x 1.4, L 14",
            paper: "-",
        },
        Case {
            name: "stacked e=1000, lower light",
            scene: "scene.gltf",
            photo: "stacked1000.png",
            gloss: Some(1000.0),
            centre: (-0.5, 1.7),
            truth: "(-2, 1.2, 0), 3 x 1, L 16",
            paper: "-",
        },
        Case {
            name: "stacked e=1000, upper light",
            scene: "scene.gltf",
            photo: "stacked1000.png",
            gloss: Some(1000.0),
            centre: (-0.5, 3.7),
            truth: "(-2, 3, 0), 3 x 1.4, L 14",
            paper: "-",
        },
        Case {
            name: "orange-blue, orange lamp",
            scene: "scene.gltf",
            photo: "orange-blue.png",
            gloss: None,
            centre: (-0.5, 1.75),
            truth: "(-2, 1, 0), 3 x 1.5, L (20, 10, 2.5)",
            paper: "-",
        },
        Case {
            name: "orange-blue, blue lamp",
            scene: "scene.gltf",
            photo: "orange-blue.png",
            gloss: None,
            centre: (-0.5, 4.75),
            truth: "(-2, 4, 0), 3 x 1.5, L (3, 7, 20)",
            paper: "-",
        },
    ];
    println!(
        "| case | truth | paper | method | streaklight | unconstrained edges | fit time (s) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (case, method) in cases
        .iter()
        .flat_map(|c| [(c, Method::Paper), (c, Method::default())])
    {
        let result = convert(&options(&dir, case, method));
        let ours = match &result {
            Ok(outcome) => match outcome.report.lights.iter().min_by(|a, b| {
                let d = |l: &&streaklight::report::LightReport| {
                    (l.center[0] - case.centre.0).powi(2) + (l.center[1] - case.centre.1).powi(2)
                };
                d(a).total_cmp(&d(b))
            }) {
                Some(l) => {
                    let c = l.corner_left_bottom;
                    let r = l.radiance;
                    let free: Vec<&str> = [
                        ("left", &l.edges.left),
                        ("right", &l.edges.right),
                        ("bottom", &l.edges.bottom),
                        ("top", &l.edges.top),
                    ]
                    .iter()
                    .filter(|(_, e)| e.status == "unconstrained")
                    .map(|(n, _)| *n)
                    .collect();
                    let seconds: f64 = outcome.report.timings.iter().map(|t| t.seconds).sum();
                    format!(
                        "({:.4}, {:.4}, {:.4}), {:.4} x {:.4}, L ({:.3}, {:.3}, {:.3}) | {} | {:.2}",
                        c[0], c[1], c[2], l.width, l.height, r[0], r[1], r[2],
                        if free.is_empty() { "none".to_string() } else { free.join(", ") },
                        seconds
                    )
                }
                None => "light not found | | ".into(),
            },
            Err(e) => format!("error: {e} | | "),
        };
        println!(
            "| {} | {} | {} | {} | {} |",
            case.name,
            case.truth,
            case.paper,
            method.name(),
            ours
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
