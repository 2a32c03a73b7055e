//! Benchmark: render the Table 1 sample at 600 x 600, 64 spp (the target:
//! at least 4 M reflected rays per second on 2 cores). Run with `cargo bench --bench render`.

use std::time::Instant;

use streaklight::render::{render, RenderOptions};
use streaklight::samples;
use streaklight::scene_in::load;

fn main() {
    let dir = std::env::temp_dir().join(format!("streaklight-bench-{}", std::process::id()));
    let t = Instant::now();
    samples::write_scenes(&dir).expect("writing the sample scenes");
    let generate = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let scene = load(&dir.join("table1-truth.gltf"), &Default::default()).expect("loading");
    let load_s = t.elapsed().as_secs_f64();
    let options = RenderOptions {
        width: 600,
        height: 600,
        samples_per_pixel: 64,
        exposure: samples::PHOTO_EXPOSURE,
        seed: 1,
        ..Default::default()
    };
    // One warm-up run, then the best of three.
    let _ = render(
        &scene,
        &RenderOptions {
            samples_per_pixel: 4,
            ..options.clone()
        },
    );
    let mut best: Option<streaklight::render::Rendered> = None;
    for _ in 0..3 {
        let r = render(&scene, &options).expect("rendering");
        if best.as_ref().is_none_or(|b| r.seconds < b.seconds) {
            best = Some(r);
        }
    }
    let r = best.expect("three runs");
    println!("threads: {}", rayon::current_num_threads());
    println!(
        "scene generation: {generate:.3} s; load ({} triangles; the tiles' BVHs are built by the first rays): {load_s:.3} s",
        scene.triangles.len()
    );
    println!(
        "render 600x600 @ 64 spp: {:.3} s; camera rays {:.2} M/s; reflected rays {} ({:.2} M/s)",
        r.seconds,
        r.camera_rays as f64 / r.seconds / 1e6,
        r.reflected_rays,
        r.reflected_rays as f64 / r.seconds / 1e6
    );
    let _ = std::fs::remove_dir_all(&dir);
}
