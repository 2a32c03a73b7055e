//! What a command prints on stderr, at the verbosity `--quiet` and `--verbose` chose: warnings
//! and errors always; progress and what was done unless quiet.

use streaklight::progress::Reporter;

use super::progress::{Terminal, Verbosity};

/// The command's stderr.
pub struct Output {
    terminal: Terminal,
    quiet: bool,
}

impl Output {
    /// Output at the verbosity of the global flags.
    pub fn new(quiet: bool, verbose: bool) -> Self {
        let verbosity = if quiet {
            Verbosity::Quiet
        } else if verbose {
            Verbosity::Verbose
        } else {
            Verbosity::Normal
        };
        Output {
            terminal: Terminal::new(verbosity),
            quiet,
        }
    }

    /// The library's reporter: progress on stderr.
    pub fn progress(&self) -> Reporter<'_> {
        Reporter::new(&self.terminal)
    }

    /// What was done, unless quiet (ends the current stage's progress first).
    pub fn info(&self, line: &str) {
        if !self.quiet {
            self.terminal.finish();
            self.terminal.println(line);
        }
    }

    /// A warning, always.
    pub fn warn(&self, text: &str) {
        self.terminal
            .println(&format!("warning: {}", super::flags::in_flags(text)));
    }

    /// Ends the current stage's progress.
    pub fn done(&self) {
        self.terminal.finish();
    }
}
