//! The files each photo of `fit` writes: with `-o OUT`, the one photo's OUT and `--report`;
//! with `--out-dir DIR`, for each photo `DIR/NAME.gltf` (or `.glb`), `DIR/NAME.report.json`
//! and, with `--debug-dir D`, the pictures in `D/NAME/`, NAME being the photo's file stem,
//! or the stem and the photo's position when two photos share a stem (never colliding).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use streaklight::batch::Job;
use streaklight::Error;

/// Where the outputs go, as the command line gave it.
pub struct Outputs<'a> {
    /// `-o OUT`.
    pub output: Option<&'a Path>,
    /// `--out-dir DIR`.
    pub out_dir: Option<&'a Path>,
    /// `--report R` (one photo with `-o`).
    pub report: Option<&'a Path>,
    /// `--debug-dir D`.
    pub debug_dir: Option<&'a Path>,
    /// `--glb`: write `.glb` files into DIR.
    pub glb: bool,
}

/// The job of each photo.
pub fn jobs(photos: &[PathBuf], to: &Outputs) -> streaklight::Result<Vec<Job>> {
    match (to.output, to.out_dir) {
        (Some(output), None) => {
            if photos.len() != 1 {
                return Err(Error::Usage(format!(
                    "-o names one output, but {} photos were given: use --out-dir DIR to write \
                     one scene and report per photo",
                    photos.len()
                )));
            }
            Ok(vec![Job {
                photo: photos[0].clone(),
                output: output.to_owned(),
                report: to.report.map(Path::to_owned),
                debug_dir: to.debug_dir.map(Path::to_owned),
            }])
        }
        (None, Some(dir)) => {
            if to.report.is_some() {
                return Err(Error::Usage(
                    "--report names one file; with --out-dir every photo's report is written \
                     as DIR/NAME.report.json"
                        .into(),
                ));
            }
            let extension = if to.glb { "glb" } else { "gltf" };
            Ok(names(photos)
                .into_iter()
                .zip(photos)
                .map(|(name, photo)| Job {
                    photo: photo.clone(),
                    output: dir.join(format!("{name}.{extension}")),
                    report: Some(dir.join(format!("{name}.report.json"))),
                    debug_dir: to.debug_dir.map(|d| d.join(&name)),
                })
                .collect())
        }
        _ => Err(Error::Usage(
            "give either -o OUT (one photo) or --out-dir DIR (one or more photos)".into(),
        )),
    }
}

/// Each photo's output name: its file stem, or `STEM-K` (K its position from 1) when another
/// photo has the same stem.
pub fn names(photos: &[PathBuf]) -> Vec<String> {
    let stem = |p: &PathBuf| {
        p.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "photo".into())
    };
    let mut count: HashMap<String, usize> = HashMap::new();
    for p in photos {
        *count.entry(stem(p)).or_default() += 1;
    }
    let mut taken: Vec<String> = Vec::new();
    for (i, p) in photos.iter().enumerate() {
        let s = stem(p);
        let mut name = if count[&s] > 1 {
            format!("{s}-{}", i + 1)
        } else {
            s
        };
        // A stem that already looks like "STEM-K": add more until it is new.
        while taken.contains(&name)
            || (count.contains_key(&name) && count[&name] == 1 && name != stem(p))
        {
            name.push('_');
        }
        taken.push(name);
    }
    taken
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(list: &[&str]) -> Vec<PathBuf> {
        list.iter().map(PathBuf::from).collect()
    }

    #[test]
    fn names_are_the_stems_and_never_collide() {
        assert_eq!(names(&paths(&["a/x.png", "b/y.jpg"])), ["x", "y"]);
        assert_eq!(names(&paths(&["a/x.png", "b/x.png"])), ["x-1", "x-2"]);
        // "x-2" is a photo's own stem as well as the second "x"'s name.
        let tricky = names(&paths(&["a/x.png", "b/x.png", "x-2.png"]));
        let mut unique = tricky.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), 3, "{tricky:?}");
    }
}
