//! `streaklight render SCENE -o PHOTO`.

use std::path::PathBuf;

use streaklight::render::{render, RenderOptions};
use streaklight::scene_in;
use streaklight::{output_file, photo_out};

use super::output::Output;
use super::scene_args::SceneArgs;

/// `render --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Examples:\n  \
     streaklight render lit.gltf -o check.png --exposure 0.1\n  \
     streaklight render lit.glb -o check.exr --width 1200 --spp 256 --nits-scale 683\n  \
     streaklight render lit.gltf -o night.png --exposure 0.1 --sky 0.5 --albedo 0.25\n\n\
     Units: each pixel stores radiance times --exposure; a light's radiance is its intensity in \
     the file divided by --nits-scale. A .png is 8-bit sRGB, clipped at 1; an .exr keeps the \
     linear values.\n\n",
    super::exit::exit_codes!()
);

/// Arguments of `streaklight render`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb) with a camera, the water and EXT_lights_area lights.
    pub scene: PathBuf,
    /// The image to write: .png (8-bit sRGB, clipped) or .exr (linear float).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels, 1 or more (typical 300-2000).
    #[arg(long, value_name = "PIXELS", default_value_t = 600, value_parser = super::values::count)]
    pub width: u32,
    /// Image height in pixels, 1 or more; by default the width divided by the camera's
    /// aspect ratio.
    #[arg(long, value_name = "PIXELS", value_parser = super::values::count)]
    pub height: Option<u32>,
    /// Camera rays per pixel, 1 or more (typical 16-1024: the time grows in proportion, the
    /// noise falls as its square root).
    #[arg(long, value_name = "N", default_value_t = 64, value_parser = super::values::count)]
    pub spp: u32,
    /// Multiplies radiance before it is stored: the stored linear value per unit of radiance
    /// (> 0; typical 0.01-100; the samples use 0.1), as fit's --exposure divides by it.
    #[arg(long, value_name = "E", default_value_t = 1.0, value_parser = super::values::positive_f32)]
    pub exposure: f32,
    /// Seed of every random number, 0 to 2^64-1: the same seed gives the same image.
    #[arg(long, default_value_t = 1, value_parser = super::values::seed)]
    pub seed: u64,
    /// Blinn-Phong gloss e of the water (dimensionless, > 0; typical 100-2000, rough to calm;
    /// the samples: 200-1000), overriding its material's roughness.
    #[arg(long, value_name = "E", value_parser = super::values::positive_f32)]
    pub gloss: Option<f32>,
    /// Linear radiance of a dim sky that every ray leaving the scene sees, one value or
    /// R,G,B (>= 0; a night sky is about 1/1000 of a lamp's radiance; default black).
    #[arg(long, value_name = "L", value_parser = super::values::colour)]
    pub sky: Option<[f32; 3]>,
    /// Diffuse albedo of every surface that is not water, 0 to 1 (a facade: 0.1-0.4; default
    /// 0, black walls), lit by the sky and the lights.
    #[arg(long, value_name = "A", value_parser = super::values::unit_interval)]
    pub albedo: Option<f32>,
    /// Camera, water and units.
    #[command(flatten)]
    pub scene_options: SceneArgs,
}

impl Args {
    /// The sky and walls asked for, `None` for a black night.
    fn environment(&self) -> Option<streaklight::environment::Environment> {
        let env = streaklight::environment::Environment {
            sky: self.sky.unwrap_or([0.0; 3]),
            albedo: self.albedo.unwrap_or(0.0),
        };
        (!env.is_black()).then_some(env)
    }
}

/// Runs the command.
pub fn run(args: Args, out: &Output) -> streaklight::Result<()> {
    photo_out::ImageFormat::from_path(&args.output)?;
    super::caps::render(args.width, args.height.unwrap_or(1), args.spp)?;
    output_file::ensure_not_an_input(&args.output, &[&args.scene])?;
    // Before the render, not after it: a folder that cannot take the image fails at once.
    output_file::ensure_writable(&args.output)?;
    // The scene's buffers are recorded as they are read: the image is never written over one.
    let run = output_file::Run::begin();
    let scene = scene_in::load(&args.scene, &args.scene_options.load_options(args.gloss))?;
    for w in &scene.warnings {
        out.warn(w);
    }
    if scene.area_lights.is_empty() {
        out.warn(&format!(
            "{} has no EXT_lights_area lights: the image will be black",
            args.scene.display()
        ));
    }
    let height = args.height.unwrap_or_else(|| {
        let aspect = scene.camera.aspect_ratio.unwrap_or(1.0);
        ((args.width as f32 / aspect).round() as u32).max(1)
    });
    super::caps::render(args.width, height, args.spp)?;
    out.progress().stage("rendering");
    let options = RenderOptions {
        width: args.width,
        height,
        samples_per_pixel: args.spp,
        exposure: args.exposure,
        seed: args.seed,
        shadowing: args.scene_options.shadowing(),
        progress: out.progress(),
        water: None,
        environment: args.environment(),
    };
    let image = render(&scene, &options)?;
    photo_out::write(&args.output, image.width, image.height, &image.pixels)?;
    run.commit()?;
    out.info(&format!(
        "wrote {} ({} x {}, {} spp) in {:.2} s: {:.2} M reflected rays/s",
        args.output.display(),
        image.width,
        image.height,
        args.spp,
        image.seconds,
        image.reflected_rays as f64 / image.seconds.max(1e-9) / 1e6
    ));
    Ok(())
}
