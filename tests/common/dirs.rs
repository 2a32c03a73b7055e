//! Temporary folders for the tests, and what is in a folder.

use std::path::{Path, PathBuf};

/// A fresh, empty folder for one test: `streaklight-tests/NAME-PID` in the system's temporary
/// folder (the process id keeps concurrent test binaries apart). The first call of a test
/// binary removes the folders of test processes that have ended ([`remove_ended`]).
pub fn temp_dir(name: &str) -> PathBuf {
    static CLEARED: std::sync::Once = std::sync::Once::new();
    let root = std::env::temp_dir().join("streaklight-tests");
    CLEARED.call_once(|| remove_ended(&root));
    let dir = root.join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Removes the folders under `root` named `NAME-PID` whose process has ended, where the
/// system lists its processes under `/proc`: a test binary cannot remove its own folders
/// when it exits (the sample scenes alone are some 75 MB a binary), so each run clears the
/// runs before it. A folder of a live process, or of a process id in use again, stays.
fn remove_ended(root: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(root) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let pid = name
            .rsplit_once('-')
            .and_then(|(_, p)| p.parse::<u32>().ok());
        if let Some(pid) = pid {
            if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
}

/// The names of the files in `dir`, sorted (none when `dir` cannot be read).
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// The paths of the entries of `dir`, sorted.
pub fn sorted_paths(dir: &Path) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    paths
}
