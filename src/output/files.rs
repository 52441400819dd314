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

thread_local! {
    /// How many [`WriteGuard`]s this thread holds (the lock is taken by the first).
    static HELD: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Keeps writes of other threads from starting while it lives ([`hold_writes`]).
#[must_use]
pub struct WriteGuard {
    _lock: Option<MutexGuard<'static, ()>>,
}

impl Drop for WriteGuard {
    fn drop(&mut self) {
        // the lock (if this guard took it) is released after this
        HELD.with(|h| h.set(h.get() - 1));
    }
}

/// Waits until no write is under way and keeps new ones from starting while the guard
/// lives: what a signal handler takes before it ends the process, so that a signal during
/// the write phase leaves no staging folder or temporary file, and the target holds
/// either its previous files or the whole new set. (Writes from several threads are
/// serialised by it too.) A thread may take it again while it holds it: a write made of
/// several writes (a sweep's case folder) holds it over all of them.
pub fn hold_writes() -> WriteGuard {
    let lock =
        (HELD.with(|h| h.get()) == 0).then(|| WRITING.lock().unwrap_or_else(|e| e.into_inner()));
    HELD.with(|h| h.set(h.get() + 1));
    WriteGuard { _lock: lock }
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

/// The name of a run's staging folder begins with this ([`write_folder`]).
pub const STAGING_PREFIX: &str = ".spira-staging-";

/// The file inside a staging folder that names the process using it: `pid <id>` and
/// `host <name>` lines. A staging folder is spira's (and may be removed once its owner is
/// gone) only when its name begins with `.spira-` and it holds this file.
pub const OWNER_FILE: &str = ".spira-owner";

/// A staging folder whose owner ran on another machine (a shared file system) is taken
/// for abandoned only after this long: a write phase lasts seconds, not a day.
pub const FOREIGN_STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(24 * 3600);

/// A temporary folder in `parent` named `<prefix>XXXXXX`, removed when dropped, holding the
/// [`OWNER_FILE`] that names this process: what [`remove_stale`] recognises if the process
/// is killed (`kill -9`, a power cut) before it could remove the folder.
pub fn staging_dir(parent: &Path, prefix: &str) -> io::Result<tempfile::TempDir> {
    let stage = tempfile::Builder::new().prefix(prefix).tempdir_in(parent)?;
    std::fs::write(
        stage.path().join(OWNER_FILE),
        owner_record(std::process::id()),
    )?;
    Ok(stage)
}

/// The text of an [`OWNER_FILE`] naming process `pid` of this machine.
pub fn owner_record(pid: u32) -> String {
    format!("pid {pid}\nhost {}\n", host_name())
}

/// Removes the staging folders in `parent` that spira made ([`staging_dir`]: the name
/// begins with `.spira-` and the folder holds an [`OWNER_FILE`]) and that no live process
/// uses: the owner's process is gone (on this machine: `/proc/<pid>` on Linux,
/// `kill(pid, 0)` on other Unix systems), or, when that cannot be told (another machine,
/// another system), the owner file is older than [`FOREIGN_STALE_AFTER`]. Anything else
/// is left alone: a folder without an owner file, one whose owner file cannot be read, a
/// file, a link. Returns the folders removed.
pub fn remove_stale(parent: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    let Ok(entries) = std::fs::read_dir(parent) else {
        return removed;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        if !name.to_string_lossy().starts_with(".spira-") {
            continue;
        }
        // a real folder, not a link to one
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let marker = entry.path().join(OWNER_FILE);
        let Ok(text) = std::fs::read_to_string(&marker) else {
            continue;
        };
        let Some(owner) = Owner::parse(&text) else {
            continue;
        };
        let age = std::fs::metadata(&marker)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok());
        if !owner.in_use(age) && std::fs::remove_dir_all(entry.path()).is_ok() {
            removed.push(entry.path());
        }
    }
    removed
}

/// [`remove_stale`] on `parent`, once per folder and process (a sweep writes thousands of
/// folders into one parent).
fn remove_stale_once(parent: &Path) {
    static CLEANED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    let key = parent
        .canonicalize()
        .unwrap_or_else(|_| parent.to_path_buf());
    let mut cleaned = CLEANED.lock().unwrap_or_else(|e| e.into_inner());
    if !cleaned.contains(&key) {
        remove_stale(parent);
        cleaned.push(key);
    }
}

/// The process an [`OWNER_FILE`] names.
#[derive(Debug, PartialEq, Eq)]
struct Owner {
    pid: u32,
    host: String,
}

impl Owner {
    fn parse(text: &str) -> Option<Owner> {
        let mut pid = None;
        let mut host = None;
        for line in text.lines() {
            match line.split_once(' ') {
                Some(("pid", v)) => pid = v.trim().parse::<u32>().ok(),
                Some(("host", v)) => host = Some(v.trim().to_string()),
                _ => {}
            }
        }
        Some(Owner {
            pid: pid.filter(|&p| p > 0)?,
            host: host?,
        })
    }

    /// Whether the folder may still be in use, its owner file `age` old.
    fn in_use(&self, age: Option<std::time::Duration>) -> bool {
        let recent = || age.is_none_or(|a| a < FOREIGN_STALE_AFTER);
        if self.host != host_name() {
            return recent();
        }
        match process_alive(self.pid) {
            Some(alive) => alive,
            None => recent(),
        }
    }
}

/// Whether process `pid` of this machine is alive, when that can be told.
#[cfg(unix)]
fn process_alive(pid: u32) -> Option<bool> {
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        return Some(Path::new(&format!("/proc/{pid}")).exists());
    }
    let pid = libc::pid_t::try_from(pid).ok()?;
    // SAFETY: signal 0 only checks that the process exists and may be signalled
    if unsafe { libc::kill(pid, 0) } == 0 {
        return Some(true);
    }
    // EPERM: it exists, another user's
    Some(io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH))
}

/// Whether process `pid` of this machine is alive: not told here (the age decides).
#[cfg(not(unix))]
fn process_alive(_pid: u32) -> Option<bool> {
    None
}

/// This machine's name, for the [`OWNER_FILE`] (empty when it cannot be told).
fn host_name() -> String {
    #[cfg(unix)]
    {
        let mut buf = [0u8; 256];
        // SAFETY: the buffer is valid for its length; the name is NUL-terminated within it
        // when the call succeeds (the last byte is kept 0)
        let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len() - 1) };
        if r == 0 {
            let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
            return String::from_utf8_lossy(&buf[..end]).trim().to_string();
        }
    }
    std::env::var("COMPUTERNAME").unwrap_or_default()
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
    remove_stale_once(&parent);
    let stage = staging_dir(&parent, STAGING_PREFIX).or_else(|_| {
        remove_stale_once(dir);
        staging_dir(dir, STAGING_PREFIX)
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

    /// A staging folder as [`staging_dir`] makes it, owned by process `pid` of `host`.
    fn fake_staging(parent: &Path, name: &str, pid: u32, host: &str) -> PathBuf {
        let p = parent.join(name);
        std::fs::create_dir_all(p.join("new")).expect("folder");
        std::fs::write(p.join("new/load.csv"), "half written").expect("write");
        std::fs::write(p.join(OWNER_FILE), format!("pid {pid}\nhost {host}\n")).expect("owner");
        p
    }

    /// The id of a process that has ended (and been reaped).
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true")
            .spawn()
            .expect("spawn true");
        let pid = child.id();
        child.wait().expect("wait");
        assert!(process_alive(pid) != Some(true), "{pid} is gone");
        pid
    }

    #[test]
    fn the_next_write_removes_staging_folders_whose_process_is_gone_and_nothing_else() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let host = host_name();
        let dead = dead_pid();
        let me = std::process::id();
        fake_staging(dir.path(), ".spira-staging-killed", dead, &host);
        // a sweep's case folder that a killed sweep was writing
        fake_staging(dir.path(), ".spira-001_target-0.1-killed", dead, &host);
        // in use: this process's
        fake_staging(dir.path(), ".spira-staging-live", me, &host);
        // another machine's (a shared file system): its process cannot be told, recent
        fake_staging(dir.path(), ".spira-staging-remote", dead, "another-host");
        // not spira's: no owner file, an unreadable one, another prefix, a file
        std::fs::create_dir_all(dir.path().join(".spira-staging-nomarker/new")).expect("folder");
        let odd = dir.path().join(".spira-staging-odd");
        std::fs::create_dir(&odd).expect("folder");
        std::fs::write(odd.join(OWNER_FILE), "pid twelve\n").expect("write");
        fake_staging(dir.path(), "staging-killed", dead, &host);
        fake_staging(dir.path(), ".other-staging", dead, &host);
        std::fs::write(dir.path().join(".spira-staging-file"), "x").expect("write");
        let files = vec![("load.csv".to_string(), "a\n1\n".to_string())];
        write_folder(&dir.path().join("out"), &files, is_run_file).expect("write");
        assert_eq!(
            listing(dir.path()),
            [
                ".other-staging",
                ".spira-staging-file",
                ".spira-staging-live",
                ".spira-staging-nomarker",
                ".spira-staging-odd",
                ".spira-staging-remote",
                "out",
                "staging-killed",
            ]
        );
        // the live one is whole
        assert!(dir
            .path()
            .join(".spira-staging-live/new/load.csv")
            .is_file());
        // and once its process is gone, the next cleaning takes it
        std::fs::write(
            dir.path().join(".spira-staging-live").join(OWNER_FILE),
            format!("pid {dead}\nhost {host}\n"),
        )
        .expect("write");
        assert_eq!(
            remove_stale(dir.path()),
            [dir.path().join(".spira-staging-live")]
        );
    }

    #[test]
    fn an_owner_of_another_machine_is_taken_for_gone_only_after_a_day() {
        let owner = Owner::parse("pid 12\nhost another-host\n").expect("owner");
        assert_eq!(
            owner,
            Owner {
                pid: 12,
                host: "another-host".into()
            }
        );
        let hour = std::time::Duration::from_secs(3600);
        assert!(owner.in_use(Some(hour)));
        assert!(owner.in_use(None));
        assert!(!owner.in_use(Some(FOREIGN_STALE_AFTER + hour)));
        assert!(Owner::parse("pid 0\nhost h\n").is_none());
        assert!(Owner::parse("host h\n").is_none());
        // this process, however old its folder
        let me = Owner::parse(&format!(
            "pid {}\nhost {}\n",
            std::process::id(),
            host_name()
        ))
        .expect("owner");
        assert!(me.in_use(Some(FOREIGN_STALE_AFTER + hour)));
    }

    #[test]
    fn a_staging_folder_names_its_owner_and_goes_when_dropped() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let stage = staging_dir(dir.path(), STAGING_PREFIX).expect("staging");
        let text = std::fs::read_to_string(stage.path().join(OWNER_FILE)).expect("owner");
        let owner = Owner::parse(&text).expect("parsed");
        assert_eq!(owner.pid, std::process::id());
        assert!(remove_stale(dir.path()).is_empty(), "in use");
        let path = stage.path().to_path_buf();
        drop(stage);
        assert!(!path.exists());
    }

    #[test]
    fn writes_may_be_held_again_by_the_thread_holding_them() {
        let outer = hold_writes();
        let dir = tempfile::tempdir().expect("scratch folder");
        // would deadlock if the guard were not reentrant
        write_atomic(&dir.path().join("a"), "x").expect("write");
        drop(outer);
        // and released: another thread can write
        let p = dir.path().join("b");
        std::thread::spawn(move || write_atomic(&p, "y").expect("write"))
            .join()
            .expect("thread");
        assert_eq!(listing(dir.path()), ["a", "b"]);
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
