//! `streaklight samples [DIR]`: regenerate the sample scenes and photos.

use std::path::PathBuf;

use streaklight::{output_file, samples};

/// `samples --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Examples:\n  \
     streaklight samples --scenes-only\n  \
     streaklight samples samples --photo table3.png --spp 64\n\n",
    super::exit::exit_codes!()
);

/// Arguments of `streaklight samples`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder to write into.
    #[arg(default_value = "samples")]
    pub dir: PathBuf,
    /// Write the scenes (and the generated water mesh) only; do not render the photos.
    #[arg(long)]
    pub scenes_only: bool,
    /// Camera rays per pixel of the photos, 1 or more (typical 64-1024: the time grows in
    /// proportion).
    #[arg(long, value_name = "N", default_value_t = samples::PHOTO_SPP, value_parser = super::values::count)]
    pub spp: u32,
    /// Render only this photo (a file name such as `table1.png`; repeatable). By default
    /// every photo.
    #[arg(long = "photo", value_name = "NAME")]
    pub photos: Vec<String>,
}

/// Runs the command.
/// The scenes are written together, then the photos rendered from them together
/// ([`output_file::Run`]): an interrupted or failed run leaves no temporary file and no
/// half-written set.
pub fn run(args: Args, out: &super::output::Output) -> streaklight::Result<()> {
    streaklight::limits::check_cap(
        "--spp",
        args.spp.into(),
        super::caps::SPP,
        "camera rays per pixel",
    )?;
    output_file::ensure_folder_writable(&args.dir)?;
    let run = output_file::Run::begin();
    let scenes = samples::write_scenes(&args.dir)?;
    run.commit()?;
    for path in scenes {
        out.info(&format!("wrote {}", path.display()));
    }
    if !args.scenes_only {
        let photos = samples::render_photos(&args.dir, args.spp, &args.photos, out.progress())?;
        run.commit()?;
        for path in photos {
            out.info(&format!("wrote {}", path.display()));
        }
    }
    Ok(())
}
