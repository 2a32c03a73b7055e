//! How an output scene treats the input's files, shared by the commands that write one.

use streaklight::scene_out::InputFiles;

/// Output-file options.
#[derive(clap::Args)]
pub struct OutputArgs {
    /// For a .gltf output: refer to the input's buffer and image files where they are
    /// (relative paths, with a warning) instead of copying them beside the output. The output
    /// then breaks if they move, and a tool that rewrites it in place may write into them. By
    /// default a .gltf's folder holds every file it needs, and a .glb holds everything itself.
    #[arg(long)]
    pub reference_input_files: bool,
}

impl OutputArgs {
    /// The library's setting.
    pub fn input_files(&self) -> InputFiles {
        if self.reference_input_files {
            InputFiles::Reference
        } else {
            InputFiles::Copy
        }
    }
}
