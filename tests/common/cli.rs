//! Running the `streaklight` command line.

use std::ffi::OsStr;
use std::path::Path;

/// The `--exposure` of the test photos (see `fit_case::EXPOSURE`).
pub const EXPOSURE_ARG: &str = "0.1";

/// The `--samples` of test fits: fewer lobe samples than the default keep every run to a
/// second or two.
pub const SAMPLES_ARG: &str = "64";

/// Runs the streaklight binary; returns (exit success, stdout, stderr).
pub fn run_cli<S: AsRef<OsStr>>(args: &[S]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs the streaklight binary and asserts that it did not panic; returns (exit code, stdout,
/// stderr).
pub fn run_cli_code<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic on {args:?}: {stderr}");
    (
        out.status.code().expect("an exit code"),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr,
    )
}

/// `p` as a command-line argument.
pub fn arg(p: &Path) -> String {
    p.to_str().unwrap().to_owned()
}

/// The `fit` arguments for `scene`, `photo`, `out`, a report, the test photos' exposure,
/// [`SAMPLES_ARG`] lobe samples, and `extra`.
pub fn fit_args(
    scene: &Path,
    photo: &Path,
    out: &Path,
    report: &Path,
    extra: &[&str],
) -> Vec<String> {
    let mut args = vec![
        "fit".to_owned(),
        arg(scene),
        arg(photo),
        "-o".into(),
        arg(out),
        "--report".into(),
        arg(report),
        "--exposure".into(),
        EXPOSURE_ARG.into(),
        "--samples".into(),
        SAMPLES_ARG.into(),
    ];
    args.extend(extra.iter().map(|a| a.to_string()));
    args
}
