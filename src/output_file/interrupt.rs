//! The temporary files alive in the process, and the interrupt handler that removes them: on
//! SIGINT or SIGTERM the run stops, its temporaries are removed and the process exits with
//! 128 + the signal's number (130, 143). Committing a run's outputs holds the same lock, so
//! an interrupt arriving meanwhile waits until every output is in place: a reader finds
//! either the old outputs or the new ones, complete.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The live temporaries; holding this keeps the interrupt handler waiting.
pub(crate) fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Forgets `path` (renamed into place or removed).
pub(crate) fn forget(live: &mut Vec<PathBuf>, path: &std::path::Path) {
    live.retain(|p| p != path);
}

/// Installs the handler (once, at the start of the command). Does nothing where signals are
/// not available.
pub fn install() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let live = live();
                for path in live.iter() {
                    let _ = std::fs::remove_file(path);
                }
                eprintln!(
                    "streaklight: interrupted; {} temporary file(s) removed, no output half-written",
                    live.len()
                );
                // Exits with the lock held: no rename can follow.
                std::process::exit(128 + signal);
            }
        });
    }
}
