//! `spira tui` (and `spira` alone): the terminal explorer.

use super::load_case_with;
use anyhow::Result;
use spira::case::Setting;
use std::path::PathBuf;

/// `spira tui`: the explorer on the case at `case` (default: the built-in thesis case,
/// n = 8) with the overrides `set`, its exported CSV files written into `out`. After
/// SIGTERM or SIGHUP the process exits with 128 + the signal's number.
pub fn explore(case: Option<PathBuf>, out: PathBuf, set: &[Setting]) -> Result<()> {
    let loaded = load_case_with(case.as_deref(), set)?;
    let flags = set.iter().map(Setting::as_flag).collect();
    spira::tui::run_with_set(loaded, out, case, flags)?;
    // the terminal is restored: a signal that ended the explorer ends the process as it
    // would have, with the status a shell expects
    if let Some(signal) = spira::tui::ended_by_signal() {
        std::process::exit(128 + signal);
    }
    Ok(())
}
