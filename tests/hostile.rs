//! Hostile input through the binary, by class: outputs never land on inputs or on each other;
//! temporaries are unpredictable, never follow a planted symlink and are removed on an
//! interrupt, which leaves the old outputs or the new ones, complete; a refused run leaves the
//! output folders as they were; nothing hangs or runs without bound; no wrong result with exit
//! 0; messages in words, naming the file, with names escaped.

mod common;

#[path = "hostile/support.rs"]
mod support;

#[path = "hostile/overlap.rs"]
mod overlap;

#[path = "hostile/refused.rs"]
mod refused;

#[path = "hostile/interrupt.rs"]
mod interrupt;

#[path = "hostile/unbounded.rs"]
mod unbounded;

#[path = "hostile/results.rs"]
mod results;
