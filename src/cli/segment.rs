//! `streaklight segment SCENE PHOTO --out-dir DIR`.

use std::path::PathBuf;

use streaklight::fitting::{fragments, FitOptions, Skipped};
use streaklight::scene_in::{self, LoadOptions};
use streaklight::streaks::{self, pictures, report};
use streaklight::water_model::ExactSurface;

use super::streak_args::StreakArgs;
use super::values::ExposureArg;
use streaklight::{output_file, photo_exif, photo_in, water_mask, Error};

/// Arguments of `streaklight segment`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb) the photo was taken in.
    pub scene: PathBuf,
    /// The photo of the water.
    pub photo: PathBuf,
    /// Folder for the pictures and streaks.json (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Divides the photo's linear values to give radiance (> 0; typical 0.01-100; the
    /// samples use 0.1), or "auto" from the photo's EXIF, as for `fit`. The streaks are found
    /// on the photo's colours as they are; the exposure scales the radiance streaks.json
    /// reports.
    #[arg(long, value_name = "E|auto", default_value = "1", value_parser = super::values::exposure)]
    pub exposure: ExposureArg,
    /// Camera node or camera name (default: the first camera of the default scene).
    #[arg(long)]
    pub camera: Option<String>,
    /// Water node or mesh name (default: the one node whose name contains "water").
    #[arg(long)]
    pub water: Option<String>,
    /// Blinn-Phong gloss e of the water (dimensionless, > 0; typical 100-2000, rough to calm;
    /// the samples: 200-1000), overriding its material's roughness: the lobe with which the
    /// streaks' lights are placed to tell fragments of one light from two lights, as `fit`
    /// does.
    #[arg(long, value_name = "E", value_parser = super::values::positive_f32)]
    pub gloss: Option<f32>,
    /// Index of refraction of the water, above 1 (dimensionless; water 1.33; default: its
    /// material's KHR_materials_ior, else 1.33).
    #[arg(long, value_name = "N", value_parser = super::values::ior)]
    pub ior: Option<f32>,
    /// Streak-extraction settings.
    #[command(flatten)]
    pub streak: StreakArgs,
}

/// Runs the command. Nothing is written unless streaks are found; the pictures and
/// streaks.json are then written together ([`output_file::Run`]). The streaks are those of
/// the lights `fit` fits: fragments of one light (method §5 step 5) are merged as `fit` merges them
/// ([`fragments::lights`], under the scene's own water mesh), and each streak lists
/// the fragments it is made of.
pub fn run(args: Args, out: &super::output::Output) -> streaklight::Result<()> {
    let params = args.streak.params()?;
    output_file::ensure_folder_writable(&args.out_dir)?;
    let mut names: Vec<&str> = pictures::PICTURE_NAMES.to_vec();
    names.push(pictures::STREAKS_JSON);
    let outputs: Vec<PathBuf> = names.iter().map(|n| args.out_dir.join(n)).collect();
    for o in &outputs {
        output_file::ensure_not_an_input(o, &[&args.scene, &args.photo])?;
    }
    let run = output_file::Run::begin();
    let exposure = match args.exposure {
        ExposureArg::Value(e) => e,
        ExposureArg::Auto => {
            let (e, source) = photo_exif::exposure_of(&args.photo)?;
            out.info(&format!("exposure {e} ({source})"));
            e
        }
    };
    let photo = photo_in::load(&args.photo, exposure)?;
    let scene = scene_in::load(
        &args.scene,
        &LoadOptions {
            camera: args.camera,
            water: args.water,
            gloss: args.gloss,
            ior: args.ior,
            ..LoadOptions::default()
        },
    )?;
    for w in &scene.warnings {
        out.warn(w);
    }
    streaklight::convert::check_photo(&scene, &photo, &args.photo)?;
    let water = water_mask::water_mask(&scene, photo.width, photo.height);
    let in_photo = |e: Error| match e {
        Error::NothingFound(m) => Error::NothingFound(format!("{}: {m}", args.photo.display())),
        other => other,
    };
    let mut pieces = streaks::extract_streaks(&photo, &water, &params).map_err(in_photo)?;
    // As `fit` does: a night's smooth background is taken off and the streaks found again.
    let photo = match streaklight::background::take_off(&photo, &water, &pieces) {
        None => photo,
        Some((background, less)) => {
            let m = background.water_mean;
            out.info(&format!(
                "measured the night's smooth background (mean on the water {:.4} {:.4} {:.4}, \
                 {:.0} % of the streaks' light) and took it off the photo",
                m[0],
                m[1],
                m[2],
                100.0 * background.streak_share
            ));
            pieces = streaks::extract_streaks(&less, &water, &params).map_err(in_photo)?;
            less
        }
    };
    pieces
        .require_streaks()
        .map_err(|e| Error::NothingFound(format!("{}: {e}", args.photo.display())))?;
    let observations: Vec<_> = pieces
        .streaks
        .iter()
        .map(|s| streaklight::pipeline::observation(s, photo.width))
        .collect();
    let (groups, grouping) = fragments::lights(
        &ExactSurface,
        &scene,
        &photo,
        &water,
        &observations,
        &FitOptions::for_scene(&scene),
    );
    for w in &grouping.warnings {
        out.warn(w);
    }
    for skipped in &grouping.skipped {
        let (Skipped::NoPlane { streak, message } | Skipped::NoSolution { streak, message }) =
            skipped;
        out.warn(&format!(
            "streak {streak} of the extraction gave no light, so it is merged with none: \
             {message}"
        ));
    }
    let seg = pieces.merged(&photo, &groups);

    output_file::create_dir_all(&args.out_dir)?;
    let mut written = pictures::write_pictures(&args.out_dir, &photo, &water, &seg)?;
    let json = args.out_dir.join(pictures::STREAKS_JSON);
    report::write_report(&json, &seg, Some(&pieces), &params)?;
    written.push(json);
    run.commit()?;
    for p in &written {
        println!("wrote {}", p.display());
    }
    for s in &seg.streaks {
        let fragments: Vec<String> = s.fragments.iter().map(|f| f.to_string()).collect();
        println!(
            "streak {} (fragments {}): {} pixels, columns {}-{}, rows {}-{}, brightest pixel \
             ({}, {})",
            s.id,
            fragments.join(", "),
            s.pixels.len(),
            s.bbox.x_min,
            s.bbox.x_max,
            s.bbox.y_min,
            s.bbox.y_max,
            s.brightest.0,
            s.brightest.1
        );
    }
    Ok(())
}
