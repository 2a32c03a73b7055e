//! `streaklight segment SCENE PHOTO --out-dir DIR`.

use std::path::PathBuf;

use streaklight::scene_in::{self, LoadOptions};
use streaklight::streaks::{self, pictures, report, StreakParams};
use streaklight::{photo_in, water_mask, Error};

/// Arguments of `streaklight segment`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb) the photo was taken in.
    pub scene: PathBuf,
    /// The photo of the water.
    pub photo: PathBuf,
    /// Folder for the pictures and streaks.json (created if missing).
    #[arg(long)]
    pub out_dir: PathBuf,
    /// Divides the photo's linear values to give radiance.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Camera node or camera name (default: the first camera of the default scene).
    #[arg(long)]
    pub camera: Option<String>,
    /// Water node or mesh name (default: the one node whose name contains "water").
    #[arg(long)]
    pub water: Option<String>,
    /// Number of superpixels K (default: one per 400 pixels).
    #[arg(long)]
    pub superpixels: Option<usize>,
    /// SLIC compactness m.
    #[arg(long, default_value_t = 10.0)]
    pub compactness: f32,
    /// Seed search: every k-th row.
    #[arg(long, default_value_t = 8)]
    pub seed_row_step: usize,
    /// Seed threshold t on the value V (sRGB-encoded, 0 to 1).
    #[arg(long, default_value_t = 0.35)]
    pub seed_threshold: f32,
    /// Gaussian blur sigma in pixels before the seed search.
    #[arg(long, default_value_t = 1.5)]
    pub blur: f32,
    /// Histogram correlation at or above which two superpixels are one streak (-1 to 1).
    #[arg(long, default_value_t = 0.5)]
    pub similarity: f32,
    /// Mean V below which a superpixel never joins a streak.
    #[arg(long, default_value_t = 0.15)]
    pub min_value: f32,
}

/// Runs the command.
pub fn run(args: Args) -> streaklight::Result<()> {
    let mut params = StreakParams::default();
    params.slic.superpixels = args.superpixels;
    params.slic.compactness = args.compactness;
    params.seeds.row_step = args.seed_row_step;
    params.seeds.threshold = args.seed_threshold;
    params.seeds.blur_sigma = args.blur;
    params.grow.similarity = args.similarity;
    params.grow.min_value = args.min_value;
    params.seeds.validate()?;
    params.grow.validate()?;

    let photo = photo_in::load(&args.photo, args.exposure)?;
    let scene = scene_in::load(
        &args.scene,
        &LoadOptions {
            camera: args.camera,
            water: args.water,
            ..LoadOptions::default()
        },
    )?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(aspect) = scene.camera.aspect_ratio {
        let photo_aspect = photo.width as f32 / photo.height as f32;
        if ((photo_aspect - aspect) / aspect).abs() > 0.005 {
            return Err(Error::photo(
                &args.photo,
                format!(
                    "the photo is {} x {} (aspect {photo_aspect:.4}) but the camera's aspect ratio is {aspect:.4}",
                    photo.width, photo.height
                ),
            ));
        }
    }
    let water = water_mask::water_mask(&scene, photo.width, photo.height);
    let seg = streaks::extract_streaks(&photo, &water, &params).map_err(|e| match e {
        Error::NothingFound(m) => Error::NothingFound(format!("{}: {m}", args.photo.display())),
        other => other,
    })?;

    std::fs::create_dir_all(&args.out_dir).map_err(|e| Error::io(&args.out_dir, e))?;
    let written = pictures::write_pictures(&args.out_dir, &photo, &water, &seg)?;
    let json = args.out_dir.join("streaks.json");
    report::write_report(&json, &seg, &params)?;
    for p in written.iter().chain(std::iter::once(&json)) {
        println!("wrote {}", p.display());
    }
    for s in &seg.streaks {
        println!(
            "streak {}: {} pixels, columns {}-{}, rows {}-{}, brightest pixel ({}, {})",
            s.id,
            s.pixels.len(),
            s.bbox.x_min,
            s.bbox.x_max,
            s.bbox.y_min,
            s.bbox.y_max,
            s.brightest.0,
            s.brightest.1
        );
    }
    seg.require_streaks()
        .map_err(|e| Error::NothingFound(format!("{}: {e}", args.photo.display())))
}
