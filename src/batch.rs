//! Several photos of one scene in one run: the scene (and its BVH) is loaded once, and each
//! photo is fitted and written as [`crate::convert::convert`] would, to its own files.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::convert::{
    check_output, convert_loaded, convert_loaded_with, copies_ahead, refusing, ConvertOptions,
    ConvertOutcome,
};
use crate::{output_file, scene_in, Error, Result};

/// One photo of a batch and the files its fit writes.
#[derive(Clone, Debug)]
pub struct Job {
    /// The photo.
    pub photo: PathBuf,
    /// The lit scene to write (`.gltf` or `.glb`).
    pub output: PathBuf,
    /// The report to write, if any.
    pub report: Option<PathBuf>,
    /// The folder of the debug pictures, if any.
    pub debug_dir: Option<PathBuf>,
}

/// Fits every job's photo in the scene of `template` (whose photo, output, report and debug
/// folder are replaced by each job's), loading the scene once. Returns each job's outcome in
/// order: one photo's refusal does not stop the others, and a job with a report path writes
/// its refusal there as [`convert`](crate::convert::convert) does.
///
/// Fails as a whole, before any work, when two jobs would write the same file or one would
/// write over another's photo; and when the settings or the scene are refused (then every
/// job's report says so).
pub fn convert_all(template: &ConvertOptions, jobs: &[Job]) -> Result<Vec<Result<ConvertOutcome>>> {
    check_distinct(jobs)?;
    let photos: Vec<&Path> = jobs.iter().map(|j| j.photo.as_path()).collect();
    let options: Vec<ConvertOptions> = jobs
        .iter()
        .map(|j| ConvertOptions {
            photo: j.photo.clone(),
            output: j.output.clone(),
            report: j.report.clone(),
            debug_dir: j.debug_dir.clone(),
            ..template.clone()
        })
        .collect();
    // Paths first, for every job: a long batch does not end in a refusal of its last output.
    let checked: Vec<Result<()>> = options
        .iter()
        .map(|o| {
            check_output(o)?
                .iter()
                .try_for_each(|w| output_file::ensure_not_an_input(w, &photos))
        })
        .collect();
    if checked.iter().all(Result::is_err) {
        // Nothing to do: no scene load either.
        return Ok(checked
            .into_iter()
            .filter_map(Result::err)
            .map(Err)
            .collect());
    }
    // Every file read from here on (the scene, its buffers, the photos) is kept from being
    // written over, and each photo's outputs are committed together or not at all.
    let _run = output_file::Run::begin();
    let progress = template.progress;
    // The first photo's output copies the scene's files while the scene loads, on the core
    // the load leaves free; the others start with their own fits.
    let mut first_ahead = options
        .iter()
        .zip(&checked)
        .find(|(_, c)| c.is_ok())
        .map(|(o, _)| (o.output.clone(), copies_ahead(o)));
    let start = Instant::now();
    progress.stage("load scene");
    let loaded = template
        .fit
        .validate()
        .and_then(|()| scene_in::load(&template.scene, &template.load));
    let seconds = start.elapsed().as_secs_f64();
    let scene = match loaded {
        Ok(scene) => scene,
        Err(e) => {
            let text = e.to_string();
            for (o, c) in options.iter().zip(&checked) {
                if c.is_ok() {
                    // The same refusal in each report.
                    let _ = refusing(o, || Err::<(), _>(Error::Usage(text.clone())));
                }
            }
            return Err(e);
        }
    };
    let n = jobs.len();
    Ok(options
        .iter()
        .zip(checked)
        .enumerate()
        .map(|(i, (o, c))| {
            c?;
            progress.stage(&format!("photo {} of {n}: {}", i + 1, o.photo.display()));
            let before = vec![("load scene".into(), seconds)];
            let ahead = first_ahead
                .take_if(|(output, _)| *output == o.output)
                .map(|(_, ahead)| ahead);
            refusing(o, || match ahead {
                Some(ahead) => convert_loaded_with(&scene, before, o, ahead),
                None => convert_loaded(&scene, before, o),
            })
        })
        .collect())
}

/// Refuses jobs that would write the same file or folder twice.
fn check_distinct(jobs: &[Job]) -> Result<()> {
    let mut seen = HashSet::new();
    for j in jobs {
        let paths = std::iter::once(&j.output)
            .chain(&j.report)
            .chain(&j.debug_dir);
        for p in paths {
            if !seen.insert(output_file::identity(p)) {
                return Err(Error::output(
                    p,
                    "two photos of the batch would write this same file; name their outputs apart",
                ));
            }
        }
    }
    Ok(())
}
