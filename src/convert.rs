//! Files in, files out: the converter turns paths into a scene and a photo, runs the fit in
//! memory ([`crate::pipeline::fit`]), and writes the lit scene, the report and the debug
//! pictures. The command line's `fit` is a thin wrapper around [`convert`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;

use crate::fitting::FittedLight;
use crate::pipeline::{self, light_name, FitSettings, Input};
use crate::progress::Reporter;
use crate::report::{self, Files, Report};
use crate::scene_in::{self, LoadOptions, Scene};
use crate::scene_out::{self, InputFiles, LightToWrite, WriteOptions};
use crate::settings::{reword, Setting};
use crate::{debug_pictures, output_file, Error, Result};
use crate::{photo_exif, photo_in};

pub use crate::pipeline::check_photo;

/// Everything `fit` needs.
#[derive(Clone, Debug)]
pub struct ConvertOptions<'a> {
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
    /// Take the exposure from the photo's EXIF instead of [`ConvertOptions::exposure`]
    /// ([`crate::photo_exif`]); a photo without the EXIF it needs is refused.
    pub exposure_from_exif: bool,
    /// How to fit.
    pub fit: FitSettings,
    /// Write emissive fallback quads under the lights.
    pub fallback_quads: bool,
    /// Metres each light's node sits in front of its wall ([`WriteOptions::light_offset`]).
    pub light_offset: f64,
    /// Where a `.gltf` output finds the input's files ([`WriteOptions::input_files`]).
    pub input_files: InputFiles,
    /// Succeed (writing the scene unchanged) when no light is found.
    pub allow_empty: bool,
    /// Told as each stage of the run starts (silent by default).
    pub progress: Reporter<'a>,
    /// How the report's texts name a setting (by default the library's names; the command
    /// line spells its flags).
    pub wording: fn(Setting) -> String,
}

impl ConvertOptions<'_> {
    /// The options `streaklight fit SCENE PHOTO -o OUTPUT` runs with: exposure 1, the default
    /// [`FitSettings`], fallback quads, no report or pictures, silent. Change fields with
    /// struct update syntax.
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
            exposure_from_exif: false,
            fit: FitSettings::default(),
            fallback_quads: true,
            light_offset: scene_out::DEFAULT_LIGHT_OFFSET,
            input_files: InputFiles::Copy,
            allow_empty: false,
            progress: Reporter::default(),
            wording: |s| s.to_string(),
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
    /// Every file written: the scene (and its `.bin`), the report, the debug pictures.
    pub files_written: Vec<PathBuf>,
}

/// Runs a stage, timing it and telling the reporter as it starts.
fn timed<T>(
    timings: &mut Vec<(String, f64)>,
    progress: Reporter<'_>,
    stage: &str,
    f: impl FnOnce() -> T,
) -> T {
    progress.stage(stage);
    let start = Instant::now();
    let out = f();
    timings.push((stage.into(), start.elapsed().as_secs_f64()));
    out
}

/// Checks the output paths before any work, so a long run does not end in a refusal: every
/// output's folder can take it, and no file the run writes (the scene, the files beside it,
/// the report, the debug pictures) is a file it reads (the scene, its buffers and images, the
/// photo) or another of its outputs, however spelled. Returns the files the run writes.
pub fn check_output(options: &ConvertOptions) -> Result<Vec<PathBuf>> {
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
    if !(options.light_offset.is_finite() && options.light_offset >= 0.0) {
        return Err(Error::Usage(format!(
            "the light offset must be a number of metres >= 0, not {}",
            options.light_offset
        )));
    }
    let direct = [options.scene.as_path(), options.photo.as_path()];
    output_file::ensure_not_an_input(&options.output, &direct)?;
    output_file::ensure_writable(&options.output)?;
    // A scene that cannot be read is refused by the load, with a report saying why.
    let plan = scene_out::plan(&options.scene, &options.output, options.input_files)
        .unwrap_or_else(|_| scene_out::Plan {
            reads: vec![options.scene.clone()],
            writes: vec![options.output.clone()],
            own_lights: Vec::new(),
        });
    if let Some(first) = plan.own_lights.first() {
        return Err(Error::scene(
            &options.scene,
            format!(
                "it already holds {} light(s) that streaklight fitted (\"{first}\" ...; nodes \
                 marked in extras.streaklight): a new fit would add a second set beside them. \
                 Fit the scene they were fitted into, or remove those nodes first",
                plan.own_lights.len()
            ),
        ));
    }
    let (mut reads, mut writes) = (plan.reads, plan.writes);
    reads.push(options.photo.clone());
    if let Some(report) = &options.report {
        // Checked now, so a missing or read-only report folder cannot leave a scene written
        // without its report.
        output_file::ensure_writable(report)?;
        writes.push(report.clone());
    }
    if let Some(dir) = &options.debug_dir {
        output_file::ensure_folder_writable(dir)?;
        let all: Vec<&Path> = reads.iter().chain(&writes).map(PathBuf::as_path).collect();
        if let Some(same) = all
            .iter()
            .find(|p| output_file::identity(p) == output_file::identity(dir))
        {
            return Err(Error::output(
                dir,
                format!(
                    "the debug pictures' folder is the file {}; choose another folder",
                    same.display()
                ),
            ));
        }
        writes.extend(debug_pictures::file_names().iter().map(|n| dir.join(n)));
    }
    let reads: Vec<&Path> = reads.iter().map(PathBuf::as_path).collect();
    for w in &writes {
        output_file::ensure_not_an_input(w, &reads)?;
    }
    output_file::ensure_distinct(&writes.iter().map(PathBuf::as_path).collect::<Vec<_>>())?;
    Ok(writes)
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

/// Runs the whole conversion. Once the output paths are checked, a refusal with
/// [`ConvertOptions::report`] set writes a report that says why ([`refusing`]).
pub fn convert(options: &ConvertOptions) -> Result<ConvertOutcome> {
    check_output(options)?;
    refusing(options, || {
        options.fit.validate()?;
        // Started before the scene's load, which leaves a core free.
        let ahead = copies_ahead(options);
        let mut before = Vec::new();
        let scene = timed(&mut before, options.progress, "load scene", || {
            scene_in::load(&options.scene, &options.load)
        })?;
        convert_loaded_with(&scene, before, options, ahead)
    })
}

/// Runs `run` in an [`output_file::Run`], so its outputs are written all together or not at
/// all; when it fails and [`ConvertOptions::report`] is set, writes there (alone) a report of
/// the refusal (the error's text and the files, [`report::Refusal`]) and returns the error.
pub fn refusing<T>(options: &ConvertOptions, run: impl FnOnce() -> Result<T>) -> Result<T> {
    let outputs = output_file::Run::begin();
    let result = run().and_then(|value| outputs.commit().map(|_| value));
    if let Err(e) = &result {
        outputs.discard();
        if let Some(path) = &options.report {
            let refusal = report::Refusal::new(
                files(options, None),
                reword(&e.to_string(), options.wording),
            );
            refusal.write(path)?;
            outputs.commit()?;
        }
    }
    result
}

fn files(options: &ConvertOptions, output: Option<&Path>) -> Files {
    Files {
        scene: options.scene.display().to_string(),
        photo: options.photo.display().to_string(),
        output: output.map(|o| o.display().to_string()),
    }
}

/// The conversion of [`ConvertOptions::photo`] in `scene`, already loaded from
/// [`ConvertOptions::scene`] (`before`: the seconds that took, for the report's timings). The
/// output paths must have been checked ([`check_output`]).
pub fn convert_loaded(
    scene: &Scene,
    before: Vec<(String, f64)>,
    options: &ConvertOptions,
) -> Result<ConvertOutcome> {
    convert_loaded_with(scene, before, options, copies_ahead(options))
}

/// The output's copies of the scene's files, to be written while the fit runs
/// ([`scene_out::CopiesAhead`]).
pub fn copies_ahead(options: &ConvertOptions) -> scene_out::CopiesAhead {
    scene_out::CopiesAhead::start(&options.scene, &options.output, options.input_files)
}

/// [`convert_loaded`], the output's copies started already (`ahead`, [`copies_ahead`]).
pub fn convert_loaded_with(
    scene: &Scene,
    mut before: Vec<(String, f64)>,
    options: &ConvertOptions,
    ahead: scene_out::CopiesAhead,
) -> Result<ConvertOutcome> {
    let progress = options.progress;
    let (resolved, exposure_source) = exposure_of(options)?;
    let options = &resolved;
    let photo = timed(&mut before, progress, "load photo", || {
        photo_in::load(&options.photo, options.exposure)
    })?;
    check_photo(scene, &photo, &options.photo)?;
    let mut lit = pipeline::fit(scene, &photo, &options.fit, progress)?;
    lit.warnings.extend(photo.warnings.iter().cloned());
    let word = |text: &str| reword(text, options.wording);
    if let Some((about, why)) = &lit.nothing_found {
        let message = format!(
            "{}: {why}",
            match about {
                Input::Photo => options.photo.display(),
                Input::Scene => options.scene.display(),
            }
        );
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
                "{message}{scene_warnings}; nothing was written ({} writes the scene anyway)",
                Setting::AllowEmpty
            )));
        }
        lit.warnings.push(message);
    }
    lit.warnings = lit.warnings.iter().map(|w| word(w)).collect();
    lit.gloss_source = word(&lit.gloss_source);

    let mut after = Vec::new();
    let to_write: Vec<LightToWrite> = lit
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| light_to_write(scene, l, light_name(i)))
        .collect();
    let summary = timed(&mut after, progress, "write scene", || {
        scene_out::write_lit_scene_with(
            &options.scene,
            &options.output,
            &to_write,
            &WriteOptions {
                fallback_quads: options.fallback_quads,
                nits_scale: options.load.nits_scale,
                light_offset: options.light_offset,
                input_files: options.input_files,
            },
            Some(ahead),
        )
    })?;
    lit.warnings
        .extend(summary.resources.warnings.iter().cloned());
    let mut files_written = summary.resources.files_written.clone();
    let mut report = report::build(
        scene,
        &lit,
        report::Run {
            files: files(options, Some(&options.output)),
            settings: &options.fit,
            exposure: options.exposure,
            exposure_source,
            nits_scale: options.load.nits_scale,
            timings_before: before,
            timings_after: after,
        },
    );
    for (k, r) in report.lights.iter_mut().enumerate() {
        r.light_index = summary.light_indices.get(k).copied();
        r.node_index = summary.node_indices.get(k).copied();
        r.node_translation = summary.node_translations.get(k).copied();
    }
    report.settings.light_offset = Some(options.light_offset);
    if let Some(dir) = &options.debug_dir {
        // After the report is built: the pictures' index shows its numbers.
        progress.stage("debug pictures");
        let start = Instant::now();
        let pictures = debug_pictures::write(dir, scene, &photo, &lit, &report, options)?;
        report.timings.push(report::Timing {
            stage: "debug pictures".into(),
            seconds: start.elapsed().as_secs_f64(),
        });
        files_written.extend(pictures);
    }
    if let Some(path) = &options.report {
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::output(path, e.to_string()))?;
        output_file::write_atomically(path, text.as_bytes())?;
        files_written.push(path.clone());
    }
    Ok(ConvertOutcome {
        report,
        lights: lit.lights,
        files_written,
    })
}

/// `options` with the exposure the photo is read with, and where that came from: the
/// option's value, or the photo's EXIF ([`ConvertOptions::exposure_from_exif`]).
fn exposure_of<'a>(options: &ConvertOptions<'a>) -> Result<(ConvertOptions<'a>, String)> {
    if !options.exposure_from_exif {
        return Ok((options.clone(), "given".into()));
    }
    let (exposure, source) = photo_exif::exposure_of(&options.photo)?;
    Ok((
        ConvertOptions {
            exposure,
            exposure_from_exif: false,
            ..options.clone()
        },
        source,
    ))
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
