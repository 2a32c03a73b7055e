//! SLIC benchmark: streaklight's SLIC against scikit-image's on the same images in the same run.
//!
//!     cargo bench --bench slic
//!
//! Images: synthetic shapes with noise (`streaklight::samples::shapes`) at 600 x 600, 1920 x 1080 and
//! 4000 x 3000, K = N / 400, compactness 10, 10 iterations. Ours is timed with every core and
//! with one; scikit-image (one core) through tests/python/slic_reference.py. Medians of a few
//! runs after a warm-up. Set SLIC_BENCH_NO_PYTHON=1 to skip scikit-image.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use streaklight::samples::shapes;
use streaklight::streaks::superpixels::{slic, SlicParams};

fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1000.0
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/slic_reference.py");
    let use_python = std::env::var_os("SLIC_BENCH_NO_PYTHON").is_none();
    let dir = std::env::temp_dir().join(format!("streaklight-slic-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    println!(
        "| size | K | labels | ours, {} threads (ms) | ours, 1 thread (ms) | scikit-image, 1 core (ms) |",
        rayon::current_num_threads()
    );
    println!("|---|---|---|---|---|---|");
    for (w, h, runs) in [(600u32, 600u32, 21), (1920, 1080, 7), (4000, 3000, 3)] {
        let img = shapes::shapes(w, h, 40, 0.02, 5);
        let k = (w * h / 400) as usize;
        let params = SlicParams {
            superpixels: Some(k),
            ..SlicParams::default()
        };
        let mut labels = 0;
        let ours = median_ms(runs, || {
            labels = slic(w, h, &img.srgb, &params).expect("slic").count;
        });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("thread pool");
        let ours_one = pool.install(|| {
            median_ms(runs.min(5), || {
                slic(w, h, &img.srgb, &params).expect("slic");
            })
        });
        let theirs = if use_python {
            let path = dir.join(format!("{w}x{h}.png"));
            img.rgb8().save(&path).expect("write image");
            let out = Command::new("python3")
                .arg(&script)
                .args(["time", path.to_str().expect("utf-8 path")])
                .arg(k.to_string())
                .arg("10")
                .arg(runs.min(3).to_string())
                .env("OMP_NUM_THREADS", "1")
                .output()
                .expect("python3 with scikit-image (pip install scikit-image numpy)");
            assert!(
                out.status.success(),
                "slic_reference.py failed: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            String::from_utf8_lossy(&out.stdout).trim().to_string()
        } else {
            "-".to_string()
        };
        println!("| {w} x {h} | {k} | {labels} | {ours:.1} | {ours_one:.1} | {theirs} |");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
