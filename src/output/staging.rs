//! Staging folders: the temporary folders a set of files is written into before it is moved
//! into place ([`super::files::write_folder`], a sweep's case folders). Each names the process
//! that made it, so that the folders a killed process left behind are recognised and removed
//! by the next write into the same parent, and nothing else is.

use std::io;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The name of a run's staging folder begins with this ([`super::files::write_folder`]).
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
pub(super) fn remove_stale_once(parent: &Path) {
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
pub(super) fn process_alive(pid: u32) -> Option<bool> {
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
pub(super) fn process_alive(_pid: u32) -> Option<bool> {
    None
}

/// This machine's name, for the [`OWNER_FILE`] (empty when it cannot be told).
pub(super) fn host_name() -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
