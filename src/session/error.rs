//! Why a session could not be saved, read or replayed: every refusal of a session file is
//! one paragraph that names the file and the line, and the action when it is about one.

use std::path::PathBuf;

/// Why a session could not be saved, read or replayed.
#[derive(Debug, thiserror::Error)]
pub enum ScriptError {
    #[error("reading or writing {path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Not a session: TOML syntax, a missing or unknown key, a value of the wrong type;
    /// `action` is the action (from 1) the error is in, if it is in one, `key` the key
    /// (dotted) at fault when it is known.
    #[error("{file}:{line}: not a valid session: {}{}{message}", in_action(*action), of_key(key))]
    Parse {
        file: String,
        line: usize,
        action: Option<usize>,
        key: Option<String>,
        message: String,
    },
    #[error("writing the session: {0}")]
    Serialise(#[from] toml::ser::Error),
    /// A version this spira does not read (`newest`: the newest it reads).
    #[error(
        "{file}:{line}: the session is of version {version}; this spira reads versions 1 to {newest}"
    )]
    Version {
        file: String,
        line: usize,
        version: u32,
        newest: u32,
    },
    /// The first action is not a start (or there is none).
    #[error("{file}:{line}: action 1: the session has no start action (its first action must be do = \"start\")")]
    NoStart { file: String, line: usize },
    /// An action that cannot be done on the case, found before anything runs (or, for the
    /// index of a critical point, before the action runs).
    #[error(
        "{file}:{line}: action {number} (do = \"{kind}\") refused: {message}; nothing was written"
    )]
    Refused {
        file: String,
        line: usize,
        number: usize,
        kind: &'static str,
        message: String,
    },
    /// An action the solver could not do (the explorer's message).
    #[error("{file}:{line}: action {number} (do = \"{kind}\") could not be done: {reason}; nothing was written")]
    Failed {
        file: String,
        line: usize,
        number: usize,
        kind: &'static str,
        reason: String,
    },
}

/// "key `k`: " for an error about key `k`.
fn of_key(key: &Option<String>) -> String {
    key.as_ref()
        .map_or(String::new(), |k| format!("key `{k}`: "))
}

/// "action k: " for an error in action `k`.
fn in_action(action: Option<usize>) -> String {
    action.map_or(String::new(), |k| format!("action {k}: "))
}

impl ScriptError {
    /// The session file the error is about (`None` when writing a session).
    pub fn file(&self) -> Option<String> {
        match self {
            ScriptError::Io { path, .. } => Some(path.display().to_string()),
            ScriptError::Serialise(_) => None,
            ScriptError::Parse { file, .. }
            | ScriptError::Version { file, .. }
            | ScriptError::NoStart { file, .. }
            | ScriptError::Refused { file, .. }
            | ScriptError::Failed { file, .. } => Some(file.clone()),
        }
    }

    /// The line (from 1) of the file the error points at, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            ScriptError::Io { .. } | ScriptError::Serialise(_) => None,
            ScriptError::Parse { line, .. }
            | ScriptError::Version { line, .. }
            | ScriptError::NoStart { line, .. }
            | ScriptError::Refused { line, .. }
            | ScriptError::Failed { line, .. } => Some(*line),
        }
    }

    /// The action (from 1) the error is about, if it is about one.
    pub fn action(&self) -> Option<usize> {
        match self {
            ScriptError::Parse { action, .. } => *action,
            ScriptError::NoStart { .. } => Some(1),
            ScriptError::Refused { number, .. } | ScriptError::Failed { number, .. } => {
                Some(*number)
            }
            _ => None,
        }
    }
}
