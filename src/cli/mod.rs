//! One file per subcommand: its arguments and a `run` that calls the library.

pub mod caps;
pub mod completions;
pub mod exit;
pub mod fit;
pub mod fit_batch;
pub mod flags;
pub mod json;
pub mod man;
pub mod output;
pub mod output_args;
pub mod progress;
pub mod render;
pub mod restore_lights;
pub mod samples;
pub mod scene_args;
pub mod segment;
pub mod streak_args;
pub mod values;
