//! The report of a refused run: the files it was about and why it was refused, nothing else
//! (no light was written).

use std::path::Path;

use serde::Serialize;

use super::{Files, REPORT_VERSION};
use crate::{output_file, Error, Result};

/// [`Refusal::status`].
pub const REFUSED: &str = "refused";

/// What `fit --report` writes when the run is refused after its output paths were checked.
#[derive(Clone, Debug, Serialize)]
pub struct Refusal {
    /// Version of the report's shape.
    pub report_version: u32,
    /// streaklight's version.
    pub tool_version: String,
    /// Always `REFUSED`.
    pub status: String,
    /// Why, as the error message says it.
    pub error: String,
    /// The input scene and photo (`output` is null: nothing was written).
    pub files: Files,
}

impl Refusal {
    /// The refusal of the run on `files` for the reason `error`.
    pub fn new(files: Files, error: String) -> Self {
        Refusal {
            report_version: REPORT_VERSION,
            tool_version: env!("CARGO_PKG_VERSION").into(),
            status: REFUSED.into(),
            error,
            files: Files {
                output: None,
                ..files
            },
        }
    }

    /// Writes it to `path` (atomically).
    pub fn write(&self, path: &Path) -> Result<()> {
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::output(path, e.to_string()))?;
        output_file::write_atomically(path, text.as_bytes())
    }
}
