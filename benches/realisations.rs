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
//! truth holds. At the harbour it also holds the fit's slope variances against the ones of
//! that realisation's mesh under the streaks
//! ([`streaklight::samples::streak_slopes::lobe_under_streaks`]): per axis the error in %
//! and in reported sigmas, then their root mean square, mean and largest, and how many lie
//! within 15 %.
//!
//! `cargo bench --bench realisations` runs 16 seeds of the harbour's warm white sign (6 x
//! 1.2 m, 40 m from a camera 2 m above the water, its image clipped in every channel) and of
//! Table 1's lamp (0.5-1 m in front of a camera 0.2 m above the water, its image clipped).
//! `REALISATION_CASES=pair` runs the harbour's pair in frame (an orange and a blue lamp whose
//! images leave channels unclipped), for its slope variances.
//! Environment: `REALISATION_SEEDS` (count), `REALISATION_CASES` (comma-separated: "sign",
//! "pair", "table1"), `REALISATION_SPP` (camera rays per pixel of the renders; the samples' 256 by
//! default).

use std::path::{Path, PathBuf};

use streaklight::convert::{convert, ConvertOptions};
use streaklight::fitting::slopes::MICROFACET_GLOSS;
use streaklight::pipeline::FitSettings;
use streaklight::render::{render, RenderOptions};
use streaklight::samples::harbour::HARBOUR_GLOSS;
use streaklight::samples::realisation::write_over_waves;
use streaklight::samples::streak_slopes::lobe_under_streaks;
use streaklight::samples::{self, SampleLight, PHOTO_EXPOSURE, PHOTO_SIZE};

/// One case: the truth scene rendered, the scene fitted against, the truth lights, and
/// whether it is the harbour's (whose slope variances are held against the mesh's).
struct Case {
    name: &'static str,
    truth: &'static str,
    fitted_against: &'static str,
    lights: Vec<SampleLight>,
    harbour: bool,
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
            harbour: true,
        },
        "pair" => Case {
            name: "pair",
            truth: "harbour-pair-truth.gltf",
            fitted_against: "harbour-flat.gltf",
            lights: truth("harbour-pair-truth.gltf"),
            harbour: true,
        },
        "table1" => Case {
            name: "table1",
            truth: "table1-truth.gltf",
            fitted_against: "scene-flat.gltf",
            lights: truth("table1-truth.gltf"),
            harbour: false,
        },
        other => panic!("REALISATION_CASES: no case {other} (sign, pair, table1)"),
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
        // Per axis (along, across the view), each seed's slope variance error: ln(fitted /
        // mesh's) and that in reported sigmas.
        let mut slope_errors: [Vec<(f64, Option<f64>)>; 2] = [Vec::new(), Vec::new()];
        for seed in 1..=seeds {
            let Fitted { lights, slopes } = fit_realisation(&dir, &case, seed, spp);
            if let Some(s) = slopes {
                let mut line = format!("{} seed {seed}: slope variances", case.name);
                for (axis, name) in ["along", "across"].into_iter().enumerate() {
                    let ln = (s.fitted[axis] / s.mesh[axis]).ln();
                    let z = s.sigma_ln[axis].map(|sigma| ln / sigma);
                    line += &format!(
                        " {name} {:.2e} against the mesh's {:.2e} ({:+.1} %, {} sigmas)",
                        s.fitted[axis],
                        s.mesh[axis],
                        100.0 * ln.exp_m1(),
                        z.map_or("-".into(), |z| format!("{z:+.1}"))
                    );
                    slope_errors[axis].push((ln, z));
                }
                println!("{line}");
            }
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
        for (axis, name) in ["along", "across"].into_iter().enumerate() {
            let errors = &slope_errors[axis];
            if errors.is_empty() {
                continue;
            }
            let e: Vec<f64> = errors.iter().map(|x| 100.0 * x.0.exp_m1()).collect();
            let z: Vec<f64> = errors.iter().filter_map(|x| x.1).collect();
            println!(
                "| {} | slope variance {name} | {} | {:.1} | {:+.1} | {:.1} | {}/{} | {:.1} | {:.1} |",
                case.name,
                e.len(),
                rms(&e),
                e.iter().sum::<f64>() / e.len() as f64,
                e.iter().map(|x| x.abs()).fold(0.0, f64::max),
                e.iter().filter(|x| x.abs() < 15.0).count(),
                e.len(),
                rms(&z),
                z.iter().map(|x| x.abs()).fold(0.0, f64::max),
            );
        }
    }
    println!(
        "(columns: case | light | seeds | rms error % | mean % | largest % | rms sigmas | \
         largest sigmas | within 3 sigmas | seeds with more lights than the truth; for a slope \
         variance: case | axis | seeds | rms error % | mean % | largest % | within 15 % | rms \
         sigmas | largest sigmas)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A realisation's fit: the report's lights, and at the harbour its slope variances.
struct Fitted {
    lights: Vec<streaklight::report::LightReport>,
    slopes: Option<Slopes>,
}

/// The fit's slope variances (along, across the view) with the sigmas of their logarithms,
/// and the realisation's mesh's under the streaks.
struct Slopes {
    fitted: [f64; 2],
    sigma_ln: [Option<f64>; 2],
    mesh: [f64; 2],
}

/// Renders `case`'s truth over the waves of `seed` as the sample photos are, fits the photo
/// against the case's flat quad at the defaults, and returns the report's lights and, at the
/// harbour, its slope variances against the realisation's mesh's.
fn fit_realisation(dir: &Path, case: &Case, seed: u64, spp: u32) -> Fitted {
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
    let report = convert(&options).expect("fit").report;
    let slopes = case
        .harbour
        .then_some(report.water_model.slopes.as_ref())
        .flatten()
        .map(|s| Slopes {
            fitted: s.variance.map(f64::from),
            sigma_ln: s.sigma_ln.map(|x| x.map(f64::from)),
            mesh: lobe_under_streaks(
                &scene,
                PHOTO_SIZE,
                PHOTO_SIZE,
                HARBOUR_GLOSS,
                MICROFACET_GLOSS as f64,
            )
            .expect("the mesh's slopes under the streaks"),
        });
    let _ = std::fs::remove_dir_all(&here);
    Fitted {
        lights: report.lights,
        slopes,
    }
}

fn distance(light: &streaklight::report::LightReport, truth: &SampleLight) -> f64 {
    let c = light.corner_left_bottom;
    let centre = truth.center();
    (c[0] + light.width / 2.0 - centre.x).hypot(c[1] + light.height / 2.0 - centre.y)
}
