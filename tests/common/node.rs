//! Running the Node scripts of `tests/engines/` (headless Chromium through playwright-core).

use std::path::Path;
use std::process::Command;

/// The folder of the Node scripts.
pub const ENGINES_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/engines");

/// What to do when Node, its packages or Chromium are missing.
pub const INSTALL: &str = "run `scripts/test`, which installs Node.js, Debian's Chromium and \
     `npm ci --prefix tests/engines` (and `--prefix examples/threejs`)";

/// Runs `node tests/engines/SCRIPT ARGS...`; panics with its output unless it succeeds.
/// Returns its stdout.
pub fn run_node(script: &str, args: &[(&str, &Path)], dir: &Path) -> String {
    let mut command = Command::new("node");
    command.arg(Path::new(ENGINES_DIR).join(script));
    for (flag, value) in args {
        command.arg(flag).arg(value);
    }
    let run = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run `node` ({e}): {INSTALL}"));
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    println!("{stdout}{stderr}");
    assert!(
        run.status.success(),
        "{script} failed ({}); files in {}:\n{stdout}{stderr}\n(if something is missing: {INSTALL})",
        run.status,
        dir.display()
    );
    stdout.into_owned()
}
