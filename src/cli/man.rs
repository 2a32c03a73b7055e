//! `streaklight man [DIR]`: the manual pages, `streaklight.1` and one `streaklight-NAME.1`
//! per subcommand, written from the same definitions as `--help`.

use std::path::{Path, PathBuf};

use clap::CommandFactory;
use streaklight::Error;

use super::exit::exit_codes;
use super::output::Output;

/// Arguments of `streaklight man`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder to write the pages into (created if missing), e.g. ~/.local/share/man/man1.
    #[arg(default_value = "man", value_name = "DIR")]
    pub dir: PathBuf,
}

/// `man --help`'s epilogue.
pub const AFTER_HELP: &str = concat!(
    "Examples:\n  \
     streaklight man ~/.local/share/man/man1 && man streaklight-fit\n  \
     streaklight man /tmp/pages && man -l /tmp/pages/streaklight.1\n\n",
    exit_codes!()
);

/// Writes the pages of the command line `C` into the folder.
pub fn run<C: CommandFactory>(args: Args, out: &Output) -> streaklight::Result<()> {
    std::fs::create_dir_all(&args.dir).map_err(|e| Error::io(&args.dir, e))?;
    let mut command = C::command().disable_help_subcommand(true);
    command.build();
    for path in write_pages(command, &args.dir)? {
        out.info(&format!("wrote {}", path.display()));
    }
    Ok(())
}

/// Writes the page of `command` and of each of its subcommands, recursively; returns the
/// files written.
fn write_pages(command: clap::Command, dir: &Path) -> streaklight::Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for sub in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        written.extend(write_pages(sub.clone(), dir)?);
    }
    let page = clap_mangen::Man::new(command);
    let path = dir.join(page.get_filename());
    let mut roff = Vec::new();
    page.render(&mut roff).map_err(|e| Error::io(&path, e))?;
    streaklight::output_file::write_atomically(&path, &roff)?;
    written.insert(0, path);
    Ok(written)
}
