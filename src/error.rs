//! The one error type of the library. Every variant names the file it is about, so that the
//! command line can print a message a user can act on.

use std::path::PathBuf;

/// Everything that can go wrong in streaklight, as a message for a person.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A scene file is not a glTF we can use.
    #[error("{path}: {message}")]
    Scene {
        /// The scene file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A photo could not be decoded or does not fit the scene.
    #[error("{path}: {message}")]
    Photo {
        /// The photo file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// An output could not be produced.
    #[error("{path}: {message}")]
    Output {
        /// The output file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A setting's value is out of range: `setting` names it in the library's terms (a front
    /// end spells it its own way, [`crate::settings::reword`]).
    #[error("{setting} {problem}")]
    Setting {
        /// The setting.
        setting: crate::settings::Setting,
        /// What is wrong with its value, completing "`setting` ...".
        problem: String,
    },
    /// Inputs that do not fit together, or a value out of range.
    #[error("{0}")]
    Usage(String),
    /// The input was read, but the method found nothing to work with.
    #[error("{0}")]
    NothingFound(String),
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    /// A problem with the scene file `path`.
    pub fn scene(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Scene {
            path: path.into(),
            message: message.into(),
        }
    }
    /// A problem with the photo `path`.
    pub fn photo(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Photo {
            path: path.into(),
            message: message.into(),
        }
    }
    /// `setting`'s value is wrong: `problem` completes "`setting` ...".
    pub fn setting(setting: crate::settings::Setting, problem: impl Into<String>) -> Self {
        Error::Setting {
            setting,
            problem: problem.into(),
        }
    }
    /// A problem producing the output `path`.
    pub fn output(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Output {
            path: path.into(),
            message: message.into(),
        }
    }
}
