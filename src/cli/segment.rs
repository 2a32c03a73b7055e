//! `streaklight segment SCENE PHOTO --out-dir DIR`.

use std::path::PathBuf;

/// Arguments of `streaklight segment`.
#[derive(clap::Args)]
pub struct Args {
    /// The glTF scene (.gltf or .glb) the photo was taken in.
    pub scene: PathBuf,
    /// The photo of the water.
    pub photo: PathBuf,
    /// Folder for the pictures and streaks.json.
    #[arg(long)]
    pub out_dir: PathBuf,
}

/// Runs the command.
pub fn run(_args: Args) -> streaklight::Result<()> {
    Err(streaklight::Error::Usage(
        "segment is not written yet".into(),
    ))
}
