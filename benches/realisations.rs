//! How far one realisation of the waves moves a radiance that only the reflections give, and
//! whether the report's uncertainties cover that. A light whose image the photo clips in
//! every channel (or that is out of frame) takes its radiance from the light its reflections
//! hold, and one photo shows one realisation of the waves, which holds more or less light
//! than the statistical model's expectation over all of them. Each case's truth scene is
//! rendered as the sample photos are (600 x 600, exposure 0.1, 8-bit PNG) over wave fields
//! drawn from seeds 1..=N with the samples' own statistics (the harbour's spectrum; the
//! paper's 24 ripples), and each photo is fitted at the defaults against the case's flat
//! quad, so what scatters is the waves, not the scene. Per seed it prints the brightest
//! channel's radiance error (% of the truth) and that error in reported sigmas, then their
//! root mean square, mean and largest, and how many seeds' fits gave more lights than the
//! truth holds.
//!
//! `cargo bench --bench realisations` runs 16 seeds of the harbour's warm white sign (6 x
//! 1.2 m, 40 m from a camera 2 m above the water, its image clipped in every channel) and of
//! Table 1's lamp (0.5-1 m in front of a camera 0.2 m above the water, its image clipped).
//! Environment: `REALISATION_SEEDS` (count), `REALISATION_CASES` (comma-separated: "sign",
//! "table1"), `REALISATION_SPP` (camera rays per pixel of the renders; the samples' 256 by
//! default).

use std::path::{Path, PathBuf};

use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::FitSettings;
use streaklight::render::{render, RenderOptions};
use streaklight::samples::realisation::write_over_waves;
use streaklight::samples::{self, SampleLight, PHOTO_EXPOSURE, PHOTO_SIZE};

/// One case: the truth scene rendered, the scene fitted against, and the truth lights.
struct Case {
    name: &'static str,
    truth: &'static str,
    fitted_against: &'static str,
    lights: Vec<SampleLight>,
}

fn case(name: &str) -> Case {
    let truth = |file: &str| {
        samples::catalogue()
            .into_iter()
            .find(|s| s.file == file)
            .map(|s| s.lights)
            .unwrap_or_default()
    };
    match name {
        "sign" => Case {
            name: "sign",
            truth: "harbour-sign-truth.gltf",
            fitted_against: "harbour-flat.gltf",
            lights: truth("harbour-sign-truth.gltf"),
        },
        "table1" => Case {
            name: "table1",
            truth: "table1-truth.gltf",
            fitted_against: "scene-flat.gltf",
            lights: truth("table1-truth.gltf"),
        },
        other => panic!("REALISATION_CASES: no case {other} (sign, table1)"),
    }
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

fn main() {
    let seeds: u64 = std::env::var("REALISATION_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(16);
    let spp: u32 = std::env::var("REALISATION_SPP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(samples::PHOTO_SPP);
    let cases: Vec<String> = std::env::var("REALISATION_CASES")
        .unwrap_or_else(|_| "sign,table1".into())
        .split(',')
        .map(|s| s.trim().to_owned())
        .filter(|s| !s.is_empty())
        .collect();
    let dir = std::env::temp_dir().join(format!("streaklight-realisations-{}", std::process::id()));
    samples::write_scenes(&dir).expect("writing the sample scenes");
    println!(
        "wave seeds 1..={seeds}, photos rendered at {spp} spp, fitted at the defaults against \
         the flat quad; radiance error of the brightest channel in % of the truth and in \
         reported sigmas"
    );
    for name in &cases {
        let case = case(name);
        let mut errors: Vec<Vec<f64>> = vec![Vec::new(); case.lights.len()];
        let mut zs: Vec<Vec<f64>> = vec![Vec::new(); case.lights.len()];
        // Seeds whose fit gave more lights than the truth holds.
        let mut extra = 0;
        for seed in 1..=seeds {
            let lights = fit_realisation(&dir, &case, seed, spp);
            if lights.len() > case.lights.len() {
                extra += 1;
            }
            for (k, truth) in case.lights.iter().enumerate() {
                let ch = (0..3)
                    .max_by(|&a, &b| truth.radiance[a].total_cmp(&truth.radiance[b]))
                    .unwrap_or(0);
                let nearest = lights
                    .iter()
                    .min_by(|a, b| distance(a, truth).total_cmp(&distance(b, truth)));
                let Some(l) = nearest else {
                    println!("{} seed {seed}: no light", case.name);
                    continue;
                };
                let off = l.radiance[ch] - truth.radiance[ch];
                let e = 100.0 * off / truth.radiance[ch];
                let z = l.uncertainty.as_ref().map(|u| off / u.radiance[ch]);
                println!(
                    "{} seed {seed}: {} radiance {e:+.2} % ({} sigmas), {} light(s)",
                    case.name,
                    truth.name,
                    z.map_or("-".into(), |z| format!("{z:+.1}")),
                    lights.len()
                );
                errors[k].push(e);
                if let Some(z) = z {
                    zs[k].push(z);
                }
            }
        }
        for (k, truth) in case.lights.iter().enumerate() {
            let e = &errors[k];
            let z = &zs[k];
            println!(
                "| {} | {} | {} | {:.1} | {:+.1} | {:.1} | {:.1} | {:.1} | {}/{} | {extra} |",
                case.name,
                truth.name,
                e.len(),
                rms(e),
                e.iter().sum::<f64>() / e.len().max(1) as f64,
                e.iter().map(|x| x.abs()).fold(0.0, f64::max),
                rms(z),
                z.iter().map(|x| x.abs()).fold(0.0, f64::max),
                z.iter().filter(|x| x.abs() <= 3.0).count(),
                z.len()
            );
        }
    }
    println!(
        "(columns: case | light | seeds | rms error % | mean % | largest % | rms sigmas | \
         largest sigmas | within 3 sigmas | seeds with more lights than the truth)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Renders `case`'s truth over the waves of `seed` as the sample photos are, fits the photo
/// against the case's flat quad at the defaults, and returns the report's lights.
fn fit_realisation(
    dir: &Path,
    case: &Case,
    seed: u64,
    spp: u32,
) -> Vec<streaklight::report::LightReport> {
    let here = dir.join(format!("{}-{seed}", case.name));
    let truth = write_over_waves(case.truth, seed, &here).expect("writing the truth's scene");
    let scene = streaklight::scene_in::load(&truth, &Default::default())
        .expect("loading the truth over the realisation");
    let image = render(
        &scene,
        &RenderOptions {
            width: PHOTO_SIZE,
            height: PHOTO_SIZE,
            samples_per_pixel: spp,
            exposure: PHOTO_EXPOSURE,
            seed: 1,
            ..Default::default()
        },
    )
    .expect("rendering the photo");
    let photo: PathBuf = here.join("photo.png");
    streaklight::photo_out::write(&photo, image.width, image.height, &image.pixels)
        .expect("writing the photo");
    let options = ConvertOptions {
        exposure: PHOTO_EXPOSURE,
        fit: FitSettings::default(),
        ..ConvertOptions::new(dir.join(case.fitted_against), &photo, here.join("lit.gltf"))
    };
    let lights = convert(&options).expect("fit").report.lights;
    let _ = std::fs::remove_dir_all(&here);
    lights
}

fn distance(light: &streaklight::report::LightReport, truth: &SampleLight) -> f64 {
    let c = light.corner_left_bottom;
    let centre = truth.center();
    (c[0] + light.width / 2.0 - centre.x).hypot(c[1] + light.height / 2.0 - centre.y)
}
