//! `streaklight render SCENE -o PHOTO`.

use std::path::PathBuf;

use streaklight::render::{render, RenderOptions};
use streaklight::scene_in;
use streaklight::{output_file, photo_out};

use super::output::Output;
use super::scene_args::SceneArgs;

/// Arguments of `streaklight render`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb) with a camera, the water and EXT_lights_area lights.
    pub scene: PathBuf,
    /// The image to write: .png (8-bit sRGB, clipped) or .exr (linear float).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 600)]
    pub width: u32,
    /// Image height in pixels; by default the width divided by the camera's aspect ratio.
    #[arg(long)]
    pub height: Option<u32>,
    /// Camera rays per pixel.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Multiplies radiance before it is stored (> 0; the samples use 0.1).
    #[arg(long, default_value_t = 1.0, value_parser = super::values::positive_f32)]
    pub exposure: f32,
    /// Seed of every random number: the same seed gives the same image.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Blinn-Phong gloss e of the water, overriding its material's roughness (> 0; the
    /// samples: 200-1000).
    #[arg(long, value_parser = super::values::positive_f32)]
    pub gloss: Option<f32>,
    /// Camera, water and units.
    #[command(flatten)]
    pub scene_options: SceneArgs,
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
