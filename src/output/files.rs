//! Files on disk, written atomically: every file is written to a temporary file in its
//! folder and renamed over its name, so a reader never sees it half-written and a failed write
//! leaves nothing behind. A set of files (a run's) is written together: into a staging folder
//! beside the output folder ([`super::staging`]), then moved in, after the files of the same
//! kind a previous write left there are moved out (and put back if the move fails).

use super::staging::{remove_stale_once, staging_dir, STAGING_PREFIX};
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
