//! `spira replay`: a session saved in the explorer, replayed headless.

use super::load_case;
use super::signals::end_on_signal_between_writes;
use anyhow::Result;
use spira::session::script::{replay_into, Script};
use std::path::Path;

/// `spira replay`: the actions of the session file `session` replayed on its case, and the
/// CSV files the explorer's export would have written at its end written into `out`.
pub fn replay(session: &Path, out: &Path) -> Result<()> {
    end_on_signal_between_writes();
    let script = Script::read(session)?;
    let case = load_case(script.case.as_deref())?;
    let files = replay_into(&script, &case, out)?;
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!(
        "spira replay: {} actions of {}; wrote {}",
        script.actions.len(),
        session.display(),
        names.join(", ")
    );
    Ok(())
}
