//! `spira tui` (and `spira` alone): the terminal explorer.

use anyhow::Result;
use spira::case::{Case, Setting};
use std::path::PathBuf;

/// `spira tui`: the explorer on the case at `case` (default: the built-in thesis case,
/// n = 8) with the overrides `set`, its exported CSV files written into `out`. After
/// SIGTERM or SIGHUP the process exits with 128 + the signal's number.
pub fn explore(case: Option<PathBuf>, out: PathBuf, set: &[Setting]) -> Result<()> {
    let loaded = match case.as_deref() {
        Some(path) => Case::from_file_with(path, set)?,
        None => Case::parse_with(
            spira::case::DEFAULT_CASE,
            spira::case::DEFAULT_CASE_NAME,
            "thesis-n8",
            set,
        )?,
    };
    spira::tui::run_with(loaded, out, case)?;
    // the terminal is restored: a signal that ended the explorer ends the process as it
    // would have, with the status a shell expects
    if let Some(signal) = spira::tui::ended_by_signal() {
        std::process::exit(128 + signal);
    }
    Ok(())
}
