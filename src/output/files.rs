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

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .expect("folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn an_atomic_write_leaves_only_the_file_whatever_its_extension() {
        let dir = tempfile::tempdir().expect("scratch folder");
        for name in ["precision.svg", "precision.csv", "notes"] {
            write_atomic(&dir.path().join(name), "first").expect("write");
            write_atomic(&dir.path().join(name), "second").expect("overwrite");
            let text = std::fs::read_to_string(dir.path().join(name)).expect("read");
            assert_eq!(text, "second");
        }
        assert_eq!(
            listing(dir.path()),
            ["notes", "precision.csv", "precision.svg"]
        );
    }

    #[test]
    fn a_failed_atomic_write_leaves_nothing_behind() {
        let dir = tempfile::tempdir().expect("scratch folder");
        // a folder cannot be replaced by a file: the rename fails
        std::fs::create_dir(dir.path().join("load.csv")).expect("folder");
        assert!(write_atomic(&dir.path().join("load.csv"), "rows").is_err());
        assert_eq!(listing(dir.path()), ["load.csv"]);
        assert!(write_atomic(&dir.path().join("missing/load.csv"), "rows").is_err());
        assert_eq!(listing(dir.path()), ["load.csv"]);
    }

    #[cfg(unix)]
    #[test]
    fn an_atomic_write_gives_the_permissions_of_a_new_file() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = tempfile::tempdir().expect("scratch folder");
        let (plain, atomic) = (dir.path().join("plain"), dir.path().join("atomic"));
        std::fs::write(&plain, "x").expect("write");
        write_atomic(&atomic, "x").expect("write");
        let mode = |p: &Path| std::fs::metadata(p).expect("metadata").permissions().mode();
        assert_eq!(mode(&atomic), mode(&plain));
    }
}
