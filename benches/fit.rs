//! Benchmark: fit the Table 3 sample (600 x 600, two lights) and print the time of every
//! stage. Run with `cargo bench --bench fit` (needs the committed `samples/table3.png`).

use std::time::Instant;

use streaklight::fitting::{fit_paper, threshold_streaks, FitOptions};
use streaklight::samples;
use streaklight::scene_in::load;
use streaklight::water_mask::water_mask;

fn main() {
    let dir = std::env::temp_dir().join(format!("streaklight-bench-fit-{}", std::process::id()));
    samples::write_scenes(&dir).expect("writing the sample scenes");
    let t = Instant::now();
    let scene = load(&dir.join("scene.gltf"), &Default::default()).expect("loading");
    let load_s = t.elapsed().as_secs_f64();
    let photo_path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/table3.png");
    let photo = streaklight::photo_in::load(&photo_path, samples::PHOTO_EXPOSURE).expect("photo");
    let t = Instant::now();
    let water = water_mask(&scene, photo.width, photo.height);
    let mask_s = t.elapsed().as_secs_f64();
    let streaks = threshold_streaks(&photo, &water, 0.1, 200);
    let options = FitOptions::for_scene(&scene);
    println!("threads: {}", rayon::current_num_threads());
    println!(
        "load + BVH: {load_s:.3} s; water mask: {mask_s:.3} s; {} streaks",
        streaks.len()
    );
    let mut best = f64::INFINITY;
    for run in 0..3 {
        let t = Instant::now();
        let out = fit_paper(&scene, &photo, &water, &streaks, &options).expect("fit");
        let total = t.elapsed().as_secs_f64();
        best = best.min(total);
        let stages: Vec<String> = out
            .timings
            .iter()
            .map(|(name, s)| format!("{name} {s:.3} s"))
            .collect();
        println!(
            "run {run}: fit {total:.3} s ({}); {} lights",
            stages.join(", "),
            out.lights.len()
        );
    }
    println!("best fit: {best:.3} s");
    let _ = std::fs::remove_dir_all(&dir);
}
