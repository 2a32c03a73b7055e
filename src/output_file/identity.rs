//! Which file a path names, however it is spelled: the device and inode of an existing file
//! (through symlinks, `..`, hard links), else the canonical path of its folder and its name.

use std::path::{Path, PathBuf};

/// The identity of the file a path names (or would name once written).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum FileId {
    /// An existing file: its device and inode.
    Inode(u64, u64),
    /// A file that does not exist (yet): its folder's canonical path joined with its name.
    Path(PathBuf),
}

/// The identity of the file at `path`.
pub fn identity(path: &Path) -> FileId {
    #[cfg(unix)]
    if let Ok(meta) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return FileId::Inode(meta.dev(), meta.ino());
    }
    #[cfg(not(unix))]
    if let Ok(p) = path.canonicalize() {
        return FileId::Path(p);
    }
    FileId::Path(canonical_or_absolute(path))
}

/// `path` with its folder resolved (the file itself need not exist).
pub(crate) fn canonical_or_absolute(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    match parent.map(|p| p.canonicalize()) {
        Some(Ok(dir)) => dir.join(name),
        None => std::env::current_dir()
            .map(|d| d.join(&name))
            .unwrap_or(name),
        // The folder does not exist either: resolve what does, keep the rest as written.
        Some(Err(_)) => match parent {
            Some(p) => canonical_or_absolute(p).join(name),
            None => path.to_path_buf(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_and_links_of_one_file_are_one_identity() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.bin");
        std::fs::write(&a, b"x").unwrap();
        assert_eq!(identity(&a), identity(&dir.path().join(".").join("a.bin")));
        std::fs::hard_link(&a, dir.path().join("b.bin")).unwrap();
        assert_eq!(identity(&a), identity(&dir.path().join("b.bin")));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.path(), dir.path().join("via")).unwrap();
            assert_eq!(identity(&a), identity(&dir.path().join("via/a.bin")));
            // A file yet to be written, through the symlinked folder.
            assert_eq!(
                identity(&dir.path().join("new.bin")),
                identity(&dir.path().join("via/new.bin"))
            );
        }
        assert_ne!(identity(&a), identity(&dir.path().join("c.bin")));
        assert_eq!(
            identity(&dir.path().join("x/y/z.bin")),
            identity(&dir.path().join("x/./y/z.bin"))
        );
    }
}
