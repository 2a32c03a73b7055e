//! The whole converter, end to end (METHOD §5): scene and photo in, lights fitted to the
//! photo's streaks, the lit scene and a report out. The command line's `fit` is a thin wrapper
//! around [`convert`]; pipelines can call it from Rust.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;

use crate::fitting::gloss::GlossSearch;
use crate::fitting::joint::{self, JointOptions, Uncertainty};
use crate::fitting::{self, EdgeStatus, FitOptions, FittedLight, Skipped, StreakObservation};
use crate::optics::{ReflectionModel, Shadowing};
use crate::photo_in::{self, Photo};
use crate::report::{
    EdgeReport, EdgesReport, Files, LightReport, PlaneReport, Report, Settings, SkippedStreak,
    Timing, UncertaintyReport, REPORT_VERSION,
};
use crate::scene_in::{self, AreaLight, LoadOptions, Scene};
use crate::scene_out::{self, LightToWrite, WriteOptions};
use crate::streaks::{self, Segmentation, StreakParams};
use crate::{output_file, photo_out, render, water_mask, Error, Result};

/// The smallest photo the method can work with: superpixels of ~20 pixels need room.
pub const MIN_PHOTO_SIDE: u32 = 64;
/// How far the photo's aspect ratio may differ from the camera's (METHOD §2).
pub const ASPECT_TOLERANCE: f32 = 0.005;

/// How the lights are fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// The paper's per-streak estimate, then all lights refined together against every water
    /// pixel from which they can be seen (render and compare), a light split in two where
    /// the residual shows overlapping streaks, with per-parameter uncertainties (the
    /// default: BENCHMARKS.md has the accuracy of both methods).
    #[default]
    Joint,
    /// The paper's per-streak estimate alone, with streaklight's corrections (METHOD §5).
    Paper,
}

impl Method {
    /// "joint" or "paper".
    pub fn name(self) -> &'static str {
        match self {
            Method::Joint => "joint",
            Method::Paper => "paper",
        }
    }
}

/// Everything `fit` needs.
#[derive(Clone, Debug)]
pub struct ConvertOptions {
    /// The input scene.
    pub scene: PathBuf,
    /// The photo of the water.
    pub photo: PathBuf,
    /// The output scene (`.gltf` or `.glb`).
    pub output: PathBuf,
    /// Where to write the JSON report, if anywhere.
    pub report: Option<PathBuf>,
    /// Where to write pictures of every stage, if anywhere.
    pub debug_dir: Option<PathBuf>,
    /// Camera, water, gloss, IOR and nits-scale choices.
    pub load: LoadOptions,
    /// Divides the photo's linear values.
    pub exposure: f32,
    /// Lobe samples per traced pixel.
    pub samples: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Shadowing term of the reflection model.
    pub shadowing: Shadowing,
    /// Write emissive fallback quads under the lights.
    pub fallback_quads: bool,
    /// Succeed (writing the scene unchanged) when no light is found.
    pub allow_empty: bool,
    /// Settings of the streak extraction.
    pub streak_params: StreakParams,
    /// Paper estimate alone, or refined jointly.
    pub method: Method,
    /// Estimate the water's gloss from the photo together with the lights (`--gloss auto`;
    /// the scene's or `load.gloss` is the search's start). Implies the joint fit.
    pub estimate_gloss: bool,
    /// Independent joint fits, each from its own samples, whose mean is the result (at least
    /// 1; see [`JointOptions::repeats`]): N times slower, about sqrt(N) times less of the
    /// samples' noise, with the fits' spread added to the uncertainties.
    pub repeats: u32,
    /// Lobe samples per pixel of the joint fit (`None`: its default,
    /// [`joint::DEFAULT_JOINT_SAMPLES`], or under `--gloss auto` the final fit's
    /// [`fitting::gloss::SEARCH_SAMPLES`]). More cost proportionally more time and leave less of
    /// the fit's own noise in the result.
    pub joint_samples: Option<u32>,
    /// Fit every pixel of the joint fit's region, not a checkerboard half
    /// ([`JointOptions::checkerboard`] off): about twice the time, less noise.
    pub all_pixels: bool,
    /// Told a line as each stage of the run starts (None: silent). The CLI prints them, so a
    /// long fit (`--gloss auto`, `--repeats`) shows where it is.
    pub progress: Option<fn(&str)>,
}

impl ConvertOptions {
    /// The options `streaklight fit SCENE PHOTO -o OUTPUT` runs with: exposure 1, the default
    /// samples, seed 1, the paper's G = 1, fallback quads, no report or pictures, the joint
    /// method with the scene's gloss. Change fields with struct update syntax.
    pub fn new(
        scene: impl Into<PathBuf>,
        photo: impl Into<PathBuf>,
        output: impl Into<PathBuf>,
    ) -> Self {
        ConvertOptions {
            scene: scene.into(),
            photo: photo.into(),
            output: output.into(),
            report: None,
            debug_dir: None,
            load: LoadOptions::default(),
            exposure: 1.0,
            samples: crate::fitting::DEFAULT_SAMPLES,
            seed: 1,
            shadowing: Shadowing::None,
            fallback_quads: true,
            allow_empty: false,
            streak_params: StreakParams::default(),
            method: Method::default(),
            estimate_gloss: false,
            repeats: 1,
            joint_samples: None,
            all_pixels: false,
            progress: None,
        }
    }
}

/// What a conversion produced.
#[derive(Clone, Debug)]
pub struct ConvertOutcome {
    /// The report (also written to [`ConvertOptions::report`] when set).
    pub report: Report,
    /// The fitted lights, in the scene frame of the loaded scene.
    pub lights: Vec<FittedLight>,
}

/// Each stage's time, and whom to tell as one starts ([`ConvertOptions::progress`]).
struct Stopwatch(Vec<Timing>, Option<fn(&str)>);

impl Stopwatch {
    fn time<T>(&mut self, stage: &str, f: impl FnOnce() -> T) -> T {
        self.say(stage);
        let start = Instant::now();
        let out = f();
        self.0.push(Timing {
            stage: stage.into(),
            seconds: start.elapsed().as_secs_f64(),
        });
        out
    }

    fn say(&self, line: &str) {
        if let Some(progress) = self.1 {
            progress(line);
        }
    }
}

/// Checks the output path before any work, so a long run does not end in a refusal.
fn check_output(options: &ConvertOptions) -> Result<()> {
    let ext = options
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("gltf") | Some("glb")) {
        return Err(Error::output(
            &options.output,
            "the output must end in .gltf or .glb",
        ));
    }
    let inputs = [options.scene.as_path(), options.photo.as_path()];
    output_file::ensure_not_an_input(&options.output, &inputs)?;
    output_file::ensure_folder_exists(&options.output)?;
    output_file::ensure_writable(&options.output)?;
    if let Some(report) = &options.report {
        output_file::ensure_not_an_input(report, &inputs)?;
        output_file::ensure_not_an_input(report, &[options.output.as_path()])?;
        // Checked now, so a missing or read-only report folder cannot leave a scene written
        // without its report.
        output_file::ensure_folder_exists(report)?;
        output_file::ensure_writable(report)?;
    }
    Ok(())
}

/// Checks that the photo can have been taken by the scene's camera.
pub fn check_photo(scene: &Scene, photo: &Photo, path: &Path) -> Result<()> {
    if photo.width < MIN_PHOTO_SIDE || photo.height < MIN_PHOTO_SIDE {
        return Err(Error::photo(
            path,
            format!(
                "the photo is {} x {} pixels; streaklight needs at least {MIN_PHOTO_SIDE} x {MIN_PHOTO_SIDE}",
                photo.width, photo.height
            ),
        ));
    }
    if let Some(camera_aspect) = scene.camera.aspect_ratio {
        let photo_aspect = photo.width as f32 / photo.height as f32;
        if ((photo_aspect - camera_aspect) / camera_aspect).abs() > ASPECT_TOLERANCE {
            return Err(Error::photo(
                path,
                format!(
                    "the photo's aspect ratio {photo_aspect:.4} ({} x {}) differs from the camera \"{}\"'s {camera_aspect:.4}: was it taken with another camera, or cropped?",
                    photo.width, photo.height, scene.camera.name
                ),
            ));
        }
    }
    Ok(())
}

/// Why the photo shows no reflection when every water pixel holds the same value.
fn uniform_water(photo: &Photo, water: &[bool]) -> Option<String> {
    let mut seen = photo.display.iter().zip(water).filter(|(_, &w)| w);
    let (first, _) = seen.next()?;
    if seen.any(|(p, _)| p != first) {
        return None;
    }
    let clipped = photo
        .display
        .iter()
        .zip(&photo.clipped)
        .zip(water)
        .all(|((_, &c), &w)| !w || c);
    let value = first.map(|c| (c * 100.0).round());
    Some(if clipped {
        format!(
            "every water pixel is clipped (at the encoding's maximum, {}/{}/{} %): the photo is overexposed and shows no streak; lower the camera's exposure",
            value[0], value[1], value[2]
        )
    } else {
        format!(
            "every water pixel has the same value ({}/{}/{} % of full scale): the photo is blank and shows no streak; is it the right photo?",
            value[0], value[1], value[2]
        )
    })
}

/// A streak as the fitters take it: its id, pixels and edges, and the photo width they index.
pub fn observation(streak: &streaks::Streak, width: u32) -> StreakObservation {
    StreakObservation {
        id: streak.id,
        pixels: streak.pixels.clone(),
        brightest: streak.brightest.1 * width + streak.brightest.0,
        edges: streak.edges.clone(),
    }
}

/// A fitted light as a renderable area light (scene frame).
pub fn area_light(light: &FittedLight, name: String) -> AreaLight {
    let c = light.rect().center();
    let plane = &light.plane;
    AreaLight {
        name,
        node: plane.node,
        center: plane.point + plane.u * c.x + plane.v * c.y,
        half_width: plane.u * (light.width() * 0.5),
        half_height: plane.v * (light.height() * 0.5),
        normal: plane.normal,
        radiance: light.radiance,
    }
}

fn light_name(index: usize) -> String {
    format!("streaklight_light_{index}")
}

fn edge_report(status: &EdgeStatus) -> EdgeReport {
    match status {
        EdgeStatus::Constrained { pixels } => EdgeReport {
            status: "constrained".into(),
            pixels: *pixels,
            reason: None,
        },
        EdgeStatus::Unconstrained { reason, .. } => EdgeReport {
            status: "unconstrained".into(),
            pixels: 0,
            reason: Some(reason.clone()),
        },
    }
}

fn uncertainty_report(u: &Uncertainty) -> Option<UncertaintyReport> {
    // A light whose radiance cannot be told apart from another's has no finite uncertainty:
    // report none rather than a number a pipeline might trust.
    if !u.radiance.iter().all(|r| r.is_finite()) {
        return None;
    }
    let e = |i: usize| u.edges[i].filter(|s| s.is_finite()).map(f64::from);
    Some(UncertaintyReport {
        left: e(0),
        right: e(1),
        bottom: e(2),
        top: e(3),
        radiance: u.radiance.map(f64::from),
    })
}

fn light_report(
    scene: &Scene,
    light: &FittedLight,
    uncertainty: Option<&Uncertainty>,
    name: String,
) -> LightReport {
    let origin = scene.origin;
    let v3 = |v: glam::Vec3| v.as_dvec3().to_array();
    let radiance = light.radiance.map(f64::from);
    LightReport {
        name,
        streak_ids: light.streak_ids.clone(),
        plane: PlaneReport {
            node: light.plane.node,
            node_name: scene.node_names.get(light.plane.node).cloned().flatten(),
            point: (origin + light.plane.point.as_dvec3()).to_array(),
            normal: v3(light.plane.normal),
            hit_fraction: light.plane.hit_fraction as f64,
        },
        center: light.center_world(origin).to_array(),
        corner_left_bottom: light.corner_left_bottom_world(origin).to_array(),
        u_axis: v3(light.plane.u),
        v_axis: v3(light.plane.v),
        width: light.width() as f64,
        height: light.height() as f64,
        radiance,
        edges: EdgesReport {
            left: edge_report(&light.edges[0]),
            right: edge_report(&light.edges[1]),
            bottom: edge_report(&light.edges[2]),
            top: edge_report(&light.edges[3]),
        },
        uncertainty: uncertainty.and_then(uncertainty_report),
        light_index: None,
        node_index: None,
    }
}

fn light_to_write(scene: &Scene, light: &FittedLight, name: String) -> LightToWrite {
    let streak_id = light.streak_ids.first().copied();
    LightToWrite {
        name,
        center: light.center_world(scene.origin),
        normal: light.plane.normal.as_dvec3().normalize(),
        up: light.plane.v.as_dvec3().normalize(),
        width: light.width() as f64,
        height: light.height() as f64,
        radiance: light.radiance.map(|c| f64::from(c.max(0.0))),
        streak_id,
    }
}

fn skipped_report(s: &Skipped) -> SkippedStreak {
    match s {
        Skipped::NoPlane { streak, message } | Skipped::NoSolution { streak, message } => {
            SkippedStreak {
                streak: *streak,
                reason: message.clone(),
            }
        }
    }
}

/// Joint samples per pixel of the refit of lights that share a streak (with every pixel
/// read): on `stacked1000.png` (8 seeds) their facing edges and radiances come out 1.2-1.3 %
/// rms off instead of 2.6-2.8 % with the checkerboard and 72 samples, in about twice the
/// time (36 s against 19 s per fit; BENCHMARKS.md, twelfth session).
const THOROUGH_SAMPLES: u32 = 128;

/// Whether lights that the joint fit finds sharing a streak are fitted again over every pixel
/// with [`THOROUGH_SAMPLES`] samples: by default yes; not when the user chose the pixels or
/// the samples (their choice stands), and not under `--gloss auto` (whose final fit has its
/// own settings).
fn refit_overlaps(options: &ConvertOptions) -> bool {
    options.joint_samples.is_none() && !options.all_pixels && !options.estimate_gloss
}

/// Whether two of `lights` stand for the same streak (the joint fit split it).
fn shares_a_streak(lights: &[FittedLight]) -> bool {
    let mut seen = std::collections::BTreeSet::new();
    lights
        .iter()
        .flat_map(|l| l.streak_ids.iter())
        .any(|&id| !seen.insert(id))
}

/// One warning per set of lights that share streaks (overlapping reflections, split by the
/// joint fit; a light merged from two streaks and then split makes one warning naming both
/// streaks): the photo tells such lights apart only weakly, so their facing edges and
/// radiances can be off by several percent (the stacked sample, even with the refit over
/// every pixel: the facing edges about 5 % rms over 8 seeds, the upper light's radiance 7 %,
/// up to 14 %; BENCHMARKS.md, twelfth session). Their reported uncertainties are as wide
/// (BENCHMARKS.md, "Uncertainties: the curvature of the cost the fit minimises"); the
/// warning says why. Unless the fit already
/// read every pixel with at least [`THOROUGH_SAMPLES`] samples (`thorough`), it also says how
/// to fit such lights more closely.
fn shared_streak_warnings(lights: &[LightReport], thorough: bool) -> Vec<String> {
    let mut by_streak: std::collections::BTreeMap<usize, Vec<&str>> = Default::default();
    for light in lights {
        for &streak in &light.streak_ids {
            by_streak.entry(streak).or_default().push(&light.name);
        }
    }
    // Two streaks that one merged light spans make one warning, not one per streak.
    let mut by_lights: std::collections::BTreeMap<Vec<&str>, Vec<usize>> = Default::default();
    for (streak, names) in by_streak {
        if names.len() > 1 {
            by_lights.entry(names).or_default().push(streak);
        }
    }
    by_lights
        .into_iter()
        .map(|(names, streaks)| {
            let ids: Vec<String> = streaks.iter().map(|s| s.to_string()).collect();
            let (noun, verb) = if streaks.len() == 1 {
                ("streak", "holds")
            } else {
                ("streaks", "hold")
            };
            format!(
                "{noun} {} {verb} {} lights ({}), whose reflections overlap: the photo tells them \
                 apart only weakly where they meet, so their facing edges and radiances may be off \
                 by several percent (up to about 15 % on the bundled stacked sample); their reported \
                 uncertainties are correspondingly wide{}",
                ids.join(", "),
                names.len(),
                names.join(", "),
                if thorough {
                    String::new()
                } else {
                    format!(
                        "; --all-pixels --joint-samples {THOROUGH_SAMPLES} fits them about twice \
                         as closely, in about twice the time"
                    )
                }
            )
        })
        .collect()
}

/// Runs the whole conversion.
pub fn convert(options: &ConvertOptions) -> Result<ConvertOutcome> {
    check_output(options)?;
    if options.samples == 0 {
        return Err(Error::Usage("--samples must be at least 1".into()));
    }
    let joint_samples = match options.joint_samples {
        Some(0) => return Err(Error::Usage("--joint-samples must be at least 1".into())),
        Some(n) => n,
        None if options.estimate_gloss => fitting::gloss::SEARCH_SAMPLES,
        None => joint::DEFAULT_JOINT_SAMPLES,
    };
    if options.estimate_gloss && options.method == Method::Paper {
        return Err(Error::Usage(
            "--gloss auto fits the gloss with the joint fit: it cannot be combined with --method paper"
                .into(),
        ));
    }
    let mut clock = Stopwatch(Vec::new(), options.progress);
    let scene = clock.time("load scene", || {
        scene_in::load(&options.scene, &options.load)
    })?;
    let photo = clock.time("load photo", || {
        photo_in::load(&options.photo, options.exposure)
    })?;
    check_photo(&scene, &photo, &options.photo)?;
    let water = clock.time("water mask", || {
        water_mask::water_mask(&scene, photo.width, photo.height)
    });
    if !water.iter().any(|&w| w) {
        return Err(Error::scene(
            &options.scene,
            format!(
                "the camera \"{}\" sees no water: check --camera and --water",
                scene.camera.name
            ),
        ));
    }
    let segmentation = clock.time("streaks", || {
        streaks::extract_streaks(&photo, &water, &options.streak_params)
    })?;
    // A blank photo (one value over all the water: black, grey, all clipped) shows no
    // reflection, however the streak extraction reads it.
    let uniform = uniform_water(&photo, &water);
    let observations: Vec<StreakObservation> = segmentation
        .streaks
        .iter()
        .filter(|_| uniform.is_none())
        .map(|s| observation(s, photo.width))
        .collect();
    let fit_options = FitOptions {
        samples: options.samples,
        seed: options.seed,
        model: ReflectionModel {
            gloss: scene.water.gloss,
            ior: scene.water.ior,
            shadowing: options.shadowing,
        },
    };
    let mut warnings: Vec<String> = scene.warnings.clone();
    let mut uncertainties: Vec<Uncertainty> = Vec::new();
    let mut gloss = (scene.water.gloss, scene.water.gloss_source.clone());
    let mut fit = if observations.is_empty() {
        None
    } else if options.estimate_gloss {
        clock.say(&format!(
            "gloss search and fit of {} streak(s) (each step a joint fit)",
            observations.len()
        ));
        let estimate = fitting::gloss::estimate_gloss(
            &scene,
            &photo,
            &water,
            &observations,
            &GlossSearch {
                final_repeats: options.repeats,
                final_samples: joint_samples,
                final_checkerboard: !options.all_pixels,
                progress: options.progress,
                ..GlossSearch::starting_from(fit_options)
            },
        )?;
        gloss = (
            estimate.gloss,
            format!(
                "estimated from the photo (--gloss auto, {} fits from e = {})",
                estimate.evaluations.len(),
                scene.water.gloss
            ),
        );
        uncertainties = estimate.uncertainty;
        Some(fitting::FitOutcome {
            lights: estimate.lights,
            skipped: estimate.skipped,
            warnings: estimate.warnings,
            timings: estimate.timings,
        })
    } else {
        clock.say(&format!(
            "fit of {} streak(s): the paper's estimate",
            observations.len()
        ));
        Some(fitting::fit_paper(
            &scene,
            &photo,
            &water,
            &observations,
            &fit_options,
        )?)
    };
    // What the joint fit read in the end: (samples per pixel, every pixel).
    let mut joint_reading = (joint_samples, options.all_pixels);
    if let (Some(f), Method::Joint, false) = (fit.as_mut(), options.method, options.estimate_gloss)
    {
        if !f.lights.is_empty() {
            clock.say(&format!("joint fit of {} light(s)", f.lights.len()));
            // One joint fit from the paper's lights, reading `(samples, every pixel)`; its
            // timings are added under `label`.
            let run_joint = |(samples, all_pixels): (u32, bool),
                             label: &str,
                             timings: &mut Vec<(String, f64)>|
             -> Result<joint::JointOutcome> {
                let outcome = joint::fit_joint(
                    &scene,
                    &photo,
                    &water,
                    &observations,
                    &f.lights,
                    &JointOptions {
                        repeats: options.repeats,
                        samples,
                        checkerboard: !all_pixels,
                        progress: options.progress,
                        ..JointOptions::new(fit_options.model, options.seed)
                    },
                )?;
                timings.extend(
                    outcome
                        .timings
                        .iter()
                        .map(|(stage, s)| (format!("{label} {stage}"), *s)),
                );
                Ok(outcome)
            };
            let mut refined = run_joint(joint_reading, "joint", &mut f.timings)?;
            if refit_overlaps(options) && shares_a_streak(&refined.lights) {
                clock.say(&format!(
                    "lights share a streak: joint fit again over every pixel with \
                     {THOROUGH_SAMPLES} samples (set --joint-samples or --all-pixels to skip this)"
                ));
                joint_reading = (THOROUGH_SAMPLES, true);
                refined = run_joint(joint_reading, "joint refit of overlaps", &mut f.timings)?;
            }
            f.lights = refined
                .lights
                .iter()
                .zip(&refined.uncertainty)
                .map(|(l, u)| FittedLight {
                    edges: joint::edge_statuses(l, u),
                    ..l.clone()
                })
                .collect();
            uncertainties = refined.uncertainty;
        }
    }
    let (lights, skipped) = match &fit {
        Some(f) => {
            clock
                .0
                .extend(f.timings.iter().map(|(stage, seconds)| Timing {
                    stage: format!("fit: {stage}"),
                    seconds: *seconds,
                }));
            warnings.extend(f.warnings.iter().cloned());
            (
                f.lights.clone(),
                f.skipped.iter().map(skipped_report).collect(),
            )
        }
        None => (Vec::new(), Vec::new()),
    };
    let nothing_found = lights.is_empty();
    let nothing_message = if let Some(why) = &uniform {
        format!("{}: {why}", options.photo.display())
    } else if segmentation.streaks.is_empty() {
        let why = segmentation
            .require_streaks()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_else(|| "no streak found".into());
        format!("{}: {why}", options.photo.display())
    } else {
        format!(
            "{}: {} streak(s) found but no light could be fitted: {}",
            options.scene.display(),
            segmentation.streaks.len(),
            skipped
                .iter()
                .map(|s: &SkippedStreak| format!("streak {}: {}", s.streak, s.reason))
                .collect::<Vec<_>>()
                .join("; ")
        )
    };
    if nothing_found {
        warnings.push(nothing_message.clone());
        if !options.allow_empty {
            // Refused: nothing is written, not even the report. The scene's own warnings
            // (e.g. triangles left out for NaN vertices) may be the reason, so they are told.
            let scene_warnings = if scene.warnings.is_empty() {
                String::new()
            } else {
                format!(
                    " (warnings about {}: {})",
                    options.scene.display(),
                    scene.warnings.join("; ")
                )
            };
            return Err(Error::NothingFound(format!(
                "{nothing_message}{scene_warnings}; nothing was written (pass --allow-empty to write the scene anyway)"
            )));
        }
    }

    let mut light_reports: Vec<LightReport> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| light_report(&scene, l, uncertainties.get(i), light_name(i)))
        .collect();
    let thorough = joint_reading.1 && joint_reading.0 >= THOROUGH_SAMPLES;
    warnings.extend(shared_streak_warnings(&light_reports, thorough));
    {
        let to_write: Vec<LightToWrite> = lights
            .iter()
            .enumerate()
            .map(|(i, l)| light_to_write(&scene, l, light_name(i)))
            .collect();
        let summary = clock.time("write scene", || {
            scene_out::write_lit_scene(
                &options.scene,
                &options.output,
                &to_write,
                &WriteOptions {
                    fallback_quads: options.fallback_quads,
                    nits_scale: options.load.nits_scale,
                },
            )
        })?;
        for (k, r) in light_reports.iter_mut().enumerate() {
            r.light_index = summary.light_indices.get(k).copied();
            r.node_index = summary.node_indices.get(k).copied();
        }
    }
    if let Some(dir) = &options.debug_dir {
        clock.time("debug pictures", || {
            write_debug(dir, &scene, &photo, &water, &segmentation, &lights, options)
        })?;
    }
    let report = Report {
        report_version: REPORT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        files: Files {
            scene: options.scene.display().to_string(),
            photo: options.photo.display().to_string(),
            output: Some(options.output.display().to_string()),
        },
        settings: Settings {
            gloss: gloss.0,
            gloss_source: gloss.1,
            ior: scene.water.ior,
            shadowing: match options.shadowing {
                Shadowing::None => "none".into(),
                Shadowing::Smith => "smith".into(),
            },
            samples: options.samples,
            seed: options.seed,
            repeats: match options.method {
                Method::Joint => options.repeats,
                Method::Paper => 1,
            },
            joint_samples: match (options.method, options.estimate_gloss) {
                (Method::Paper, false) => None,
                _ => Some(joint::effective_samples(joint_reading.0)),
            },
            joint_pixels: match (options.method, options.estimate_gloss) {
                (Method::Paper, false) => None,
                _ if joint_reading.1 => Some("all".into()),
                _ => Some("checkerboard".into()),
            },
            exposure: options.exposure,
            nits_scale: options.load.nits_scale,
            method: options.method.name().into(),
            camera: scene.camera.name.clone(),
            water: scene.water.name.clone(),
        },
        lights: light_reports,
        skipped_streaks: skipped,
        timings: clock.0,
        warnings,
    };
    if let Some(path) = &options.report {
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::output(path, e.to_string()))?;
        output_file::write_atomically(path, text.as_bytes())?;
    }
    Ok(ConvertOutcome { report, lights })
}

/// Writes the `segment` pictures and, side by side, the photo, the water re-rendered with the
/// fitted lights, and their difference.
fn write_debug(
    dir: &Path,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    segmentation: &Segmentation,
    lights: &[FittedLight],
    options: &ConvertOptions,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    streaks::pictures::write_pictures(dir, photo, water, segmentation)?;
    streaks::report::write_report(
        &dir.join("streaks.json"),
        segmentation,
        &options.streak_params,
    )?;
    let area: Vec<AreaLight> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| area_light(l, light_name(i)))
        .collect();
    let rendered = render::render_with_lights(
        scene,
        &area,
        &render::RenderOptions {
            width: photo.width,
            height: photo.height,
            samples_per_pixel: 64,
            exposure: options.exposure,
            seed: options.seed,
            shadowing: options.shadowing,
            progress: false,
        },
    )?;
    let (w, h) = (photo.width as usize, photo.height as usize);
    let mut side_by_side = vec![[0f32; 3]; 3 * w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            // Only the water is modelled; elsewhere the re-render is black by design.
            let photo_value = photo.radiance[i].map(|c| c * options.exposure);
            let model = if water[i] {
                rendered.pixels[i]
            } else {
                [0.0; 3]
            };
            let diff = if water[i] {
                [0, 1, 2].map(|c| (photo_value[c] - model[c]).abs())
            } else {
                [0.0; 3]
            };
            side_by_side[y * 3 * w + x] = photo_value;
            side_by_side[y * 3 * w + w + x] = model;
            side_by_side[y * 3 * w + 2 * w + x] = diff;
        }
    }
    photo_out::write(
        &dir.join("fit-photo-render-difference.png"),
        3 * photo.width,
        photo.height,
        &side_by_side,
    )
}

/// The world-space corner of a light for messages.
pub fn describe(light: &FittedLight, origin: DVec3) -> String {
    let c = light.corner_left_bottom_world(origin);
    format!(
        "corner ({:.4}, {:.4}, {:.4}), {:.4} x {:.4}, radiance ({:.3}, {:.3}, {:.3})",
        c.x,
        c.y,
        c.z,
        light.width(),
        light.height(),
        light.radiance[0],
        light.radiance[1],
        light.radiance[2]
    )
}
