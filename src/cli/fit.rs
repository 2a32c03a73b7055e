//! `streaklight fit SCENE PHOTO -o OUT` (or `fit SCENE PHOTO... --out-dir DIR`): the main
//! job.

use std::path::PathBuf;

use streaklight::batch::convert_all;
use streaklight::convert::ConvertOptions;
use streaklight::pipeline::{FitSettings, JointSettings, Method, WaterChoice};

use super::exit::{exit_codes, Exit};
use super::fit_batch::{jobs, Outputs};
use super::json::Summary;
use super::output::Output;
use super::output_args::OutputArgs;
use super::scene_args::SceneArgs;
use super::streak_args::StreakArgs;
use super::values::ExposureArg;

/// `fit --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Examples:\n  \
     streaklight fit samples/scene.gltf samples/table3.png --exposure 0.1 -o lit.gltf --report report.json\n  \
     streaklight fit scene.glb photo.jpg --exposure auto --nits-scale 683 --gloss auto -o lit.glb --debug-dir debug\n  \
     streaklight fit scene.gltf night1.png night2.png night3.png --exposure 0.1 --out-dir lit --json\n\n\
     Units: lights come out in metres (the scene's units) and radiance in the photo's linear \
     units divided by the exposure (with --exposure auto: W/(sr m^2)); the scene's light \
     intensity is that radiance times --nits-scale. Typical values: --exposure 0.01-100 (the \
     samples: 0.1); --gloss 100-2000 (rough to calm water; the samples: 500); --ior 1.33 \
     (water).\n\n\
     Pipelines: --json prints one summary object on stdout (schema/summary.schema.json); \
     --report writes the full report (schema/report.schema.json), or, for a refused run, \
     a report saying why.\n\n",
    exit_codes!()
);

/// Arguments of `streaklight fit`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb): a camera, the water, and the geometry lights hang on.
    pub scene: PathBuf,
    /// The night photo(s) of the water, taken from the scene's camera (PNG, JPEG, TIFF, EXR,
    /// HDR). Several photos need --out-dir; the scene is loaded once for all of them.
    #[arg(required = true, value_name = "PHOTO")]
    pub photos: Vec<PathBuf>,
    /// The lit scene to write: .gltf or .glb (never over an input). One photo only.
    #[arg(
        short,
        long,
        conflicts_with = "out_dir",
        required_unless_present = "out_dir"
    )]
    pub output: Option<PathBuf>,
    /// Write each photo's lit scene and report into this folder, as NAME.gltf and
    /// NAME.report.json (NAME: the photo's file name without its extension, with its position
    /// added when two photos share a name).
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// With --out-dir: write .glb files instead of .gltf.
    #[arg(long, requires = "out_dir")]
    pub glb: bool,
    /// Also write a JSON report of the lights, settings and timings here (with -o); a refused
    /// run writes a report saying why.
    #[arg(long, conflicts_with = "out_dir")]
    pub report: Option<PathBuf>,
    /// Write pictures of every stage into this folder, with an index.html showing them beside
    /// the report's numbers (with --out-dir: one subfolder per photo).
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
    /// Print one JSON summary object on stdout: the exit status, the lights, the warnings and
    /// the files written (schema/summary.schema.json).
    #[arg(long)]
    pub json: bool,
    /// Blinn-Phong gloss e of the water (dimensionless, > 0; typical 100-2000, rough to calm;
    /// the samples: 500), overriding its material's roughness; or "auto" to estimate it from
    /// the photo together with the lights (starting from the material's; 3 to 12 joint fits
    /// over a quarter of the pixels, weighing the samples of one or a few traces, and a final
    /// one: on the samples 2.5 to 5 times as long as with the gloss given). Not with --method
    /// paper.
    #[arg(long, value_name = "E|auto")]
    pub gloss: Option<GlossArg>,
    /// The photo's exposure: its linear values are divided by it to give radiance, in the
    /// unit the exposure assumes (> 0; typical 0.01-100; the samples: 0.1). "auto": computed
    /// from the photo's EXIF exposure time, f-number and ISO speed by the reflected-light
    /// meter equation (K = 12.5, the metered luminance at linear 0.18), giving radiance in
    /// W/(sr m^2) (add --nits-scale 683 for lights in cd/m^2); each photo gets its own, and a
    /// photo whose EXIF lacks them (or an EXR/HDR, which has none) is refused.
    #[arg(long, value_name = "E|auto", default_value = "1", value_parser = super::values::exposure)]
    pub exposure: ExposureArg,
    /// Lobe samples per traced pixel of the per-streak estimate (1 or more; typical 64-2048;
    /// its time grows in proportion). Default: 512 where the estimate is the result (--method
    /// paper); where it starts the exact model's joint fit (which moves every edge from
    /// there), 32 when every light it starts lies on its lamp's whole image in the photo
    /// (which pins it), else 128; as the statistical water model's start, 128 when every
    /// light lies so, else 512.
    #[arg(long, value_name = "N", value_parser = super::values::count)]
    pub samples: Option<u32>,
    /// Seed of every random number, 0 to 2^64-1: the same inputs and seed give the same
    /// output.
    #[arg(long, default_value_t = 1, value_parser = super::values::seed)]
    pub seed: u64,
    /// Do not add emissive fallback quads for viewers without area lights.
    #[arg(long)]
    pub no_fallback_quads: bool,
    /// How to fit: "joint" (the paper's per-streak estimate refined by fitting all lights
    /// together to every water pixel that can see them, splitting a light whose streak holds
    /// two, with per-parameter uncertainties in the report) or "paper" (the per-streak
    /// estimate alone, corrected; faster, for comparison).
    #[arg(long, default_value = "joint", value_parser = ["joint", "paper"])]
    pub method: String,
    /// Which model of the water to fit with: "exact" (the scene's water mesh holds the
    /// photo's very waves, as when the photo was rendered from the scene), "statistical" (the
    /// scene gives the mean water surface, a flat quad or another field of waves, and the
    /// waves' slopes are estimated from the photo, along and across the view), or "auto"
    /// (the default: statistical when the scene's water is flat; else a first exact fit, kept
    /// if the photo's fine glints match the ones the scene's waves put there, and the fit
    /// made again with the statistical model if not; the report says which model, and why).
    #[arg(long, default_value = "auto", value_parser = ["auto", "exact", "statistical"])]
    pub water_model: String,
    /// Run the joint fit this many times, each from its own samples, and report the mean: N
    /// times slower, about sqrt(N) times less of the samples' noise; the uncertainties add the
    /// fits' spread (and so come out on the wide side). 1 or more; typical 1-8.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = super::values::count)]
    pub repeats: u32,
    /// Lobe samples per pixel of the joint fit, rounded to 8 b^2 (8, 32, 72, 128, 200, 288,
    /// ...; default 72; the fits of the statistical water's slope search read 128): the time grows with them
    /// and the fit's own noise falls, until the photo's own noise is what is left. Without
    /// this option and --all-pixels, lights the fit finds sharing a streak are fitted again
    /// over every pixel with 128 samples; with either, they are not. 1 or more; typical
    /// 32-288.
    #[arg(long, value_name = "N", value_parser = super::values::count)]
    pub joint_samples: Option<u32>,
    /// Fit every water pixel near the streaks instead of every second one (a checkerboard;
    /// one of each 2 x 2 block on a photo of more than a megapixel, of each 4 x 4 block at
    /// 4000 x 3000, and of each 2 x 2 block where the photo shows every light whole above
    /// the water and its streaks are large): about twice the joint fit's time (four times or
    /// more), and less of both the samples' and the photo's noise (more samples per pixel
    /// cannot average the photo's noise). Lights sharing a streak get this by default (see
    /// --joint-samples).
    #[arg(long)]
    pub all_pixels: bool,
    /// Fit the water pixels alone: without this, the joint fit also reads the pixels that
    /// see a light itself above the water (its direct image, clipped or not), whose edges pin
    /// the light's edges to a fraction of a pixel. A light out of frame or hidden has none
    /// either way.
    #[arg(long)]
    pub no_direct_view: bool,
    /// Fit the photo as it is: without this, a night's smooth background (a dim sky, lit
    /// facades, their reflections in the water) is measured away from every streak and lamp
    /// and taken off the photo before the lights are fitted (a black night is left as it
    /// is); the report's `background` gives it.
    #[arg(long)]
    pub no_background: bool,
    /// How far in front of its wall each light is written, in metres, along the direction it
    /// emits: a light exactly in the wall's plane is shadowed by the wall in renderers that
    /// trace shadow rays (Blender's Cycles among them). The report records it. 0 or more;
    /// typical 0.001-0.01 (far below what a fit resolves).
    #[arg(long, value_name = "METRES", default_value_t = streaklight::scene_out::DEFAULT_LIGHT_OFFSET, value_parser = super::values::non_negative_f64)]
    pub light_offset: f64,
    /// Output-file options.
    #[command(flatten)]
    pub files: OutputArgs,
    /// Succeed and write the scene unchanged when no light is found.
    #[arg(long)]
    pub allow_empty: bool,
    /// Camera, water and units.
    #[command(flatten)]
    pub scene_options: SceneArgs,
    /// Streak-extraction settings.
    #[command(flatten)]
    pub streak: StreakArgs,
}

impl Args {
    /// The fit's settings: the method carries its own (the joint fit's reading, refit and
    /// gloss); `--method paper` with joint-fit options is refused by the argument parser.
    fn fit_settings(&self) -> streaklight::Result<FitSettings> {
        let method = if self.method == "paper" {
            if matches!(self.gloss, Some(GlossArg::Auto)) {
                return Err(streaklight::Error::Usage(
                    "--gloss auto fits the gloss with the joint fit: it cannot be combined with \
                     --method paper"
                        .into(),
                ));
            }
            Method::Paper
        } else {
            let joint = match self.gloss {
                Some(GlossArg::Auto) => JointSettings::estimating_gloss(),
                _ => JointSettings::default(),
            };
            Method::Joint(JointSettings {
                repeats: self.repeats,
                direct_view: !self.no_direct_view,
                ..joint.reading_chosen(self.joint_samples, self.all_pixels)
            })
        };
        Ok(FitSettings {
            samples: self.samples,
            seed: self.seed,
            shadowing: self.scene_options.shadowing(),
            streaks: self.streak.params()?,
            method,
            water: match self.water_model.as_str() {
                "exact" => WaterChoice::Exact,
                "statistical" => WaterChoice::Statistical,
                _ => WaterChoice::Auto,
            },
            background: !self.no_background,
        })
    }
}

/// Runs the command: fits every photo, tells what was done on stderr (and with `--json` on
/// stdout), and returns the worst photo's exit.
pub fn run(args: Args, out: &Output) -> Exit {
    let mut summary = Summary::new();
    if let Err(e) = fit_all(&args, out, &mut summary) {
        let text = super::flags::in_flags(&e.to_string());
        eprintln!("error: {text}");
        summary.stopped(text, Exit::of_error(&e));
    }
    out.done();
    if args.json {
        summary.print();
    }
    summary.exit()
}

fn fit_all(args: &Args, out: &Output, summary: &mut Summary) -> streaklight::Result<()> {
    let jobs = jobs(
        &args.photos,
        &Outputs {
            output: args.output.as_deref(),
            out_dir: args.out_dir.as_deref(),
            report: args.report.as_deref(),
            debug_dir: args.debug_dir.as_deref(),
            glb: args.glb,
        },
    )?;
    super::caps::fit(args)?;
    // Made for this run, the folder is removed again if no photo wrote into it.
    let made_out_dir = match &args.out_dir {
        Some(dir) => {
            streaklight::output_file::ensure_folder_writable(dir)?;
            let made = !dir.exists();
            streaklight::output_file::create_dir_all(dir)?;
            made.then_some(dir)
        }
        None => None,
    };
    let template = ConvertOptions {
        fit: args.fit_settings()?,
        load: args.scene_options.load_options(match args.gloss {
            Some(GlossArg::Value(e)) => Some(e),
            _ => None,
        }),
        exposure: args.exposure.value_or_auto().0,
        exposure_from_exif: args.exposure.value_or_auto().1,
        fallback_quads: !args.no_fallback_quads,
        light_offset: args.light_offset,
        input_files: args.files.input_files(),
        allow_empty: args.allow_empty,
        progress: out.progress(),
        wording: super::flags::flag,
        ..ConvertOptions::new(&args.scene, "", "")
    };
    let results = convert_all(&template, &jobs);
    if let Some(dir) = made_out_dir {
        let _ = std::fs::remove_dir(dir);
    }
    let results = results?;
    for (job, result) in jobs.iter().zip(results) {
        let photo = job.photo.display().to_string();
        match result {
            Ok(outcome) => {
                tell(out, &outcome, &job.output, jobs.len() > 1, &photo);
                summary.add(&photo, &outcome, &job.output.display().to_string());
            }
            Err(e) => {
                let text = super::flags::in_flags(&e.to_string());
                out.done();
                eprintln!("error: {text}");
                let report = job
                    .report
                    .as_ref()
                    .filter(|r| r.is_file())
                    .map(|r| r.display().to_string());
                summary.refused(&photo, text, Exit::of_error(&e), report);
            }
        }
    }
    Ok(())
}

/// Tells on stderr what one photo's fit found and wrote.
fn tell(
    out: &Output,
    outcome: &streaklight::convert::ConvertOutcome,
    output: &std::path::Path,
    batch: bool,
    photo: &str,
) {
    out.done();
    let prefix = if batch {
        format!("{photo}: ")
    } else {
        String::new()
    };
    for w in &outcome.report.warnings {
        out.warn(&format!("{prefix}{w}"));
    }
    let settings = &outcome.report.settings;
    if settings.exposure_source != "given" {
        out.info(&format!(
            "{prefix}exposure {} ({}): radiance in W/(sr m^2)",
            settings.exposure, settings.exposure_source
        ));
    }
    for light in &outcome.report.lights {
        out.info(&format!(
            "{prefix}{}: streak(s) {:?}, corner ({:.4}, {:.4}, {:.4}) m, {:.4} x {:.4} m, radiance ({:.4}, {:.4}, {:.4})",
            light.name,
            light.streak_ids,
            light.corner_left_bottom[0],
            light.corner_left_bottom[1],
            light.corner_left_bottom[2],
            light.width,
            light.height,
            light.radiance[0],
            light.radiance[1],
            light.radiance[2]
        ));
    }
    let total: f64 = outcome.report.timings.iter().map(|t| t.seconds).sum();
    out.info(&format!(
        "{prefix}wrote {} with {} light(s) in {:.2} s",
        output.display(),
        outcome.report.lights.len(),
        total
    ));
}

/// `--gloss`: a value, or "auto".
#[derive(Clone, Copy, Debug)]
pub enum GlossArg {
    /// Blinn-Phong exponent e.
    Value(f32),
    /// Estimate it from the photo.
    Auto,
}

impl std::str::FromStr for GlossArg {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(GlossArg::Auto);
        }
        match s.parse::<f32>() {
            Ok(e) if e.is_finite() && e > 0.0 => Ok(GlossArg::Value(e)),
            _ => Err(format!(
                "expected a number greater than 0 (the Blinn-Phong exponent e; calm water \
                 1000-2000, rippled 100-500) or \"auto\", got \"{s}\""
            )),
        }
    }
}
