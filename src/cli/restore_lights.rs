//! `streaklight restore-lights IN -o OUT`: put back the lights a tool dropped.

use std::path::PathBuf;

use streaklight::scene_out::restore_lights;

use super::output::Output;
use super::output_args::OutputArgs;

/// `restore-lights --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Example:\n  \
     gltf-transform optimize lit.glb optimized.glb && \
     streaklight restore-lights optimized.glb -o restored.glb\n\n",
    super::exit::exit_codes!()
);

/// Arguments of `streaklight restore-lights`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene written by `streaklight fit` (with its fallback quads) and then run through a
    /// tool that dropped the EXT_lights_area extension.
    pub input: PathBuf,
    /// The scene to write, with the lights back: .gltf or .glb (never over the input).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Output-file options.
    #[command(flatten)]
    pub files: OutputArgs,
}

/// Runs the command.
pub fn run(args: Args, out: &Output) -> streaklight::Result<()> {
    let run = streaklight::output_file::Run::begin();
    let summary = restore_lights(&args.input, &args.output, args.files.input_files())?;
    run.commit()?;
    for w in &summary.resources.warnings {
        out.warn(w);
    }
    out.info(&format!(
        "wrote {}: {} light(s) restored, {} still there",
        args.output.display(),
        summary.restored_nodes.len(),
        summary.already_present
    ));
    Ok(())
}
