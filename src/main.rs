//! The `streaklight` command: parses arguments and calls the library.

use std::process::ExitCode;

use clap::Parser;

#[derive(Parser)]
#[command(name = "streaklight", version, about = "Fit rectangle area lights to the reflections of lights on night water")]
enum Command {}

fn main() -> ExitCode {
    let _ = Command::parse();
    ExitCode::SUCCESS
}
