//! Errors of a sweep: its file, the cases it generates, shards, and the files it writes.

use crate::case::CaseError;

/// A sweep error. Errors about the sweep file name the file and line (1-based) and the key
/// at fault; an invalid generated case also names the axis value that made it invalid.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The sweep file (or a file it names) cannot be read.
    #[error("cannot read {file}: {reason}")]
    Io {
        file: String,
        reason: std::io::Error,
    },
    /// Not TOML, or not the layout of a sweep file.
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    /// A key of the sweep file with a bad value: `base`, `combine`, an axis.
    #[error("{file}:{line}: key `{key}`: {message}")]
    Key {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// The base case is not a valid case by itself.
    /// The case reader's refusal is said in the message (and kept out of the error
    /// chain, which a report walks: it would be said twice).
    #[error("{file}:{line}: base case: {reason}")]
    Base {
        file: String,
        line: usize,
        reason: CaseError,
    },
    /// A generated case is refused by the case reader.
    #[error(transparent)]
    Generated(Box<InvalidCase>),
    /// A `--shard K/N` that is not one, or Slurm variables that give none.
    #[error("{0}")]
    Shard(String),
    /// Writing a case folder or a table.
    #[error("{path}: {reason}")]
    Write {
        path: String,
        reason: std::io::Error,
    },
    /// A cell of a sweep table that is not what its column holds.
    #[error("{path}:{line}: column `{column}`: expected {expected}, found `{found}`")]
    Cell {
        path: String,
        line: u64,
        column: String,
        expected: &'static str,
        found: String,
    },
    /// A sweep table that cannot be read or merged.
    #[error("{path}: {message}")]
    Table { path: String, message: String },
}

impl SweepError {
    /// The file the error is about, if any.
    pub fn file(&self) -> Option<&str> {
        match self {
            SweepError::Io { file, .. }
            | SweepError::Syntax { file, .. }
            | SweepError::Key { file, .. }
            | SweepError::Base { file, .. } => Some(file),
            SweepError::Generated(g) => Some(&g.file),
            SweepError::Write { path, .. }
            | SweepError::Table { path, .. }
            | SweepError::Cell { path, .. } => Some(path),
            SweepError::Shard(_) => None,
        }
    }

    /// The line of the sweep file the error points at, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            SweepError::Syntax { line, .. }
            | SweepError::Key { line, .. }
            | SweepError::Base { line, .. } => Some(*line),
            SweepError::Generated(g) => Some(g.line),
            SweepError::Cell { line, .. } => usize::try_from(*line).ok(),
            _ => None,
        }
    }

    /// The key at fault (dotted), if any: for a generated case, the case key the reader
    /// refused.
    pub fn key(&self) -> Option<&str> {
        match self {
            SweepError::Key { key, .. } => Some(key),
            SweepError::Generated(g) => Some(&g.key),
            SweepError::Base { reason, .. } => reason.key(),
            _ => None,
        }
    }
}

/// A generated case the case reader refused. `line` is that of the axis the key at fault
/// belongs to (or of the first axis when the key is not swept); `values` lists every axis
/// value of the case.
#[derive(Debug, thiserror::Error)]
#[error(
    "{file}:{line}: axis `{axis}` = {value}: generated case {case} ({values}) is invalid: key `{key}`: {message}"
)]
pub struct InvalidCase {
    pub file: String,
    pub line: usize,
    pub axis: String,
    pub value: String,
    pub case: String,
    pub values: String,
    pub key: String,
    pub message: String,
}
