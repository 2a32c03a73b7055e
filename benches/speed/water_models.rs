//! The statistical water model's fits beside the exact model's fit of the same photo
//! (`cargo bench --bench speed -- --water-models`): the harbour photos with their lamps in
//! frame, fitted at the defaults (`--water-model auto`) against the scene of the photo's own
//! waves, another realisation of them and the flat quad a game scene holds, at 600 x 600 and,
//! for the pair, at 1920 x 1080; time and peak memory of each, the model the fit chose, its
//! time over the exact fit's, and its stages.

use std::path::Path;

use super::{aspect_copy, fit, load_text, render_photo, stage_text, FitRun, ROOT};

/// The fitting scenes, the photo's own waves first (the exact fit every ratio is over).
const SCENES: [&str; 3] = ["harbour", "harbour-other-waves", "harbour-flat"];

/// The harbour fits and their ratios to the exact fit of the same photo, best of `runs` each.
pub fn water_models(dir: &Path, runs: usize) {
    let root = Path::new(ROOT);
    println!(
        "\nthe harbour photos fitted at the defaults (--water-model auto), child processes, \
         best of {runs}:\n"
    );
    println!("| photo | scene | model | lights | wall s | peak MiB | load avg | / exact fit |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut stages = Vec::new();
    let mut fits = |photo_name: &str, photo: &Path, size: (u32, u32)| {
        let mut exact = None;
        for name in SCENES {
            let scene = aspect_copy(dir, name, size);
            let f = fit(&scene, photo, &[], runs, dir);
            let wall = f.measured.wall;
            let over_exact = *exact.get_or_insert(wall);
            row(photo_name, name, &f, wall / over_exact);
            stages.push((format!("{photo_name}, {name}.gltf"), stage_text(&f.stages)));
        }
    };
    for layout in ["pair", "three", "sign"] {
        let name = format!("harbour-{layout}.png");
        fits(&name, &root.join("samples").join(&name), (600, 600));
    }
    let size = (1920, 1080);
    let truth = aspect_copy(dir, "harbour-pair-truth", size);
    let photo = dir.join("harbour-pair-1920x1080.png");
    render_photo(&truth, &photo, size, dir);
    fits("the pair at 1920 x 1080", &photo, size);
    println!("\nstages of each best run (the report's timings, seconds):\n");
    for (name, s) in stages {
        println!("- {name}: {s}");
    }
}

fn row(photo: &str, scene: &str, f: &FitRun, over_exact: f64) {
    println!(
        "| {photo} | {scene}.gltf | {} | {} | {:.2} | {:.0} | {} | **{over_exact:.2}** |",
        f.model,
        f.lights,
        f.measured.wall,
        f.measured.peak_mib,
        load_text(&f.measured),
    );
}
