//! Class 2: temporaries are created exclusively under unpredictable names, so a symlink planted
//! at any name the run uses is never followed; an interrupt (SIGINT, SIGTERM) at any point of
//! the write stage removes them and leaves either the old outputs or the new ones, complete.
//! The pause between files is the documented test hook `STREAKLIGHT_TEST_PAUSE_MS`.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::cli::arg;
use crate::support::{case, fit, run_with, temporaries, Case};

/// The files a `-o out.gltf --report report.json` fit of a case writes.
const OUTPUTS: [&str; 4] = [
    "out.gltf",
    "out.buffer0.bin",
    "out.streaklight.bin",
    "report.json",
];

/// The `fit` of case `c` that writes [`OUTPUTS`], with `seed`: the paper's method, a few
/// times quicker than the joint fit, since only the write stage is under test.
fn outputs_fit(c: &Case, seed: &str) -> Vec<String> {
    let out = arg(&c.dir.join(OUTPUTS[0]));
    let report = arg(&c.dir.join(OUTPUTS[3]));
    fit(
        &c.scene,
        &c.photo,
        &[
            "-o", &out, "--report", &report, "--seed", seed, "--method", "paper",
        ],
    )
}

#[cfg(unix)]
#[test]
fn symlinks_planted_at_every_output_name_are_never_followed() {
    let c = case("hostile-planted-links");
    let victims = c.dir.join("victims");
    std::fs::create_dir(&victims).unwrap();
    for name in OUTPUTS {
        let victim = victims.join(name);
        std::fs::write(&victim, b"precious").unwrap();
        std::os::unix::fs::symlink(&victim, c.dir.join(name)).unwrap();
    }
    let ran = run_with(&outputs_fit(&c, "1"), &[], 60.0);
    assert_eq!(ran.code, Some(0), "{}", ran.stderr);
    for name in OUTPUTS {
        assert_eq!(
            std::fs::read(victims.join(name)).unwrap(),
            b"precious",
            "{name}"
        );
        let meta = std::fs::symlink_metadata(c.dir.join(name)).unwrap();
        assert!(meta.is_file(), "{name} is still a link");
    }
    assert!(temporaries(&c.dir).is_empty());
}

/// The bytes of the outputs that do not hold timings (the report does).
fn scene_files(dir: &Path) -> Vec<Option<Vec<u8>>> {
    OUTPUTS[..3]
        .iter()
        .map(|n| std::fs::read(dir.join(n)).ok())
        .collect()
}

/// Runs the fit with a pause after each file, sends `signal` once `temps` temporaries have
/// appeared (0: at once after the last rename's pause began), and returns the exit code.
fn interrupted(dir: &Path, args: &[String], temps: usize, signal: i32) -> Option<i32> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .args(args)
        .env("STREAKLIGHT_TEST_PAUSE_MS", "400")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temporaries(dir).len() < temps && start.elapsed() < Duration::from_secs(60) {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    // In the middle of the pause that follows the file.
    std::thread::sleep(Duration::from_millis(150));
    // SAFETY: kill(2) on the child's own process id.
    unsafe {
        libc::kill(child.id() as i32, signal);
    }
    child.wait().unwrap().code()
}

#[cfg(unix)]
#[test]
fn an_interrupt_in_the_write_stage_leaves_old_or_new_outputs_complete() {
    let c = case("hostile-interrupt");
    let args_for = |seed: &str| outputs_fit(&c, seed);
    // The new outputs, as an uninterrupted run writes them.
    let reference = run_with(&args_for("2"), &[], 60.0);
    assert_eq!(reference.code, Some(0), "{}", reference.stderr);
    let new = scene_files(&c.dir);
    for (temps, signal) in [
        (1, libc::SIGINT),
        (2, libc::SIGTERM),
        (3, libc::SIGINT),
        (4, libc::SIGINT),
    ] {
        let old_run = run_with(&args_for("1"), &[], 60.0);
        assert_eq!(old_run.code, Some(0), "{}", old_run.stderr);
        let old = scene_files(&c.dir);
        assert_ne!(old, new, "the seeds should give different outputs");
        let code = interrupted(&c.dir, &args_for("2"), temps, signal);
        let after = scene_files(&c.dir);
        assert!(
            temporaries(&c.dir).is_empty(),
            "temporaries left after a signal at {temps}: {:?}",
            temporaries(&c.dir)
        );
        assert!(
            after == old || after == new,
            "a mix of old and new outputs after a signal at {temps} (exit {code:?})"
        );
        if after == old {
            assert_eq!(code, Some(128 + signal), "signal at {temps}");
        }
    }
}
