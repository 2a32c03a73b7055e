//! How long work tells where it is: one reporter type for every stage of the library (the
//! pipeline's stages, the joint fit's repeats and refits, the gloss search's evaluations, the
//! renderer's rows).
//!
//! The library only says what happens; what to do with it (a line on stderr, a progress bar
//! on a terminal, nothing at all) is the caller's. A reporter is any `Fn(&str) + Sync`
//! closure (it may hold state: a counter, a log, a channel), or a type implementing
//! [`Progress`] for finer control over counted work.

/// Receives the progress of long work. Every method has a default that does nothing, so an
/// implementation overrides what it shows. Called from worker threads too, hence `Sync`.
pub trait Progress: Sync {
    /// A stage starts: `line` says what it is, for a person ("joint fit of 2 light(s)").
    fn stage(&self, line: &str) {
        let _ = line;
    }

    /// Counted work within the current stage: `done` of `total` steps are finished (for
    /// example rendered rows). Called with `done == 0` first and `done == total` last.
    fn advance(&self, done: u64, total: u64) {
        let _ = (done, total);
    }
}

/// Any `Fn(&str) + Sync` closure reports stages.
impl<F: Fn(&str) + Sync> Progress for F {
    fn stage(&self, line: &str) {
        self(line)
    }
}

/// The reporter that shows nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {}

/// A `&'static` silent reporter, the default of every options struct that holds one.
pub static SILENT: Silent = Silent;

/// A reporter borrowed by options structs: `Copy`, and silent by default.
#[derive(Clone, Copy)]
pub struct Reporter<'a>(pub &'a dyn Progress);

impl<'a> Reporter<'a> {
    /// Reports to `progress`.
    pub fn new(progress: &'a dyn Progress) -> Self {
        Reporter(progress)
    }

    /// A stage starts.
    pub fn stage(&self, line: &str) {
        self.0.stage(line)
    }

    /// `done` of `total` steps of the current stage are finished.
    pub fn advance(&self, done: u64, total: u64) {
        self.0.advance(done, total)
    }
}

impl Default for Reporter<'_> {
    fn default() -> Self {
        Reporter(&SILENT)
    }
}

impl std::fmt::Debug for Reporter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Reporter")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn a_closure_with_state_receives_every_stage_in_order() {
        let seen = Mutex::new(Vec::new());
        let record = |line: &str| seen.lock().unwrap().push(line.to_owned());
        let reporter = Reporter::new(&record);
        reporter.stage("load scene");
        reporter.advance(1, 2); // a closure ignores counted work
        reporter.stage("streaks");
        assert_eq!(*seen.lock().unwrap(), ["load scene", "streaks"]);
    }

    #[test]
    fn counted_work_reaches_a_reporter_that_wants_it() {
        struct Counter(Mutex<Vec<(u64, u64)>>);
        impl Progress for Counter {
            fn advance(&self, done: u64, total: u64) {
                self.0.lock().unwrap().push((done, total));
            }
        }
        let counter = Counter(Mutex::new(Vec::new()));
        let reporter = Reporter::new(&counter);
        reporter.stage("render"); // the default stage() ignores it
        reporter.advance(0, 3);
        reporter.advance(3, 3);
        assert_eq!(*counter.0.lock().unwrap(), [(0, 3), (3, 3)]);
        Reporter::default().stage("nobody hears this");
    }
}
