//! Writing outputs safely: never over an input or another output, never half-written,
//! nothing left behind by a refused or interrupted run (see [`Run`]).

mod identity;
pub mod interrupt;
mod run;

use std::io::Write;
use std::path::Path;

use crate::{Error, Result};

pub use identity::{identity, FileId};
pub use run::{record_input, Run};

/// Environment variable, a test hook: milliseconds to pause after each output is written to
/// its temporary file and before a run's outputs are renamed into place, so that tests can
/// interrupt the write stage at a known point. Unset (the default), there is no pause.
pub const TEST_PAUSE_VAR: &str = "STREAKLIGHT_TEST_PAUSE_MS";

pub(crate) fn test_pause() {
    if let Some(ms) = std::env::var(TEST_PAUSE_VAR)
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms));
    }
}

/// Refuses an output path that names one of the inputs (the same file, however spelled).
pub fn ensure_not_an_input(output: &Path, inputs: &[&Path]) -> Result<()> {
    let out = identity(output);
    for input in inputs {
        if identity(input) == out {
            return Err(Error::output(
                output,
                format!(
                    "the output path is the input file {}; choose another output so the input is not overwritten",
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses outputs of one run that name the same file (however spelled).
pub fn ensure_distinct(outputs: &[&Path]) -> Result<()> {
    for (i, a) in outputs.iter().enumerate() {
        let id = identity(a);
        if let Some(b) = outputs[..i].iter().find(|b| identity(b) == id) {
            return Err(Error::output(
                a,
                format!(
                    "this run also writes {} and it is the same file; name the outputs apart",
                    b.display()
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses, before any work, an output path whose folder does not exist (or is not a folder),
/// or that is itself a folder.
pub fn ensure_folder_exists(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::output(
            path,
            "this is a folder; give the path of a file to write",
        ));
    }
    let dir = folder_of(path);
    if !dir.is_dir() {
        let what = if dir.exists() {
            "is not a folder"
        } else {
            "does not exist"
        };
        return Err(Error::output(
            path,
            format!("the folder {} {what}", dir.display()),
        ));
    }
    Ok(())
}

/// The folder a path is in ("." for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Refuses, before any work, an output whose folder does not let us create files (read-only
/// folder or disk, no permission): found out only at the end, it would leave one output
/// written and the next one not. Creates and removes a temporary file as
/// [`write_atomically`] would.
pub fn ensure_writable(path: &Path) -> Result<()> {
    ensure_folder_exists(path)?;
    probe(folder_of(path))
        .map_err(|e| Error::output(path, format!("cannot create a file in its folder ({e})")))
}

fn probe(dir: &Path) -> std::io::Result<()> {
    tempfile::Builder::new()
        .prefix(".streaklight-probe.")
        .tempfile_in(dir)
        .map(drop)
}

/// Refuses, before any work, a folder of outputs (`--debug-dir`, `--out-dir`) that cannot be
/// one: a file, or a folder (or, when missing, its nearest existing parent) where no file can
/// be created.
pub fn ensure_folder_writable(dir: &Path) -> Result<()> {
    let mut existing = dir;
    while !existing.exists() {
        match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => existing = p,
            _ => {
                existing = Path::new(".");
                break;
            }
        }
    }
    if !existing.is_dir() {
        let message = if existing == dir {
            "this is a file, not a folder; give a folder for the outputs".to_string()
        } else {
            format!("{} is a file, not a folder", existing.display())
        };
        return Err(Error::output(dir, message));
    }
    probe(existing).map_err(|e| {
        Error::output(
            dir,
            format!("cannot create files in {} ({e})", existing.display()),
        )
    })
}

/// Creates `dir` and its missing parents; in an open run, the ones it creates are removed
/// again if the run is not committed.
pub fn create_dir_all(dir: &Path) -> Result<()> {
    let mut missing = Vec::new();
    let mut d = dir;
    while !d.as_os_str().is_empty() && !d.exists() {
        missing.push(d.to_path_buf());
        match d.parent() {
            Some(p) => d = p,
            None => break,
        }
    }
    for m in missing.iter().rev() {
        match std::fs::create_dir(m) {
            Ok(()) => run::add_created_dir(m),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && m.is_dir() => {}
            Err(e) => return Err(Error::io(m, e)),
        }
    }
    if !dir.is_dir() {
        return Err(Error::output(dir, "this is a file, not a folder"));
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically: into a new temporary file in the same folder (created
/// exclusively under an unpredictable name), flushed to disk, then renamed over `path`. In an
/// open [`Run`], the rename waits for [`Run::commit`], and `path` is refused if the run read
/// it or writes it already. A failure leaves no file behind.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write(path, bytes, false)
}

/// As [`write_atomically`], for a file that refers to the run's other outputs (a `.gltf`
/// scene to its side files): committed after them.
pub fn write_atomically_last(path: &Path, bytes: &[u8]) -> Result<()> {
    write(path, bytes, true)
}

fn write(path: &Path, bytes: &[u8], last: bool) -> Result<()> {
    ensure_folder_exists(path)?;
    run::check_target(path)?;
    let temp = write_temporary(path, bytes)?;
    place(path, temp, last)
}

/// `bytes` in a new temporary file beside `path` (created exclusively under an unpredictable
/// name, registered for the interrupt handler), flushed to disk. A failure leaves no file.
fn write_temporary(path: &Path, bytes: &[u8]) -> Result<tempfile::TempPath> {
    let name = path
        .file_name()
        .ok_or_else(|| Error::output(path, "the output path names no file"))?;
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    // Created and registered under the lock: an interrupt finds every temporary.
    let mut live = interrupt::live();
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp-streaklight");
    // As a file created the ordinary way (0666 less the umask), not a temporary's 0600.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let temp = builder
        .tempfile_in(folder_of(path))
        .map_err(|e| Error::io(path, e))?;
    let temp_path = temp.path().to_path_buf();
    live.push(temp_path.clone());
    drop(live);
    let written = (|| -> std::io::Result<tempfile::TempPath> {
        let mut temp = temp;
        temp.write_all(bytes)?;
        temp.as_file().sync_all()?;
        Ok(temp.into_temp_path())
    })();
    written.map_err(|e| {
        // The temporary was dropped, and so removed, inside the closure.
        interrupt::forget(&mut interrupt::live(), &temp_path);
        Error::io(path, e)
    })
}

/// Puts a written temporary in place as `path`: in the open run, at its commit; else now.
fn place(path: &Path, temp: tempfile::TempPath, last: bool) -> Result<()> {
    if run::is_open() {
        run::add_pending(path, temp, last);
        test_pause();
        return Ok(());
    }
    let temp_path = temp.to_path_buf();
    let mut live = interrupt::live();
    let result = temp.persist(path);
    interrupt::forget(&mut live, &temp_path);
    result.map_err(|e| Error::io(path, e.error))
}

/// A file written ahead of its place: its bytes in a temporary beside it, flushed to disk, so
/// that a long run's large outputs that do not depend on its result (the copies of a scene's
/// buffers) reach the disk while it works. [`WrittenAhead::place`] puts it in place as
/// [`write_atomically`] would; dropped instead, the temporary is removed.
pub struct WrittenAhead {
    path: std::path::PathBuf,
    temp: Option<tempfile::TempPath>,
}

impl WrittenAhead {
    /// Writes `bytes` for `path`, whose folder must exist already (on any thread: no run is
    /// consulted until [`Self::place`]).
    pub fn write(path: &Path, bytes: &[u8]) -> Result<Self> {
        if !folder_of(path).is_dir() {
            return Err(Error::output(path, "its folder does not exist yet"));
        }
        Ok(WrittenAhead {
            path: path.to_path_buf(),
            temp: Some(write_temporary(path, bytes)?),
        })
    }

    /// The file it will be.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Puts the file in place as [`write_atomically`] would (checked against the open run's
    /// inputs and outputs, renamed at its commit).
    pub fn place(mut self) -> Result<()> {
        run::check_target(&self.path)?;
        match self.temp.take() {
            Some(temp) => place(&self.path, temp, false),
            None => Ok(()),
        }
    }
}

impl Drop for WrittenAhead {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            let temp_path = temp.to_path_buf();
            let mut live = interrupt::live();
            drop(temp);
            interrupt::forget(&mut live, &temp_path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn refuses_an_output_in_a_folder_it_cannot_write() {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("streaklight-ro-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.json");
        assert!(ensure_writable(&path).is_ok());
        assert!(
            std::fs::read_dir(&dir).unwrap().next().is_none(),
            "probe left behind"
        );
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
        // Root writes anywhere: then there is nothing to refuse.
        let root = std::fs::write(dir.join("probe"), b"x").is_ok();
        let result = ensure_writable(&path);
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        if !root {
            let message = result.expect_err("read-only folder").to_string();
            assert!(message.contains("out.json"), "{message}");
            assert!(message.contains("cannot create a file"), "{message}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refuses_output_equal_to_input_spelled_differently() {
        let dir = std::env::temp_dir().join(format!("streaklight-of-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("a.gltf");
        std::fs::write(&input, b"{}").unwrap();
        let other = dir.join(".").join("a.gltf");
        assert!(ensure_not_an_input(&other, &[&input]).is_err());
        assert!(ensure_not_an_input(&dir.join("b.gltf"), &[&input]).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn outputs_get_the_permissions_of_an_ordinary_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let ordinary = dir.path().join("ordinary");
        std::fs::write(&ordinary, b"x").unwrap();
        let ours = dir.path().join("ours");
        write_atomically(&ours, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&ours), mode(&ordinary));
    }

    #[test]
    fn a_run_commits_together_or_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("sub/b"));
        {
            let _run = Run::begin();
            create_dir_all(&dir.path().join("sub")).unwrap();
            write_atomically(&a, b"a").unwrap();
            write_atomically(&b, b"b").unwrap();
            // Not committed: dropped.
        }
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
        let run = Run::begin();
        write_atomically(&a, b"a").unwrap();
        assert!(!a.exists(), "renamed before the commit");
        let again = write_atomically(&dir.path().join(".").join("a"), b"c");
        assert!(again.unwrap_err().to_string().contains("same file"));
        assert_eq!(run.commit().unwrap(), vec![a.clone()]);
        assert_eq!(std::fs::read(&a).unwrap(), b"a");
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("streaklight-aw-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        write_atomically(&path, b"one").unwrap();
        write_atomically(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let entries: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(entries.len(), 1);
        assert!(write_atomically(&dir.join("missing").join("x"), b"x").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
