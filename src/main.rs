//! The `streaklight` command: parses arguments and calls the library. No logic lives here.

use std::process::ExitCode;

use clap::Parser;

mod cli;

#[derive(Parser)]
#[command(
    name = "streaklight",
    version,
    about = "Fit rectangle area lights to the reflections of lights on night water, and write them into a glTF scene"
)]
enum Command {
    /// Fit rectangle area lights to the streaks of a photo and write them into the scene.
    Fit(cli::fit::Args),
    /// Find the streaks (reflections of lights) in a photo and draw pictures of every stage.
    Segment(cli::segment::Args),
    /// Render the water and the EXT_lights_area lights of a scene as its camera sees them.
    Render(cli::render::Args),
    /// Put back the EXT_lights_area lights of a fit output from its fallback quads, after a
    /// tool without the extension dropped them.
    RestoreLights(cli::restore_lights::Args),
    /// Write the sample scenes of the paper's setup and render their photos.
    Samples(cli::samples::Args),
}

fn main() -> ExitCode {
    let result = match Command::parse() {
        Command::Fit(args) => cli::fit::run(args),
        Command::Segment(args) => cli::segment::run(args),
        Command::Render(args) => cli::render::run(args),
        Command::Samples(args) => cli::samples::run(args),
        Command::RestoreLights(args) => cli::restore_lights::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", cli::flags::in_flags(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}
