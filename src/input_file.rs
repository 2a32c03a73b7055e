//! Reading an input file, bounded: only regular files (a FIFO, a device such as `/dev/zero`
//! or a folder is refused at once, never waited on or read without end), and at most
//! [`crate::limits::max_input_bytes`] bytes.

use std::io::Read;
use std::path::Path;

use crate::{Error, Result};

fn refused(path: &Path, message: String) -> Error {
    Error::io(
        path,
        std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
    )
}

/// What kind of thing a non-regular file is, in words.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// Opens `path` without blocking (opening a FIFO with no writer would wait forever).
fn open(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// Reads the whole regular file at `path`; refuses anything else, and a file larger than the
/// input limit, with a message naming the file.
pub fn read(path: &Path) -> Result<Vec<u8>> {
    let limit = crate::limits::max_input_bytes()?;
    let file = open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(refused(
            path,
            format!(
                "is {}; streaklight reads only regular files",
                kind_of(&meta)
            ),
        ));
    }
    let too_large = || {
        refused(
            path,
            format!(
                "is larger than the input limit of {} MiB; set the environment variable {} to \
                 raise it",
                limit >> 20,
                crate::limits::MAX_INPUT_MB_VAR
            ),
        )
    };
    if meta.len() > limit {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    // A file that grows while it is read stops at the limit all the same.
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    crate::output_file::record_input(path);
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_and_devices_are_refused_by_kind() {
        let dir = std::env::temp_dir();
        let e = read(&dir).unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
        #[cfg(unix)]
        {
            let e = read(Path::new("/dev/zero")).unwrap_err().to_string();
            assert!(e.contains("/dev/zero: is a device"), "{e}");
        }
    }
}
