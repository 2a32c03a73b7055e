//! Writing outputs safely: never over an input, never half-written.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Refuses an output path that names one of the inputs (the same file, however spelled).
pub fn ensure_not_an_input(output: &Path, inputs: &[&Path]) -> Result<()> {
    let out = canonical_or_absolute(output);
    for input in inputs {
        if canonical_or_absolute(input) == out {
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

fn canonical_or_absolute(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    // The file does not exist yet: resolve its folder, which may.
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    match parent.map(|p| p.canonicalize()) {
        Some(Ok(dir)) => dir.join(name),
        None => std::env::current_dir()
            .map(|d| d.join(&name))
            .unwrap_or(name),
        Some(Err(_)) => path.to_path_buf(),
    }
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
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
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

/// Refuses, before any work, an output whose folder does not let us create files (read-only
/// folder or disk, no permission): found out only at the end, it would leave one output
/// written and the next one not. Creates and removes the temporary file that
/// [`write_atomically`] would use.
pub fn ensure_writable(path: &Path) -> Result<()> {
    let tmp = temporary_path(path)?;
    match std::fs::File::create(&tmp) {
        Ok(_) => {
            let _ = std::fs::remove_file(&tmp);
            Ok(())
        }
        Err(e) => Err(Error::output(
            path,
            format!("cannot create a file in its folder ({e})"),
        )),
    }
}

/// The temporary file beside `path` that [`write_atomically`] writes first.
fn temporary_path(path: &Path) -> Result<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(Error::output(
            path,
            format!("the folder {} does not exist", dir.display()),
        ));
    }
    let name = path
        .file_name()
        .ok_or_else(|| Error::output(path, "the output path names no file"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".{}.tmp-streaklight", std::process::id()));
    Ok(dir.join(tmp_name))
}

/// Writes `bytes` to `path` atomically: into a temporary file in the same folder, flushed to
/// disk, then renamed over `path`. A failure leaves no partial file behind.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temporary_path(path)?;
    let result = (|| -> std::io::Result<()> {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    Ok(())
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
