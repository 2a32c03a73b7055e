//! A run's outputs, written all together or not at all.
//!
//! While a [`Run`] is open on a thread, every output written through
//! [`write_atomically`](super::write_atomically) goes to a temporary file beside its target
//! (created exclusively, under an unpredictable name: a planted symlink is never followed),
//! and is checked against every file the run has read ([`record_input`]) and every other
//! output, by identity ([`super::identity`]). [`Run::commit`] renames the temporaries into
//! place, the scene files last (so a reader never sees a new scene with old side files);
//! dropping the run without committing removes the temporaries and the folders it created:
//! a refused run leaves the output folders as they were.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use super::identity::{identity, FileId};
use super::interrupt;
use crate::{Error, Result};

/// An output waiting in its temporary file.
struct Pending {
    target: PathBuf,
    id: FileId,
    temp: tempfile::TempPath,
    last: bool,
}

#[derive(Default)]
struct State {
    inputs: Vec<(FileId, PathBuf)>,
    pending: Vec<Pending>,
    /// Outputs already committed by this run (a batch commits photo by photo).
    committed: Vec<(FileId, PathBuf)>,
    created_dirs: Vec<PathBuf>,
}

thread_local! {
    static CURRENT: RefCell<Option<State>> = const { RefCell::new(None) };
}

/// The open run of this thread; see the module docs. Only the outermost `begin` on a thread
/// owns it and closes it when dropped; an inner one (a library function called by a command
/// that opened its own) shares it: its `commit` and `discard` act on the shared run, so a
/// function that may be called inside another's run commits only when it [`owns`](Run::owns)
/// the run.
#[must_use = "a run that is dropped without commit() removes everything it wrote"]
pub struct Run {
    owner: bool,
}

impl Run {
    /// Opens a run on this thread (or joins the one open).
    pub fn begin() -> Run {
        let owner = CURRENT.with(|c| {
            let mut c = c.borrow_mut();
            if c.is_some() {
                return false;
            }
            *c = Some(State::default());
            true
        });
        Run { owner }
    }

    /// Renames every pending output into place (scene files last) and returns their paths;
    /// the run stays open (its inputs and committed outputs are still protected). Interrupts
    /// wait until it is done.
    pub fn commit(&self) -> Result<Vec<PathBuf>> {
        let pending = CURRENT.with(|c| {
            let mut c = c.borrow_mut();
            let Some(state) = c.as_mut() else {
                return Vec::new();
            };
            state.created_dirs.clear();
            std::mem::take(&mut state.pending)
        });
        super::test_pause();
        let (first, last): (Vec<_>, Vec<_>) = pending.into_iter().partition(|p| !p.last);
        let mut live = interrupt::live();
        let mut done = Vec::new();
        let mut failure = None;
        for p in first.into_iter().chain(last) {
            if failure.is_some() {
                interrupt::forget(&mut live, &p.temp);
                continue; // dropping the TempPath removes it
            }
            let temp_path = p.temp.to_path_buf();
            match p.temp.persist(&p.target) {
                Ok(()) => {
                    interrupt::forget(&mut live, &temp_path);
                    done.push((p.id, p.target));
                }
                Err(e) => {
                    interrupt::forget(&mut live, &temp_path);
                    failure = Some(Error::io(&p.target, e.error));
                }
            }
        }
        drop(live);
        let paths = done.iter().map(|(_, p)| p.clone()).collect();
        CURRENT.with(|c| {
            if let Some(state) = c.borrow_mut().as_mut() {
                state.committed.extend(done);
            }
        });
        match failure {
            Some(e) => Err(e),
            None => Ok(paths),
        }
    }

    /// Removes every pending output and the folders created for them, keeping the run open
    /// (the next photo of a batch goes on).
    pub fn discard(&self) {
        CURRENT.with(|c| {
            if let Some(state) = c.borrow_mut().as_mut() {
                discard(state);
            }
        });
    }

    /// Whether this is the outermost `begin` of the thread's run.
    pub fn owns(&self) -> bool {
        self.owner
    }
}

impl Drop for Run {
    fn drop(&mut self) {
        if self.owner {
            CURRENT.with(|c| {
                if let Some(mut state) = c.borrow_mut().take() {
                    discard(&mut state);
                }
            });
        }
    }
}

fn discard(state: &mut State) {
    let mut live = interrupt::live();
    for p in state.pending.drain(..) {
        interrupt::forget(&mut live, &p.temp);
        drop(p.temp);
    }
    drop(live);
    // Deepest first; a folder something else was put into meanwhile stays.
    for dir in state.created_dirs.drain(..).rev() {
        let _ = std::fs::remove_dir(dir);
    }
}

/// Records `path` as an input of the open run: no output of the run may be written over it.
/// Without an open run, does nothing.
pub fn record_input(path: &Path) {
    CURRENT.with(|c| {
        if let Some(state) = c.borrow_mut().as_mut() {
            let id = identity(path);
            if !state.inputs.iter().any(|(i, _)| *i == id) {
                state.inputs.push((id, path.to_path_buf()));
            }
        }
    });
}

/// Refuses `output` when it is a file the open run read or writes (or has written).
pub(crate) fn check_target(output: &Path) -> Result<()> {
    let id = identity(output);
    CURRENT.with(|c| {
        let c = c.borrow();
        let Some(state) = c.as_ref() else {
            return Ok(());
        };
        if let Some((_, input)) = state.inputs.iter().find(|(i, _)| *i == id) {
            return Err(Error::output(
                output,
                format!(
                    "this is the input file {}; choose another output so the input is not \
                     overwritten",
                    input.display()
                ),
            ));
        }
        let other = state
            .pending
            .iter()
            .map(|p| (&p.id, &p.target))
            .chain(state.committed.iter().map(|(i, p)| (i, p)))
            .find(|(i, _)| **i == id);
        if let Some((_, earlier)) = other {
            return Err(Error::output(
                output,
                format!(
                    "this run also writes {} and it is the same file; name the outputs apart",
                    earlier.display()
                ),
            ));
        }
        Ok(())
    })
}

/// Whether a run is open on this thread.
pub(crate) fn is_open() -> bool {
    CURRENT.with(|c| c.borrow().is_some())
}

/// Hands a written temporary to the open run, to be renamed to `target` at commit.
pub(crate) fn add_pending(target: &Path, temp: tempfile::TempPath, last: bool) {
    let id = identity(target);
    CURRENT.with(|c| {
        if let Some(state) = c.borrow_mut().as_mut() {
            state.pending.push(Pending {
                target: target.to_path_buf(),
                id,
                temp,
                last,
            });
        }
    });
}

/// Records a folder the open run created, to be removed if the run is not committed.
pub(crate) fn add_created_dir(dir: &Path) {
    CURRENT.with(|c| {
        if let Some(state) = c.borrow_mut().as_mut() {
            state.created_dirs.push(dir.to_path_buf());
        }
    });
}
