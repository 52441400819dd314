//! Files on disk: every file is written to a temporary file in its folder and renamed over
//! its name, so a reader never sees it half-written and a failed write leaves nothing
//! behind.

use super::csv::{critical_csv, load_csv, mode_csv, reactions_csv, state_csv, with_note};
use crate::discretisation::model::DiscreteModel;
use crate::results::{CriticalPoint, LoadPoint, Snapshot};
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

/// Writes `contents` to `path` atomically: into a temporary file of the same folder (removed
/// again if anything fails), then renamed to `path`. The file gets the permissions a newly
/// created file has (`0o666` less the umask on Unix), not the temporary file's private ones.
pub fn write_atomic(path: &Path, contents: &str) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".spira-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    tmp.write_all(contents.as_bytes())?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// The files of a run, written into `dir` (created if needed): load, reactions and state,
/// and when there are critical points, `critical.csv` and one `mode-<k>.csv` each.
/// Returns their paths.
pub fn write_run(
    dir: &Path,
    case: &str,
    points: &[LoadPoint],
    snapshot: &Snapshot,
    critical: &[CriticalPoint],
    model: &DiscreteModel,
) -> io::Result<Vec<PathBuf>> {
    write_run_noted(dir, case, None, points, snapshot, critical, model)
}

/// [`write_run`] with `note`, when given, as a `#` line in the header of every file.
pub fn write_run_noted(
    dir: &Path,
    case: &str,
    note: Option<&str>,
    points: &[LoadPoint],
    snapshot: &Snapshot,
    critical: &[CriticalPoint],
    model: &DiscreteModel,
) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut files = vec![
        ("load.csv".to_string(), load_csv(case, points)),
        ("reactions.csv".to_string(), reactions_csv(case, points)),
        ("state.csv".to_string(), state_csv(case, snapshot)),
    ];
    if !critical.is_empty() {
        files.push(("critical.csv".to_string(), critical_csv(case, critical)));
        for (i, c) in critical.iter().enumerate() {
            files.push((format!("mode-{i}.csv"), mode_csv(case, model, i, c)));
        }
    }
    let mut out = Vec::new();
    for (name, text) in files {
        let text = match note {
            Some(n) => with_note(&text, n),
            None => text,
        };
        let p = dir.join(name);
        write_atomic(&p, &text)?;
        out.push(p);
    }
    Ok(out)
}
