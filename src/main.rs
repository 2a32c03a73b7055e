//! The `streaklight` command: parses arguments and calls the library. No logic lives here.

use std::process::ExitCode;

use clap::Parser;

mod cli;

use cli::exit::Exit;

#[derive(Parser)]
#[command(
    name = "streaklight",
    version,
    about = "Fit rectangle area lights to the reflections of lights on night water, and write them into a glTF scene",
    after_help = cli::exit::MAIN_HELP
)]
pub struct Cli {
    /// Print only warnings and errors: no progress, no summary lines.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    /// Also print every stage's time, and counted work as lines even on a terminal.
    #[arg(short, long, global = true)]
    pub verbose: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(clap::Subcommand)]
pub enum Command {
    /// Fit rectangle area lights to the streaks of a photo (or several photos of one scene)
    /// and write them into the scene.
    #[command(allow_negative_numbers = true, after_help = cli::fit::AFTER_HELP)]
    Fit(cli::fit::Args),
    /// Find the streaks (reflections of lights) in a photo, one per light as `fit` fits them
    /// (fragments of one light merged), and draw pictures of every stage.
    #[command(allow_negative_numbers = true, after_help = cli::exit::SEGMENT_HELP)]
    Segment(cli::segment::Args),
    /// Render the water and the EXT_lights_area lights of a scene as its camera sees them.
    #[command(allow_negative_numbers = true, after_help = cli::render::AFTER_HELP)]
    Render(cli::render::Args),
    /// Put back the EXT_lights_area lights of a fit output from its fallback quads, after a
    /// tool without the extension dropped them.
    #[command(after_help = cli::restore_lights::AFTER_HELP)]
    RestoreLights(cli::restore_lights::Args),
    /// Write the sample scenes of the paper's setup and render their photos.
    #[command(allow_negative_numbers = true, after_help = cli::samples::AFTER_HELP)]
    Samples(cli::samples::Args),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell) on stdout.
    #[command(after_help = cli::completions::AFTER_HELP)]
    Completions(cli::completions::Args),
    /// Write the manual pages: streaklight.1 and one streaklight-NAME.1 per command.
    #[command(after_help = cli::man::AFTER_HELP)]
    Man(cli::man::Args),
}

fn main() -> ExitCode {
    let parsed = Cli::parse();
    streaklight::output_file::interrupt::install();
    let out = cli::output::Output::new(parsed.quiet, parsed.verbose);
    let exit = match parsed.command {
        Command::Fit(args) => cli::fit::run(args, &out),
        Command::Segment(args) => Exit::of(cli::segment::run(args, &out)),
        Command::Render(args) => Exit::of(cli::render::run(args, &out)),
        Command::Samples(args) => Exit::of(cli::samples::run(args, &out)),
        Command::Completions(args) => Exit::of(cli::completions::run::<Cli>(args)),
        Command::RestoreLights(args) => Exit::of(cli::restore_lights::run(args, &out)),
        Command::Man(args) => Exit::of(cli::man::run::<Cli>(args, &out)),
    };
    exit.code()
}
