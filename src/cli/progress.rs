//! How the command line shows progress: each stage as a line on stderr, and counted work
//! (rendered rows) as a bar when stderr is a terminal.

use std::io::IsTerminal;
use std::sync::Mutex;

use streaklight::progress::Progress;

/// Lines on stderr, and a bar for counted work on a terminal.
pub struct Terminal {
    bar: Mutex<Option<indicatif::ProgressBar>>,
    terminal: bool,
    /// The name of the current stage, shown in the bar.
    stage: Mutex<String>,
}

impl Terminal {
    /// A reporter on stderr.
    pub fn new() -> Self {
        Terminal {
            bar: Mutex::new(None),
            terminal: std::io::stderr().is_terminal(),
            stage: Mutex::new(String::new()),
        }
    }
}

impl Progress for Terminal {
    fn stage(&self, line: &str) {
        if let Ok(mut bar) = self.bar.lock() {
            if let Some(b) = bar.take() {
                b.finish_and_clear();
            }
        }
        if let Ok(mut stage) = self.stage.lock() {
            *stage = line.to_owned();
        }
        eprintln!("{line}");
    }

    fn advance(&self, done: u64, total: u64) {
        if !self.terminal {
            return;
        }
        let Ok(mut bar) = self.bar.lock() else {
            return;
        };
        if done >= total {
            if let Some(b) = bar.take() {
                b.finish_and_clear();
            }
            return;
        }
        let b = bar.get_or_insert_with(|| {
            let b = indicatif::ProgressBar::new(total);
            let name = self.stage.lock().map(|s| s.clone()).unwrap_or_default();
            let template = format!(
                "{} {{bar:40}} {{pos}}/{{len}}, {{elapsed}} elapsed, ~{{eta}} left",
                if name.is_empty() { "working" } else { &name }
            );
            if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
                b.set_style(style);
            }
            b
        });
        b.set_position(done);
    }
}
