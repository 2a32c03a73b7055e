//! How far the joint fit's own samples move its result, and whether the report's
//! uncertainties cover that: `streaklight fit` (the whole pipeline, `convert`) of committed
//! sample photos with seeds 1..=N, each light's errors from the truth (root mean square and
//! mean over the seeds) and each error in units of its reported sigma (rms and largest).
//! One photo per case, so what scatters is the fit's samples, not the photo's noise.
//!
//! `cargo bench --bench spread` runs 8 seeds of Table 3 and the stacked sample with 1 and 4
//! repeats (the stacked sample's fits include the refit of its two lights over every pixel:
//! 63 s per fit with 1 repeat on 2 cores; with 4 repeats each repeat refits). Environment:
//! `SPREAD_SEEDS` (count), `SPREAD_REPEATS` (comma-separated, e.g. "1,4"), `SPREAD_CASES`
//! (comma-separated photo names, e.g. "table1.png,table3.png,stacked.png,stacked1000.png"),
//! `SPREAD_JOINT_SAMPLES` (`--joint-samples`; unset: the default), `SPREAD_ALL_PIXELS` ("1":
//! `--all-pixels`), `SPREAD_RENDER_SPP` (fit a fresh render of each case's truth scene with
//! this many camera rays per pixel instead of the committed 256-spp photo: a photo with less
//! of its own noise), `SPREAD_RENDER_CACHE` (a directory: such renders are kept there and
//! reused by later runs, which saves minutes per case; empty it after changing the
//! renderer).

use std::path::{Path, PathBuf};

use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, JointSettings, Method};
use streaklight::progress::Reporter;
use streaklight::report::LightReport;
use streaklight::samples::{self, SampleLight};
use streaklight::scene_in::LoadOptions;

/// Per light: errors (left, right, bottom, top in % of the size, radiance in % of the truth's
/// largest channel) and the same in sigmas (`None` where no uncertainty was reported).
type Measure = ([f64; 5], [Option<f64>; 5]);

fn measure(light: &LightReport, truth: &SampleLight) -> Measure {
    let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
    let ch = (0..3)
        .max_by(|&a, &b| truth.radiance[a].total_cmp(&truth.radiance[b]))
        .unwrap_or(0);
    let rad = (light.radiance[ch] - truth.radiance[ch]) / truth.radiance[ch];
    let errors = [edges[0], edges[1], edges[2], edges[3], rad];
    let sigmas = match &light.uncertainty {
        Some(u) => {
            let metres = [
                edges[0] * truth.width,
                edges[1] * truth.width,
                edges[2] * truth.height,
                edges[3] * truth.height,
            ];
            let sd = [u.left, u.right, u.bottom, u.top];
            let mut z = [None; 5];
            for i in 0..4 {
                z[i] = sd[i].filter(|s| *s > 0.0).map(|s| metres[i] / s);
            }
            z[4] = Some((light.radiance[ch] - truth.radiance[ch]) / u.radiance[ch]);
            z
        }
        None => [None; 5],
    };
    (errors.map(|e| 100.0 * e), sigmas)
}

/// The truths of a committed sample photo, and its water's gloss where it is not the
/// default scene's (`scene.gltf`'s material says e = 500; the fit is told the others).
fn truths(photo: &str) -> (Vec<SampleLight>, Option<f32>) {
    match samples::by_photo(photo) {
        Some(spec) if !spec.lights.is_empty() => {
            let gloss = (spec.gloss != samples::DEFAULT_GLOSS).then_some(spec.gloss as f32);
            (spec.lights, gloss)
        }
        _ => panic!("no truth for {photo}: use a sample photo of lights, e.g. table3.png"),
    }
}

fn env_list(name: &str, default: &str) -> Vec<String> {
    std::env::var(name)
        .unwrap_or_else(|_| default.to_owned())
        .split(',')
        .map(|s| s.trim().to_owned())
        .filter(|s| !s.is_empty())
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

fn main() {
    let seeds: u64 = std::env::var("SPREAD_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(8);
    let repeats: Vec<u32> = env_list("SPREAD_REPEATS", "1,4")
        .iter()
        .map(|s| s.parse().expect("SPREAD_REPEATS: counts such as 1,4"))
        .collect();
    let cases = env_list("SPREAD_CASES", "table3.png,stacked.png");
    let render_spp: Option<u32> = std::env::var("SPREAD_RENDER_SPP")
        .ok()
        .map(|s| s.parse().expect("SPREAD_RENDER_SPP: a count such as 4096"));
    let joint_samples: Option<u32> = std::env::var("SPREAD_JOINT_SAMPLES").ok().map(|s| {
        s.parse()
            .expect("SPREAD_JOINT_SAMPLES: a count such as 288")
    });
    let all_pixels = std::env::var("SPREAD_ALL_PIXELS").is_ok_and(|v| v == "1");
    let cache = std::env::var_os("SPREAD_RENDER_CACHE").map(PathBuf::from);
    let dir = std::env::temp_dir().join(format!("streaklight-spread-{}", std::process::id()));
    samples::write_scenes(&dir).expect("writing the sample scenes");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    println!(
        "seeds 1..={seeds}; joint samples {}; {}; photos {}; errors in % of the size (edges) \
         and of the radiance",
        joint_samples.map_or("default".into(), |n| n.to_string()),
        if all_pixels {
            "all pixels"
        } else {
            "checkerboard"
        },
        render_spp.map_or("committed".into(), |n| format!("rendered at {n} spp"))
    );
    println!();
    println!("| photo | repeats | light | rms error L, R, B, T; rad | mean error | largest error | rms sigmas | largest sigma | s per fit |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for photo in &cases {
        let (truth, gloss) = truths(photo);
        let photo_path = match render_spp {
            None => root.join("samples").join(photo),
            Some(spp) => rendered(&dir, photo, spp, cache.as_deref()),
        };
        for &r in &repeats {
            let mut per_light: Vec<Vec<Measure>> = vec![Vec::new(); truth.len()];
            let mut seconds = 0.0;
            for seed in 1..=seeds {
                let t = std::time::Instant::now();
                let lights = fit(
                    &dir,
                    &photo_path,
                    BenchFit {
                        seed,
                        repeats: r,
                        joint_samples,
                        all_pixels,
                        gloss,
                    },
                );
                seconds += t.elapsed().as_secs_f64();
                for (k, t) in truth.iter().enumerate() {
                    // The fitted light nearest the truth's centre.
                    let nearest = lights
                        .iter()
                        .min_by(|a, b| distance(a, t).total_cmp(&distance(b, t)));
                    if let Some(l) = nearest {
                        per_light[k].push(measure(l, t));
                    }
                }
            }
            for (k, m) in per_light.iter().enumerate() {
                let column = |i: usize| -> Vec<f64> { m.iter().map(|x| x.0[i]).collect() };
                let zs = |i: usize| -> Vec<f64> { m.iter().filter_map(|x| x.1[i]).collect() };
                let fmt = |f: &dyn Fn(usize) -> String| {
                    format!("{}, {}, {}, {}; {}", f(0), f(1), f(2), f(3), f(4))
                };
                let rms_err = fmt(&|i| format!("{:.2}", rms(&column(i))));
                let mean_err = fmt(&|i| {
                    let c = column(i);
                    format!("{:+.2}", c.iter().sum::<f64>() / c.len().max(1) as f64)
                });
                let rms_z = fmt(&|i| {
                    let z = zs(i);
                    if z.is_empty() {
                        "-".into()
                    } else {
                        format!("{:.1}", rms(&z))
                    }
                });
                let max_z = (0..5).flat_map(zs).map(f64::abs).fold(0.0, f64::max);
                let max_err = fmt(&|i| {
                    let largest = column(i).iter().map(|e| e.abs()).fold(0.0, f64::max);
                    format!("{largest:.2}")
                });
                println!(
                    "| {photo} | {r} | {} | {rms_err} | {mean_err} | {max_err} | {rms_z} | {max_z:.1} | {:.1} |",
                    truth[k].name,
                    seconds / seeds as f64
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The sample photo `photo` rendered afresh from its truth scene with `spp` camera rays per
/// pixel, written into `dir`, or into `cache` if given (where an earlier run's render is
/// reused).
fn rendered(dir: &Path, photo: &str, spp: u32, cache: Option<&Path>) -> PathBuf {
    let path = cache.unwrap_or(dir).join(format!("rendered-{spp}-{photo}"));
    if cache.is_some() && path.is_file() {
        eprintln!("reusing {}", path.display());
        return path;
    }
    let spec = samples::catalogue()
        .into_iter()
        .find(|s| s.photo.as_deref() == Some(photo))
        .unwrap_or_else(|| panic!("{photo} is not a sample photo"));
    let t = std::time::Instant::now();
    let image =
        samples::render_photo(dir, &spec, spp, Reporter::default()).expect("rendering the photo");
    if let Some(cache) = cache {
        std::fs::create_dir_all(cache).expect("creating SPREAD_RENDER_CACHE");
    }
    streaklight::photo_out::write(&path, image.width, image.height, &image.pixels)
        .expect("writing the photo");
    eprintln!(
        "rendered {photo} at {spp} spp in {:.0} s",
        t.elapsed().as_secs_f64()
    );
    path
}

fn distance(light: &LightReport, truth: &SampleLight) -> f64 {
    let c = light.corner_left_bottom;
    let centre = truth.center();
    (c[0] + light.width / 2.0 - centre.x).hypot(c[1] + light.height / 2.0 - centre.y)
}

/// The settings of one bench fit.
struct BenchFit {
    seed: u64,
    repeats: u32,
    joint_samples: Option<u32>,
    all_pixels: bool,
    gloss: Option<f32>,
}

/// `streaklight fit` of `photo` with `settings`: the report's lights.
fn fit(dir: &Path, photo: &Path, settings: BenchFit) -> Vec<LightReport> {
    let BenchFit {
        seed,
        repeats,
        joint_samples,
        all_pixels,
        gloss,
    } = settings;
    let options = ConvertOptions {
        load: LoadOptions {
            gloss,
            ..Default::default()
        },
        exposure: samples::PHOTO_EXPOSURE,
        fit: FitSettings {
            seed,
            method: Method::Joint(JointSettings {
                repeats,
                ..JointSettings::default().reading_chosen(joint_samples, all_pixels)
            }),
            ..FitSettings::default()
        },
        ..ConvertOptions::new(
            dir.join("scene.gltf"),
            photo,
            dir.join(format!("spread-{seed}-{repeats}.gltf")),
        )
    };
    convert(&options).expect("fit").report.lights
}
