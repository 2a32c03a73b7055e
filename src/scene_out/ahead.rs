//! A `.gltf` output's copies of the input's files, written while the fit runs.
//!
//! The copies (the input's buffers and images beside the output, [`super::side_files`]) do
//! not depend on the fit, yet they are most of what writing the output costs: the sample
//! scene's 12 MB buffer, written and flushed to disk, took 0.02-0.23 s after a 0.9 s fit.
//! [`CopiesAhead::start`] stages the output and writes its copies to temporaries on a thread
//! of their own from the start; [`super::write_lit_scene_with`] then puts them in place with
//! the rest. When anything about that goes wrong (the folder is not there yet, a write
//! fails), the output is staged and written at the end as without it, which reports the
//! problem if there is one.

use std::path::{Path, PathBuf};
use std::thread::JoinHandle;

use super::staged::{self, Staged};
use super::InputFiles;
use crate::output_file::WrittenAhead;

/// The output staged, and its copies written, on a thread started before the fit (see the
/// module doc). Dropped unused, it waits for the thread and removes what it wrote.
pub struct CopiesAhead {
    /// What it was started for: a write of anything else does not take it.
    input: PathBuf,
    output: PathBuf,
    files: InputFiles,
    thread: Option<JoinHandle<Option<Ahead>>>,
}

/// What the thread made: the staged output (its copies taken out) and the copies written.
pub(super) struct Ahead {
    pub(super) staged: Staged,
    pub(super) written: Vec<WrittenAhead>,
}

impl CopiesAhead {
    /// Starts staging `input` as `output` and writing its copies. Only a `.gltf` output that
    /// copies the input's files has any; for the others there is nothing to start.
    pub fn start(input: &Path, output: &Path, files: InputFiles) -> Self {
        let copies = files == InputFiles::Copy
            && output
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
        let (input, output) = (input.to_path_buf(), output.to_path_buf());
        let (for_input, for_output) = (input.clone(), output.clone());
        // A thread the system refuses leaves the copies to the end.
        let thread = copies.then(|| {
            std::thread::Builder::new()
                .name("copies ahead".into())
                .spawn(move || {
                    yield_to_the_fit();
                    let mut staged = staged::stage(&input, &output, files).ok()?;
                    let side = staged.take_side();
                    let written = side
                        .iter()
                        .map(|(path, bytes)| WrittenAhead::write(path, bytes))
                        .collect::<crate::Result<Vec<_>>>()
                        .ok()?;
                    Some(Ahead { staged, written })
                })
        });
        CopiesAhead {
            input: for_input,
            output: for_output,
            files,
            thread: thread.and_then(Result::ok),
        }
    }

    /// What the thread made for writing `input` as `output` with `files`, once it is done;
    /// `None` when it made nothing usable, or was started for another write (what it wrote
    /// is then removed).
    pub(super) fn finish(
        mut self,
        input: &Path,
        output: &Path,
        files: InputFiles,
    ) -> Option<Ahead> {
        if (self.input.as_path(), self.output.as_path(), self.files) != (input, output, files) {
            return None;
        }
        self.thread.take()?.join().ok().flatten()
    }
}

/// Lowers this thread's priority to the least: writing and flushing the copies takes
/// processor time (0.03-0.12 s of the kernel's for the sample scene's 12 MB buffer), which
/// the fit's own threads should have first.
fn yield_to_the_fit() {
    #[cfg(target_os = "linux")]
    // SAFETY: plain system calls on integers; on Linux a thread id with PRIO_PROCESS sets that
    // thread's niceness alone. A failure leaves the priority as it was.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t, 19);
    }
}

impl Drop for CopiesAhead {
    fn drop(&mut self) {
        // Its temporaries are removed as what it made is dropped.
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
