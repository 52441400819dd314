//! Files on disk: every file is written to a temporary file in its folder and renamed over
//! its name, so a reader never sees it half-written and a failed write leaves nothing
//! behind. The files of a run are written together: into a temporary folder beside the
//! output folder, then moved in, after the files of the same kind a previous run left
//! there are moved out (and put back if the move fails).

use super::csv::{
    bulk_csv, check_finite, critical_csv, joints_csv, load_csv, mode_csv, reactions_csv, state_csv,
    with_note, NonFinite,
};
use super::vtk;
use crate::discretisation::model::DiscreteModel;
use crate::results::{CriticalPoint, LoadPoint, ModeShape, Snapshot, StepBulk};
use crate::run::PathOutcome;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Held while a file or a folder of files is written ([`write_atomic`], [`write_folder`]).
static WRITING: Mutex<()> = Mutex::new(());

/// Waits until no write is under way and keeps new ones from starting while the guard
/// lives: what a signal handler takes before it ends the process, so that a signal during
/// the write phase leaves no staging folder or temporary file, and the target holds
/// either its previous files or the whole new set. (Writes from several threads are
/// serialised by it too.)
pub fn hold_writes() -> MutexGuard<'static, ()> {
    WRITING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Writes `contents` to `path` atomically: into a temporary file of the same folder (removed
/// again if anything fails), then renamed to `path`. The file gets the permissions a newly
/// created file has (`0o666` less the umask on Unix), not the temporary file's private ones.
pub fn write_atomic(path: &Path, contents: &str) -> io::Result<()> {
    // declared first, dropped last: after the temporary file is gone
    let _writing = hold_writes();
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

/// What a run leaves behind, for [`run_files`] and [`write_run`].
#[derive(Clone, Copy, Debug)]
pub struct RunFiles<'a> {
    pub case: &'a str,
    /// A `#` line for the header of every CSV file (the mesh an accuracy target chose).
    pub note: Option<&'a str>,
    pub points: &'a [LoadPoint],
    /// The last state.
    pub snapshot: &'a Snapshot,
    pub critical: &'a [CriticalPoint],
    pub model: &'a DiscreteModel,
    /// The bulk at every point of `points`.
    pub bulk: &'a [StepBulk],
    /// For a ParaView series (`--vtk`): the shape at every point of `points` (same order),
    /// and every critical point's mode on its state.
    pub series: Option<(&'a [Snapshot], &'a [ModeShape])>,
    /// For `state-<step>.csv` files (`--states`, `--figures`): `(output step, shape)`.
    pub states: &'a [(usize, Snapshot)],
}

impl<'a> RunFiles<'a> {
    /// The files of a path's outcome, without a ParaView series or per-step states.
    pub fn of(case: &'a str, note: Option<&'a str>, outcome: &'a PathOutcome) -> RunFiles<'a> {
        RunFiles {
            case,
            note,
            points: &outcome.points,
            snapshot: &outcome.snapshot,
            critical: &outcome.critical,
            model: &outcome.model,
            bulk: &outcome.bulk,
            series: None,
            states: &[],
        }
    }
}

/// The elastic hypotheses of the model and where its reference curvatures come from, for
/// the header of every file (issue 11).
pub fn hypotheses_note(model: &DiscreteModel) -> String {
    format!(
        "elastic hypotheses: {}; reference curvatures: {}",
        model.elasticity.describe(),
        model.reference.name()
    )
}

/// Which model was solved, for the header of every file.
pub fn model_solved(model: &DiscreteModel) -> String {
    match model.assembly.symmetry {
        Some(sym) => format!(
            "model: one right/left pair standing for all {} rods (the {}-fold rotational symmetry), stability of the whole assembly by its Bloch blocks p = 0..{}",
            sym.full_rods(),
            sym.m,
            sym.m / 2
        ),
        None => format!("model: the full assembly, {} rods", model.rods.len()),
    }
}

/// The files of a run as (name, text): load, reactions, state, joints and bulk, and when
/// there are critical points, `critical.csv` and one `mode-<k>.csv` each; the per-step
/// states when given; with a series, `series.pvd`, one `step-<k>.vtp` per output step and
/// one `mode-<k>.vtp` per critical point. Every CSV names the model solved and the note in
/// its header. A series holding a value that is not finite is refused.
pub fn run_files(run: &RunFiles) -> io::Result<Vec<(String, String)>> {
    let case = run.case;
    let mut files = vec![
        ("load.csv".to_string(), load_csv(case, run.points)),
        ("reactions.csv".to_string(), reactions_csv(case, run.points)),
        ("state.csv".to_string(), state_csv(case, run.snapshot)),
        ("joints.csv".to_string(), joints_csv(case, run.snapshot)),
        ("bulk.csv".to_string(), bulk_csv(case, run.bulk)),
    ];
    if !run.critical.is_empty() {
        files.push(("critical.csv".to_string(), critical_csv(case, run.critical)));
        for (i, c) in run.critical.iter().enumerate() {
            files.push((format!("mode-{i}.csv"), mode_csv(case, run.model, i, c)));
        }
    }
    for (step, snapshot) in run.states {
        files.push((format!("state-{step}.csv"), state_csv(case, snapshot)));
    }
    let solved = model_solved(run.model);
    let hypotheses = hypotheses_note(run.model);
    let mut files: Vec<(String, String)> = files
        .into_iter()
        .map(|(name, text)| (name, with_note(&text, &hypotheses)))
        .map(|(name, text)| (name, with_note(&text, &solved)))
        .map(|(name, text)| match run.note {
            Some(n) => (name, with_note(&text, n)),
            None => (name, text),
        })
        .collect();
    if let Some((shapes, modes)) = run.series {
        let refuse = |name: &str, e: NonFinite| {
            io::Error::new(io::ErrorKind::InvalidData, format!("{name}: {e}"))
        };
        let mut steps = Vec::new();
        for (p, shape) in run.points.iter().zip(shapes) {
            let name = vtk::step_file(p.step);
            let text = vtk::vtp(case, shape).map_err(|e| refuse(&name, e))?;
            steps.push((p.parameter, name.clone()));
            files.push((name, text));
        }
        let text = vtk::pvd(case, &steps).map_err(|e| refuse(vtk::SERIES_FILE, e))?;
        files.push((vtk::SERIES_FILE.to_string(), text));
        for (i, m) in modes.iter().enumerate() {
            let name = vtk::mode_file(i);
            let text = vtk::mode_vtp(case, i, m).map_err(|e| refuse(&name, e))?;
            files.push((name, text));
        }
    }
    Ok(files)
}

/// The files of a run ([`run_files`]) written into `dir` (created if needed) as one set.
/// Returns their paths.
pub fn write_run(dir: &Path, run: &RunFiles) -> io::Result<Vec<PathBuf>> {
    write_run_files(dir, &run_files(run)?)
}

/// Writes the files of a run (from [`run_files`], with figures if any) into `dir` as one
/// set ([`write_folder`]), after checking that no CSV holds a non-finite value. Returns
/// their paths.
pub fn write_run_files(dir: &Path, files: &[(String, String)]) -> io::Result<Vec<PathBuf>> {
    for (name, text) in files.iter().filter(|(n, _)| n.ends_with(".csv")) {
        check_finite(text)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("{name}: {e}")))?;
    }
    write_folder(dir, files, is_run_file)
}

/// Whether `name` is a file a run writes: `load.csv`, `reactions.csv`, `state.csv`,
/// `joints.csv`, `bulk.csv`, `critical.csv`, `mode-<k>.csv`, `state-<k>.csv`, a figure
/// ([`is_figure_file`]), and of a series `series.pvd`, `step-<k>.vtp` and `mode-<k>.vtp`.
pub fn is_run_file(name: &str) -> bool {
    matches!(
        name,
        "load.csv"
            | "reactions.csv"
            | "state.csv"
            | "joints.csv"
            | "bulk.csv"
            | "critical.csv"
            | "series.pvd"
    ) || numbered(name, "mode-", ".csv")
        || numbered(name, "state-", ".csv")
        || numbered(name, "mode-", ".vtp")
        || numbered(name, "step-", ".vtp")
        || is_figure_file(name)
}

/// Whether `name` is a figure of a run: `load.svg`, `curvature-step<k>.svg` or
/// `views-step<k>.svg`.
pub fn is_figure_file(name: &str) -> bool {
    name == "load.svg"
        || numbered(name, "curvature-step", ".svg")
        || numbered(name, "views-step", ".svg")
}

/// Whether `name` is `<prefix><whole number><suffix>`.
fn numbered(name: &str, prefix: &str, suffix: &str) -> bool {
    name.strip_prefix(prefix)
        .and_then(|r| r.strip_suffix(suffix))
        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
}

/// Whether `name` is a file a precision study writes.
pub fn is_precision_file(name: &str) -> bool {
    matches!(name, "precision.csv" | "precision.svg")
}

/// Writes `files` (name, contents) into `dir` (created if needed) as one set: into a
/// temporary folder beside `dir`, then, once all are written, the files of `dir` that
/// `own` says are of the same kind are moved out and the new ones moved in. If any move
/// fails the new files are taken out again and the old ones put back, so `dir` holds either
/// the old set or the new one; nothing temporary is left in `dir`. Returns the paths.
pub fn write_folder(
    dir: &Path,
    files: &[(String, String)],
    own: impl Fn(&str) -> bool,
) -> io::Result<Vec<PathBuf>> {
    // declared first, dropped last: after the staging folder is removed
    let _writing = hold_writes();
    std::fs::create_dir_all(dir)?;
    for (name, _) in files {
        let p = dir.join(name);
        if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_dir()) {
            return Err(io::Error::other(format!(
                "{} is a folder, not a file that can be replaced",
                p.display()
            )));
        }
    }
    let parent = match dir.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stage = tempfile::Builder::new()
        .prefix(".spira-staging-")
        .tempdir_in(&parent)
        .or_else(|_| {
            tempfile::Builder::new()
                .prefix(".spira-staging-")
                .tempdir_in(dir)
        })?;
    let new_dir = stage.path().join("new");
    let old_dir = stage.path().join("old");
    std::fs::create_dir(&new_dir)?;
    std::fs::create_dir(&old_dir)?;
    for (name, text) in files {
        let mut f = std::fs::File::create(new_dir.join(name))?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
    }
    // the previous run's files of this kind, out of the way
    let mut moved_out = Vec::new();
    let mut result = Ok(());
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if own(&name) && !entry.file_type()?.is_dir() {
            if let Err(e) = std::fs::rename(entry.path(), old_dir.join(&name)) {
                result = Err(e);
                break;
            }
            moved_out.push(name);
        }
    }
    let mut moved_in = Vec::new();
    if result.is_ok() {
        for (name, _) in files {
            if let Err(e) = std::fs::rename(new_dir.join(name), dir.join(name)) {
                result = Err(e);
                break;
            }
            moved_in.push(name.clone());
        }
    }
    if let Err(e) = result {
        // put the folder back as it was
        for name in &moved_in {
            let _ = std::fs::remove_file(dir.join(name));
        }
        for name in &moved_out {
            let _ = std::fs::rename(old_dir.join(name), dir.join(name));
        }
        return Err(e);
    }
    Ok(files.iter().map(|(name, _)| dir.join(name)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_write_replaces_the_files_of_its_kind_and_keeps_others() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let out = dir.path().join("out");
        std::fs::create_dir(&out).expect("folder");
        for name in [
            "mode-0.csv",
            "mode-12.csv",
            "critical.csv",
            "notes.txt",
            "mode-x.csv",
        ] {
            std::fs::write(out.join(name), "old").expect("write");
        }
        let files = vec![
            ("load.csv".to_string(), "a\n1\n".to_string()),
            ("state.csv".to_string(), "b\n2\n".to_string()),
        ];
        write_folder(&out, &files, is_run_file).expect("write");
        assert_eq!(
            listing(&out),
            ["load.csv", "mode-x.csv", "notes.txt", "state.csv"]
        );
        // nothing left beside the folder but the folder
        assert_eq!(listing(dir.path()), ["out"]);
    }

    #[test]
    fn a_failed_folder_write_leaves_the_previous_files() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("state.csv")).expect("a folder named state.csv");
        std::fs::write(out.join("load.csv"), "old").expect("write");
        let files = vec![
            ("load.csv".to_string(), "new".to_string()),
            ("state.csv".to_string(), "new".to_string()),
        ];
        assert!(write_folder(&out, &files, is_run_file).is_err());
        assert_eq!(listing(&out), ["load.csv", "state.csv"]);
        assert_eq!(
            std::fs::read_to_string(out.join("load.csv")).unwrap(),
            "old"
        );
        assert_eq!(listing(dir.path()), ["out"]);
    }

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
