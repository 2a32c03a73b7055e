//! `streaklight fit SCENE PHOTO -o OUT`: the main job.

use std::path::PathBuf;

use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, JointSettings, Method, WaterChoice};
use streaklight::progress::Reporter;

use super::output_args::OutputArgs;
use super::scene_args::SceneArgs;
use super::streak_args::StreakArgs;

/// Arguments of `streaklight fit`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb): a camera, the water, and the geometry lights hang on.
    pub scene: PathBuf,
    /// The night photo of the water, taken from the scene's camera (PNG, JPEG, TIFF, EXR, HDR).
    pub photo: PathBuf,
    /// The lit scene to write: .gltf or .glb (never over an input).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write a JSON report of the lights, settings and timings here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write pictures of every stage into this folder (superpixels, seeds, streaks, edges, and
    /// the photo beside the water re-rendered with the fitted lights).
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
    /// Blinn-Phong gloss e of the water, overriding its material's roughness; or "auto" to
    /// estimate it from the photo together with the lights (starting from the material's;
    /// several joint fits, so a few times slower). Not with --method paper.
    #[arg(long, value_name = "E|auto")]
    pub gloss: Option<GlossArg>,
    /// The photo's exposure: its linear values are divided by it to give radiance.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Lobe samples per traced pixel.
    #[arg(long, default_value_t = streaklight::fitting::DEFAULT_SAMPLES)]
    pub samples: u32,
    /// Seed of every random number: the same inputs and seed give the same output.
    #[arg(long, default_value_t = 1)]
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
    /// (exact if its fine structure matches the photo's, else statistical; the report says
    /// which, and why).
    #[arg(long, default_value = "auto", value_parser = ["auto", "exact", "statistical"])]
    pub water_model: String,
    /// Run the joint fit this many times, each from its own samples, and report the mean: N
    /// times slower, about sqrt(N) times less of the samples' noise; the uncertainties add the
    /// fits' spread (and so come out on the wide side).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeats: u32,
    /// Lobe samples per pixel of the joint fit, rounded to 8 b^2 (8, 32, 72, 128, 200, 288,
    /// ...; default 72, or 128 for the final fit of --gloss auto): the time grows with them
    /// and the fit's own noise falls, until the photo's own noise is what is left. Without
    /// this option and --all-pixels, lights the fit finds sharing a streak are fitted again
    /// over every pixel with 128 samples; with either, they are not.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub joint_samples: Option<u32>,
    /// Fit every water pixel near the streaks instead of every second one (a checkerboard):
    /// about twice the joint fit's time, and less of both the samples' and the photo's noise
    /// (more samples per pixel cannot average the photo's noise). Lights sharing a streak get
    /// this by default (see --joint-samples).
    #[arg(long)]
    pub all_pixels: bool,
    /// How far in front of its wall each light is written, in metres, along the direction it
    /// emits: a light exactly in the wall's plane is shadowed by the wall in renderers that
    /// trace shadow rays (Blender's Cycles among them). The report records it.
    #[arg(long, value_name = "METRES", default_value_t = streaklight::scene_out::DEFAULT_LIGHT_OFFSET)]
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
        })
    }
}

/// Runs the command.
pub fn run(args: Args) -> streaklight::Result<()> {
    let terminal = super::progress::Terminal::new();
    let options = ConvertOptions {
        fit: args.fit_settings()?,
        scene: args.scene,
        photo: args.photo,
        output: args.output,
        report: args.report,
        debug_dir: args.debug_dir,
        load: args.scene_options.load_options(match args.gloss {
            Some(GlossArg::Value(e)) => Some(e),
            _ => None,
        }),
        exposure: args.exposure,
        fallback_quads: !args.no_fallback_quads,
        light_offset: args.light_offset,
        input_files: args.files.input_files(),
        allow_empty: args.allow_empty,
        progress: Reporter::new(&terminal),
        wording: super::flags::flag,
    };
    let outcome = convert(&options)?;
    for w in &outcome.report.warnings {
        eprintln!("warning: {w}");
    }
    for light in &outcome.report.lights {
        eprintln!(
            "{}: streak(s) {:?}, corner ({:.4}, {:.4}, {:.4}), {:.4} x {:.4} m, radiance ({:.4}, {:.4}, {:.4})",
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
        );
    }
    let total: f64 = outcome.report.timings.iter().map(|t| t.seconds).sum();
    eprintln!(
        "wrote {} with {} light(s) in {:.2} s",
        options.output.display(),
        outcome.report.lights.len(),
        total
    );
    Ok(())
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
        s.parse::<f32>().map(GlossArg::Value).map_err(|_| {
            format!("expected a number (the Blinn-Phong exponent e) or \"auto\", got \"{s}\"")
        })
    }
}
