//! The commands of the `spira` binary, one file each, and what they share: the case a
//! command reads, the checks of their number flags, the size check before a solve and the
//! mesh an accuracy target chooses.

pub mod bench;
pub mod mesh;
pub mod plot;
pub mod precision;
pub mod replay;
pub mod run;
pub mod signals;
pub mod sweep;
pub mod tui;

use anyhow::{bail, Result};
use spira::case::Case;
use std::path::Path;

/// The case in the file at `path`, or the built-in thesis case (n = 8) without one.
pub fn load_case(path: Option<&Path>) -> Result<Case> {
    Ok(match path {
        Some(p) => Case::from_file(p)?,
        None => Case::default_case(),
    })
}

/// The most timed repetitions `--repeats` asks for.
const MAX_REPEATS: u64 = 1000;

/// `--repeats`, bounded so that a study or a benchmark ends.
pub fn repeats_flag(repeats: u64) -> Result<usize> {
    if repeats > MAX_REPEATS {
        bail!(
            "--repeats: expected a number of timed runs from 0 to {MAX_REPEATS}, found {repeats}"
        );
    }
    Ok(repeats as usize)
}

/// The size of the case's problem, said when it is large, and refused when it would not fit
/// in memory (unless `force`).
pub fn check_size(case: &Case, force: bool) -> Result<()> {
    let estimate = case.size_estimate();
    match estimate.check_fits(spira::case::available_memory()) {
        Err(e) if !force => bail!("{e}; --force solves it anyway"),
        Err(e) => println!("warning: {e}; solving anyway (--force)"),
        Ok(()) if estimate.is_large() => println!("size estimate: {estimate}"),
        Ok(()) => {}
    }
    Ok(())
}

/// The command line as typed, the program named `spira`, for captions.
pub fn command_line() -> String {
    let mut args: Vec<String> = std::env::args().collect();
    if let Some(first) = args.first_mut() {
        *first = "spira".to_string();
    }
    args.join(" ")
}
