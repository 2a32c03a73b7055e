//! `fit --json`: one summary object on stdout, described by `schema/summary.schema.json`:
//! the exit status, every light, every warning, every file written, and each photo's outcome.

use serde::Serialize;

use streaklight::convert::ConvertOutcome;
use streaklight::report::UncertaintyReport;

use super::exit::Exit;

/// Version of the summary's shape.
pub const SUMMARY_VERSION: u32 = 1;

/// The summary of one `fit` run.
#[derive(Serialize)]
pub struct Summary {
    summary_version: u32,
    /// [`Exit::word`] of the run's exit code.
    status: &'static str,
    exit_code: u8,
    /// Why the run stopped before any photo was fitted (a usage error), if it did.
    error: Option<String>,
    lights: Vec<LightSummary>,
    warnings: Vec<WarningSummary>,
    files_written: Vec<String>,
    photos: Vec<PhotoSummary>,
    #[serde(skip)]
    exit: Exit,
}

#[derive(Serialize)]
struct PhotoSummary {
    photo: String,
    status: &'static str,
    exit_code: u8,
    error: Option<String>,
    output: Option<String>,
    lights: usize,
    /// The exposure the photo was read with, and where it came from (the report's).
    exposure: Option<f32>,
    exposure_source: Option<String>,
}

#[derive(Serialize)]
struct LightSummary {
    photo: String,
    name: String,
    streak_ids: Vec<usize>,
    corner_left_bottom: [f64; 3],
    width: f64,
    height: f64,
    radiance: [f64; 3],
    unconstrained_edges: Vec<&'static str>,
    uncertainty: Option<UncertaintyReport>,
}

#[derive(Serialize)]
struct WarningSummary {
    photo: Option<String>,
    message: String,
}

impl Summary {
    /// An empty summary of a successful run.
    pub fn new() -> Self {
        Summary {
            summary_version: SUMMARY_VERSION,
            status: Exit::Success.word(),
            exit_code: 0,
            error: None,
            lights: Vec::new(),
            warnings: Vec::new(),
            files_written: Vec::new(),
            photos: Vec::new(),
            exit: Exit::Success,
        }
    }

    fn worsen(&mut self, exit: Exit) {
        self.exit = self.exit.max(exit);
        self.status = self.exit.word();
        self.exit_code = self.exit.number();
    }

    /// The run stopped before any photo: `error` says why.
    pub fn stopped(&mut self, error: String, exit: Exit) {
        self.error = Some(error);
        self.worsen(exit);
    }

    /// `photo`'s outcome.
    pub fn add(&mut self, photo: &str, outcome: &ConvertOutcome, output: &str) {
        let report = &outcome.report;
        for w in &report.warnings {
            self.warnings.push(WarningSummary {
                photo: Some(photo.into()),
                message: w.clone(),
            });
        }
        for l in &report.lights {
            let sides = [
                ("left", &l.edges.left),
                ("right", &l.edges.right),
                ("bottom", &l.edges.bottom),
                ("top", &l.edges.top),
            ];
            self.lights.push(LightSummary {
                photo: photo.into(),
                name: l.name.clone(),
                streak_ids: l.streak_ids.clone(),
                corner_left_bottom: l.corner_left_bottom,
                width: l.width,
                height: l.height,
                radiance: l.radiance,
                unconstrained_edges: sides
                    .iter()
                    .filter(|(_, e)| e.status != "constrained")
                    .map(|(s, _)| *s)
                    .collect(),
                uncertainty: l.uncertainty.clone(),
            });
        }
        self.files_written.extend(
            outcome
                .files_written
                .iter()
                .map(|p| p.display().to_string()),
        );
        self.photos.push(PhotoSummary {
            photo: photo.into(),
            status: Exit::Success.word(),
            exit_code: 0,
            error: None,
            output: Some(output.into()),
            lights: report.lights.len(),
            exposure: Some(report.settings.exposure),
            exposure_source: Some(report.settings.exposure_source.clone()),
        });
    }

    /// `photo` was refused for `error`; `report` is its refusal report, if one was written.
    pub fn refused(&mut self, photo: &str, error: String, exit: Exit, report: Option<String>) {
        self.files_written.extend(report);
        self.photos.push(PhotoSummary {
            photo: photo.into(),
            status: exit.word(),
            exit_code: exit.number(),
            error: Some(error),
            output: None,
            lights: 0,
            exposure: None,
            exposure_source: None,
        });
        self.worsen(exit);
    }

    /// The run's exit.
    pub fn exit(&self) -> Exit {
        self.exit
    }

    /// Prints the summary as one line of JSON on stdout.
    pub fn print(&self) {
        match serde_json::to_string(self) {
            Ok(line) => println!("{line}"),
            Err(e) => eprintln!("error: cannot write the JSON summary: {e}"),
        }
    }
}
