//! The exit codes of `streaklight`, one per kind of outcome, so that a pipeline can tell "no
//! light in this photo" from a broken input and from a mistyped command line.

use std::process::ExitCode;

use streaklight::Error;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Exit {
    /// Everything asked for was done (`fit --allow-empty` with no light included).
    Success,
    /// The inputs were read, but no light (for `segment`: no streak) was found; nothing was
    /// written unless `--allow-empty`.
    NothingFound,
    /// The command line parsed, but its values do not fit together or are out of range.
    Usage,
    /// An input was refused (unreadable, inconsistent) or an output could not be written.
    Failure,
}

impl Exit {
    /// The process exit code.
    pub fn number(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::Failure => 1,
            Exit::Usage => 2,
            Exit::NothingFound => 3,
        }
    }

    /// The word the JSON summary uses.
    pub fn word(self) -> &'static str {
        match self {
            Exit::Success => "ok",
            Exit::Failure => "error",
            Exit::Usage => "usage",
            Exit::NothingFound => "no light found",
        }
    }

    /// The kind of outcome an error is.
    pub fn of_error(e: &Error) -> Exit {
        match e {
            Error::NothingFound(_) => Exit::NothingFound,
            Error::Usage(_) | Error::Setting { .. } => Exit::Usage,
            _ => Exit::Failure,
        }
    }

    /// The outcome of a command that reports its error itself, printing the error as
    /// `error: ...` on stderr.
    pub fn of(result: streaklight::Result<()>) -> Exit {
        match result {
            Ok(()) => Exit::Success,
            Err(e) => {
                eprintln!("error: {}", super::flags::in_flags(&e.to_string()));
                Exit::of_error(&e)
            }
        }
    }

    /// The process exit code.
    pub fn code(self) -> ExitCode {
        ExitCode::from(self.number())
    }
}

/// The exit codes, as `--help` shows them.
macro_rules! exit_codes {
    () => {
        "Exit codes:\n  0  success (also `fit --allow-empty` when no light is found)\n  \
         1  an input was refused or an output could not be written (`error: ...` on stderr)\n  \
         2  the command line is wrong: an unknown option, a missing argument, a value out of \
         range (e.g. --exposure -1), options that do not go together\n  \
         3  no light found (`segment`: no streak): the inputs were read, nothing was written"
    };
}
pub(crate) use exit_codes;

/// The top-level `--help`'s epilogue.
pub const MAIN_HELP: &str = concat!(
    "Examples:\n  streaklight samples --scenes-only\n  \
     streaklight fit samples/scene.gltf samples/table3.png --exposure 0.1 -o lit.gltf --report report.json\n  \
     streaklight render lit.gltf -o check.png --exposure 0.1\n  \
     streaklight completions bash > ~/.local/share/bash-completion/completions/streaklight\n\n",
    exit_codes!()
);

/// `segment --help`'s epilogue.
pub const SEGMENT_HELP: &str = concat!(
    "Example:\n  streaklight segment samples/scene.gltf samples/table3.png --exposure 0.1 --out-dir streaks\n\n",
    exit_codes!()
);
