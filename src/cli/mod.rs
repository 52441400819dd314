//! The commands of the `spira` binary, one file each, and what they share: the case a
//! command reads, the checks of their number flags, the size check before a solve and the
//! mesh an accuracy target chooses.

pub mod bench;
pub mod critical;
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

/// The case in the file at `path` (or the built-in thesis case) with the keys `set`
/// overridden.
pub fn load_case_with(path: Option<&Path>, set: &[spira::case::Setting]) -> Result<Case> {
    Ok(match path {
        Some(p) => Case::from_file_with(p, set)?,
        None => Case::parse_with(
            spira::case::DEFAULT_CASE,
            spira::case::DEFAULT_CASE_NAME,
            "thesis-n8",
            set,
        )?,
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

/// The command line as typed, the program named `spira`, for captions: an absolute path
/// in it is said relative to the working folder when inside it, else by its last name, so
/// that a figure does not carry the layout of the machine that drew it.
pub fn command_line() -> String {
    let cwd = std::env::current_dir().ok();
    let mut args: Vec<String> = std::env::args()
        .map(|a| caption_arg(&a, cwd.as_deref()))
        .collect();
    if let Some(first) = args.first_mut() {
        *first = "spira".to_string();
    }
    args.join(" ")
}

/// An argument of the command line for a caption: a path ([`caption_path`]), or a
/// `--flag=path`.
fn caption_arg(arg: &str, cwd: Option<&Path>) -> String {
    match arg.split_once('=') {
        Some((flag, value)) if flag.starts_with("--") => {
            format!("{flag}={}", caption_path(value, cwd))
        }
        _ => caption_path(arg, cwd),
    }
}

/// `arg` as it is, or when an absolute path, relative to `cwd` if inside it, else its last
/// name.
fn caption_path(arg: &str, cwd: Option<&Path>) -> String {
    let path = Path::new(arg);
    if !path.is_absolute() {
        return arg.to_string();
    }
    if let Some(rel) = cwd.and_then(|c| path.strip_prefix(c).ok()) {
        let rel = rel.display().to_string();
        return if rel.is_empty() { ".".into() } else { rel };
    }
    path.file_name()
        .map_or_else(|| ".".to_string(), |n| n.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caption_says_no_absolute_path() {
        let cwd = Some(Path::new("/home/me/work"));
        assert_eq!(
            caption_arg("/home/me/work/cases/a.toml", cwd),
            "cases/a.toml"
        );
        assert_eq!(caption_arg("/tmp/x/out", cwd), "out");
        assert_eq!(caption_arg("--out=/tmp/x/out", cwd), "--out=out");
        assert_eq!(caption_arg("/", cwd), ".");
        assert_eq!(caption_arg("out/n2", cwd), "out/n2");
        assert_eq!(
            caption_arg("geometry.helices=16", cwd),
            "geometry.helices=16"
        );
    }
}
