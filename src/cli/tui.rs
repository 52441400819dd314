//! `spira tui` (and `spira` alone): the terminal explorer.

use super::load_case;
use anyhow::Result;
use std::path::PathBuf;

/// `spira tui`: the explorer on the case at `case` (default: the built-in thesis case,
/// n = 8), its exported CSV files written into `out`.
pub fn explore(case: Option<PathBuf>, out: PathBuf) -> Result<()> {
    let loaded = load_case(case.as_deref())?;
    Ok(spira::tui::run_with(loaded, out, case)?)
}
