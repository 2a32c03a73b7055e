//! Child processes of the speed bench: wall time, peak memory and the load around them.

use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// What one child process took.
pub struct Measured {
    /// Wall seconds from spawn to exit.
    pub wall: f64,
    /// Peak resident memory (MiB).
    pub peak_mib: f64,
    /// Its standard output.
    pub stdout: String,
    /// The 1-minute load average before and after.
    pub load: (f64, f64),
}

/// The 1-minute load average.
pub fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(f64::NAN)
}

/// Runs `cmd` to its end, its standard error into `log`; its wall time and peak memory.
pub fn run(cmd: &mut Command, log: &Path) -> Result<Measured, String> {
    let what = format!("{cmd:?}");
    let stderr = File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let load_before = load_average();
    let start = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::from(stderr))
        .spawn()
        .map_err(|e| format!("{what}: {e}"))?;
    let mut stdout = String::new();
    if let Some(mut out) = child.stdout.take() {
        let _ = out.read_to_string(&mut stdout);
    }
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill in.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // wait4 gives this child's own peak memory (RUSAGE_CHILDREN would be the largest of all
    // children so far); the child is reaped here, so `child` is not waited for again.
    // SAFETY: the pid is our unreaped child's; status and usage are valid for writes.
    let waited = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    let wall = start.elapsed().as_secs_f64();
    if waited < 0 {
        return Err(format!("{what}: wait4 failed"));
    }
    if !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 {
        let tail = std::fs::read_to_string(log).unwrap_or_default();
        let tail: Vec<&str> = tail.lines().rev().take(3).collect();
        return Err(format!(
            "{what} failed: {}",
            tail.into_iter().rev().collect::<Vec<_>>().join(" / ")
        ));
    }
    Ok(Measured {
        wall,
        peak_mib: usage.ru_maxrss as f64 / 1024.0,
        stdout,
        load: (load_before, load_average()),
    })
}
