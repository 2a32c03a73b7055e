//! How the command line shows progress. On a terminal: each stage as a line, and a bar under
//! it with the stage's name, its elapsed time and, for counted work, the count and the time
//! left. Elsewhere (a pipe, a log file): the stage lines, and counted work as a line at every
//! tenth with the time left. `--verbose` adds each stage's time as it ends; `--quiet` shows
//! nothing.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use streaklight::progress::Progress;

/// How much to show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verbosity {
    /// Nothing.
    Quiet,
    /// Stages and counted work.
    Normal,
    /// Also each stage's time.
    Verbose,
}

/// The stage being shown.
struct Current {
    name: String,
    started: Instant,
    bar: Option<indicatif::ProgressBar>,
    /// Tenths of counted work already told as lines (off a terminal).
    tenths_told: u64,
}

/// Progress on stderr.
pub struct Terminal {
    verbosity: Verbosity,
    terminal: bool,
    current: Mutex<Option<Current>>,
}

impl Terminal {
    /// Progress on stderr at `verbosity`, with bars when stderr is a terminal.
    pub fn new(verbosity: Verbosity) -> Self {
        Terminal {
            verbosity,
            terminal: std::io::stderr().is_terminal(),
            current: Mutex::new(None),
        }
    }

    /// Prints `line` on stderr, above the bar if one is shown.
    pub fn println(&self, line: &str) {
        let line = streaklight::names::for_terminal(line);
        let current = self.current.lock().unwrap_or_else(|e| e.into_inner());
        match current.as_ref().and_then(|c| c.bar.as_ref()) {
            Some(bar) => bar.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }

    /// Ends the current stage (its bar cleared, its time told when verbose).
    pub fn finish(&self) {
        let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(done) = current.take() {
            if let Some(bar) = done.bar {
                bar.finish_and_clear();
            }
            if self.verbosity == Verbosity::Verbose {
                eprintln!(
                    "  ({}: {:.2} s)",
                    done.name,
                    done.started.elapsed().as_secs_f64()
                );
            }
        }
    }

    fn spinner(name: &str) -> indicatif::ProgressBar {
        let bar = indicatif::ProgressBar::new_spinner();
        if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.set_message(name.to_owned());
        bar.enable_steady_tick(Duration::from_millis(120));
        bar
    }

    fn counted(bar: &indicatif::ProgressBar, total: u64) {
        bar.set_length(total);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len}, {elapsed} elapsed, ~{eta} left",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
    }
}

impl Progress for Terminal {
    fn stage(&self, line: &str) {
        if self.verbosity == Verbosity::Quiet {
            return;
        }
        self.finish();
        eprintln!("{}", streaklight::names::for_terminal(line));
        let bar = self.terminal.then(|| Self::spinner(line));
        let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
        *current = Some(Current {
            name: line.to_owned(),
            started: Instant::now(),
            bar,
            tenths_told: 0,
        });
    }

    fn advance(&self, done: u64, total: u64) {
        if self.verbosity == Verbosity::Quiet || total == 0 {
            return;
        }
        let mut current = self.current.lock().unwrap_or_else(|e| e.into_inner());
        let Some(c) = current.as_mut() else {
            return;
        };
        if let Some(bar) = &c.bar {
            if bar.length() != Some(total) {
                Self::counted(bar, total);
            }
            bar.set_position(done.min(total));
            return;
        }
        let tenths = (10 * done.min(total)) / total;
        if tenths > c.tenths_told && done > 0 {
            c.tenths_told = tenths;
            let elapsed = c.started.elapsed().as_secs_f64();
            let left = elapsed * (total - done.min(total)) as f64 / done as f64;
            eprintln!(
                "  {}: {done}/{total}, {elapsed:.1} s elapsed, ~{left:.1} s left",
                c.name
            );
        }
    }
}
