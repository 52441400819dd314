//! Errors of a case file, and how the errors of the `toml` crate are sorted into them.

use serde_path_to_error::{Path, Segment};
use std::ops::Range;

/// A case-file error: where, which key, what was expected. Every variant displays as one
/// line: the file and line, the key (dotted, e.g. `geometry.radius`), what was expected and
/// what was found.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// The file cannot be read.
    #[error("cannot read case file {file}: {reason}")]
    Io {
        file: String,
        /// Kept out of the error chain: the message already says it, and a report that
        /// walks the chain would say it twice.
        reason: std::io::Error,
    },
    /// Not TOML: an unclosed bracket, a missing value, a duplicate key.
    #[error("{file}:{line}: not valid TOML: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    /// A key or table that is not part of a case file (usually a typo); `key` is its full
    /// dotted path.
    #[error("{file}:{line}: key `{key}`: {message}")]
    UnknownKey {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// A value of the wrong type (a string for a number, a fraction for a whole number) or
    /// a name that is not one of the allowed ones.
    #[error("{file}:{line}: key `{key}`: {message}")]
    WrongType {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// A value of the right type but outside its physical or numerical range.
    #[error("{file}:{line}: key `{key}`: {message}")]
    Invalid {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// A `--set key=value` override of the case file `file` that makes it invalid (or that
    /// cannot be applied); `setting` is the override, `key=value`.
    #[error("--set {setting}: {message}")]
    Set {
        file: String,
        setting: String,
        message: String,
    },
}

impl CaseError {
    /// The file the error is about.
    pub fn file(&self) -> &str {
        match self {
            CaseError::Io { file, .. }
            | CaseError::Syntax { file, .. }
            | CaseError::UnknownKey { file, .. }
            | CaseError::WrongType { file, .. }
            | CaseError::Invalid { file, .. }
            | CaseError::Set { file, .. } => file,
        }
    }
    /// Line (1-based) the error points at, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            CaseError::Io { .. } | CaseError::Set { .. } => None,
            CaseError::Syntax { line, .. }
            | CaseError::UnknownKey { line, .. }
            | CaseError::WrongType { line, .. }
            | CaseError::Invalid { line, .. } => Some(*line),
        }
    }
    /// The key at fault (dotted path, e.g. `geometry.radius`), if the error is about one.
    pub fn key(&self) -> Option<&str> {
        match self {
            CaseError::UnknownKey { key, .. }
            | CaseError::WrongType { key, .. }
            | CaseError::Invalid { key, .. } => Some(key),
            CaseError::Set { setting, .. } => setting.split_once('=').map(|(key, _)| key),
            CaseError::Io { .. } | CaseError::Syntax { .. } => None,
        }
    }
    /// What was expected and what was found, without the location.
    pub fn message(&self) -> String {
        match self {
            CaseError::Io { reason, .. } => reason.to_string(),
            CaseError::Syntax { message, .. }
            | CaseError::UnknownKey { message, .. }
            | CaseError::WrongType { message, .. }
            | CaseError::Invalid { message, .. }
            | CaseError::Set { message, .. } => message.clone(),
        }
    }

    /// A grammar error of the TOML text (reported before any key is looked at).
    pub(super) fn syntax(e: &toml::de::Error, text: &str, file: &str) -> CaseError {
        let span = e.span().unwrap_or(0..0);
        let mut message = plain_types(e.message().trim());
        if message.starts_with("duplicate key") && !message.contains('`') {
            // name the key: the text of the line up to its `=`
            let key = line_at(text, &span)
                .split('=')
                .next()
                .unwrap_or("")
                .trim()
                .to_string();
            if !key.is_empty() && !key.starts_with('[') {
                message = format!("duplicate key `{key}` (each key may be given once)");
            } else {
                message = format!("{message} (each key and table may be given once)");
            }
        }
        CaseError::Syntax {
            file: file.to_string(),
            line: line_of(text, span.start),
            message,
        }
    }

    /// An error against the layout of the file (an unknown key, a value of the wrong type),
    /// with the path of keys serde followed down to it and the span `toml` gives it.
    pub(super) fn layout(
        e: &serde_path_to_error::Error<toml::de::Error>,
        text: &str,
        file: &str,
    ) -> CaseError {
        let span = e.inner().span().unwrap_or(0..0);
        let line = line_of(text, span.start);
        let file = file.to_string();
        let message = plain_types(e.inner().message().trim());
        let keys = keys(e.path());
        if keys.is_empty() {
            // about the document as a whole: no key to name
            return CaseError::Syntax {
                file,
                line,
                message,
            };
        }
        let key = keys.join(".");
        let value = text
            .get(span.clone())
            .unwrap_or("")
            .trim()
            .chars()
            .take(40)
            .collect::<String>();
        if message.contains("$__toml_private_datetime")
            || (message.starts_with("invalid type: table")
                && value.starts_with(|c: char| c.is_ascii_digit()))
        {
            let expected = message
                .split_once("expected ")
                .map_or("another value".to_string(), |(_, e)| e.to_string());
            return CaseError::WrongType {
                file,
                line,
                key,
                message: format!("expected {expected}, found a TOML date or time `{value}`"),
            };
        }
        if let Some(allowed) = allowed_names(&key) {
            if message.contains("wanted string or table") || message.starts_with("invalid type") {
                return CaseError::WrongType {
                    file,
                    line,
                    key,
                    message: format!("expected one of {allowed}, found `{value}`"),
                };
            }
        }
        let message = shorten_quoted(&message, &value);
        if message.starts_with("invalid value: integer") {
            return CaseError::WrongType {
                file,
                line,
                key,
                message: format!(
                    "the whole number `{value}` is out of range (beyond 64 bits); see the key's range in the README"
                ),
            };
        }
        if message.starts_with("unknown field") {
            let message = if line_at(text, &span).starts_with('[') {
                unknown_table(&message, &key)
            } else {
                message
            };
            return CaseError::UnknownKey {
                file,
                line,
                key,
                message,
            };
        }
        if let Some(table) = table_read_as_array(e.path()) {
            return CaseError::WrongType {
                file,
                line,
                message: array_for_table(text, &table),
                key: table,
            };
        }
        CaseError::WrongType {
            file,
            line,
            key,
            message,
        }
    }
}

/// Control characters as escapes (`\n`), the rest as it is.
trait EscapeControls {
    fn escape_default_controls(self) -> std::vec::IntoIter<char>;
}

impl EscapeControls for char {
    fn escape_default_controls(self) -> std::vec::IntoIter<char> {
        if self.is_control() {
            self.escape_default().collect::<Vec<_>>().into_iter()
        } else {
            vec![self].into_iter()
        }
    }
}

/// serde quotes a value as it printed it (`1e103` with 103 zeros): the first quoted
/// value of `message`, when long, is replaced by the text of the file.
fn shorten_quoted(message: &str, value: &str) -> String {
    let Some(start) = message.find('`') else {
        return message.to_string();
    };
    let Some(len) = message[start + 1..].find('`') else {
        return message.to_string();
    };
    if len <= 16 || value.is_empty() {
        return message.to_string();
    }
    format!(
        "{}`{}`{}",
        &message[..start],
        value,
        &message[start + 1 + len + 1..]
    )
}

/// The names a key that takes a name allows, quoted, for messages.
fn allowed_names(key: &str) -> Option<&'static str> {
    let last = key.rsplit('.').next().unwrap_or(key);
    Some(match last {
        "control" => "\"displacement\", \"force\"",
        "parameter" => "\"axial\", \"twist\", \"tilt\", \"pressure\"",
        "branch" => "\"fundamental\", \"switch\", \"switch-negative\"",
        "order" => "\"quadratic\", \"linear\"",
        "translation" => "\"fixed\", \"slide\", \"radial\"",
        "rotation" => "\"clamped\", \"free\", \"pinned\"",
        "reference" => "\"discrete\", \"continuum\"",
        "stress_free" => "\"helix\", \"straight\"",
        "energy" => "\"kirchhoff\", \"sadowsky\"",
        "model" => "\"auto\", \"pair\", \"full\", \"cell\"",
        _ => return None,
    })
}

/// serde's "unknown field `material`" said of a key on a header line (`[material]`): the
/// key is a table.
fn unknown_table(message: &str, key: &str) -> String {
    let name = key.rsplit('.').next().unwrap_or(key);
    message.replacen(
        &format!("unknown field `{name}`"),
        &format!("unknown table `[{key}]`"),
        1,
    )
}

/// The message for an array given where `table` is expected.
fn array_for_table(text: &str, table: &str) -> String {
    let header = format!("[[{table}]]");
    let found = if text.lines().any(|l| l.trim_start().starts_with(&header)) {
        format!("an array of tables `{header}`")
    } else {
        "an array".to_string()
    };
    format!("expected a table `[{table}]`, found {found}")
}

/// The keys of a path, down to the value at fault (array indices left out).
fn keys(path: &Path) -> Vec<&str> {
    path.iter().filter_map(file_key).collect()
}

/// The key a path segment names in the file, if it names one. A `toml::Spanned` value is
/// read as a struct with private fields (`$__serde_spanned_private_value`): those are not
/// keys of the file.
fn file_key(segment: &Segment) -> Option<&str> {
    match segment {
        Segment::Map { key } if !key.starts_with("$__") => Some(key),
        _ => None,
    }
}

/// The table that was given as an array (usually of tables, `[[geometry]]` for
/// `[geometry]`), if the path goes through an array: a case file has none. serde reads the
/// array's elements as the fields of the table in order and complains about the first
/// field, so the error is said again about the table.
fn table_read_as_array(path: &Path) -> Option<String> {
    let is_array = |segment: &&Segment| matches!(segment, Segment::Seq { .. });
    path.iter().any(|s| is_array(&s)).then(|| {
        let table: Vec<&str> = path
            .iter()
            .take_while(|s| !is_array(s))
            .filter_map(file_key)
            .collect();
        table.join(".")
    })
}

/// The whole line of the text the span starts on, without its indentation.
fn line_at<'t>(text: &'t str, span: &Range<usize>) -> &'t str {
    let start = span.start.min(text.len());
    let begin = text[..start].rfind('\n').map_or(0, |at| at + 1);
    let end = text[start..].find('\n').map_or(text.len(), |at| start + at);
    text[begin..end].trim_start()
}

/// 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// serde names Rust types in its messages; a case file (or a session file) has numbers,
/// whole numbers, arrays and tables.
pub(crate) fn plain_types(message: &str) -> String {
    // one line: a quoted value's line breaks written as escapes
    let message: String = message
        .chars()
        .flat_map(char::escape_default_controls)
        .collect();
    let mut m = message
        .replace("expected i64", "expected a whole number")
        .replace("expected usize", "expected a whole number")
        .replace("expected u32", "expected a whole number")
        .replace("expected f64", "expected a number")
        .replace("expected a boolean", "expected true or false")
        .replace("invalid type: map", "invalid type: table")
        .replace("invalid type: sequence", "invalid type: array");
    // `expected struct RawGeometry` and the like
    while let Some(at) = m.find("expected struct ") {
        let end = m[at..]
            .find(|c: char| !(c.is_alphanumeric() || c == ' '))
            .map_or(m.len(), |e| at + e);
        m.replace_range(at..end, "expected a table");
    }
    m
}
