//! `streaklight completions SHELL`: a completion script for the shell, on stdout.

use clap::CommandFactory;
use clap_complete::Shell;

/// Arguments of `streaklight completions`.
#[derive(clap::Args)]
pub struct Args {
    /// The shell to complete for.
    pub shell: Shell,
}

/// `completions --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Examples:\n  \
     streaklight completions bash > ~/.local/share/bash-completion/completions/streaklight\n  \
     streaklight completions zsh > ~/.zfunc/_streaklight\n  \
     streaklight completions fish > ~/.config/fish/completions/streaklight.fish\n\n",
    super::exit::exit_codes!()
);

/// Prints the script for the command line `C`.
pub fn run<C: CommandFactory>(args: Args) -> streaklight::Result<()> {
    let mut command = C::command();
    clap_complete::generate(
        args.shell,
        &mut command,
        "streaklight",
        &mut std::io::stdout(),
    );
    Ok(())
}
