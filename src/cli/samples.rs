//! `streaklight samples [DIR]`: regenerate the sample scenes and photos.

use std::path::PathBuf;

use streaklight::samples;

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
pub fn run(args: Args, out: &super::output::Output) -> streaklight::Result<()> {
    for path in samples::write_scenes(&args.dir)? {
        out.info(&format!("wrote {}", path.display()));
    }
    if !args.scenes_only {
        for path in samples::render_photos(&args.dir, args.spp, &args.photos, out.progress())? {
            out.info(&format!("wrote {}", path.display()));
        }
    }
    Ok(())
}
