//! `spira replay`: a session saved in the explorer, replayed headless.

use super::load_case_with;
use super::signals::end_on_signal_between_writes;
use anyhow::Result;
use spira::case::Setting;
use spira::session::replay::replay_into;
use spira::session::script::Session;
use std::path::Path;

/// `spira replay`: the actions of the session file `session` checked, replayed on its
/// case, and the CSV files the explorer's export would have written at its end written into
/// `out`. An action that cannot be done is refused (file, line, action) and nothing is
/// written.
pub fn replay(session: &Path, out: &Path) -> Result<()> {
    end_on_signal_between_writes();
    let read = Session::read(session)?;
    let set = read
        .script
        .set
        .iter()
        .map(|s| s.parse::<Setting>())
        .collect::<std::result::Result<Vec<_>, String>>()
        .map_err(|e| anyhow::anyhow!("{}: set: {e}", session.display()))?;
    let case = load_case_with(read.script.case.as_deref(), &set)?;
    let files = replay_into(&read, &case, out)?;
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!(
        "spira replay: {} actions of {}; wrote {}",
        read.script.actions.len(),
        session.display(),
        names.join(", ")
    );
    Ok(())
}
