//! The explorer's exports, shared with `spira replay`: the current state, the load path
//! with the conditions of each point and the session's events, the tip reactions, and the
//! critical points crossed with their modes, in the formats of `spira run` (the load table
//! gains a `conditions` column and `# event` comment lines).

use super::worker::CriticalMode;
use crate::model::boundary::BoundaryConditions;
use crate::output;
use crate::results::{CriticalPoint, LoadPoint, Snapshot};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A change the user made during the session, at the path point it applies from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SessionEvent {
    /// Index in the path of the first point under the change (the next point).
    pub from_point: usize,
    /// Load parameter `λ` asked for when the change was made (`ε` under displacement
    /// control, `P/Pcrit` under load control); version 1 of the session format named it
    /// by its symbol under displacement control.
    #[serde(alias = "eps")]
    pub parameter: f64,
    pub what: String,
}

/// A file-name-safe version of a case name.
pub fn sanitise(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "case".into()
    } else {
        s
    }
}

/// File names of an export of the state at output step `step` and compression ratio
/// `ratio` of case `label` on a path that crossed `critical` critical points: state, load
/// path, reactions, and with critical points the table of them and one mode file each.
pub fn names(label: &str, step: usize, ratio: f64, critical: usize) -> Vec<String> {
    let stem = format!("{}-step{step}-eps{ratio:.4}", sanitise(label));
    let mut names = vec![
        format!("{stem}-state.csv"),
        format!("{stem}-load.csv"),
        format!("{stem}-reactions.csv"),
    ];
    if critical > 0 {
        names.push(format!("{stem}-critical.csv"));
        names.extend((0..critical).map(|k| format!("{stem}-mode-{k}.csv")));
    }
    names
}

/// What an export writes: the state on screen and the path that reached it.
#[derive(Clone, Copy, Debug)]
pub struct Export<'a> {
    /// The case's label, in the file names and headers.
    pub label: &'a str,
    pub snapshot: &'a Snapshot,
    pub path: &'a [LoadPoint],
    /// The conditions of each point of `path`.
    pub conditions: &'a [BoundaryConditions],
    pub events: &'a [SessionEvent],
    /// The critical points crossed on the path, and the mode of each.
    pub critical: &'a [CriticalPoint],
    pub modes: &'a [CriticalMode],
}

/// The load table of `spira run` with the conditions of each point (`conditions[k]` for
/// `path[k]`) in a last column and the session's events as `# event` comment lines.
pub fn load_csv(
    label: &str,
    path: &[LoadPoint],
    conditions: &[BoundaryConditions],
    events: &[SessionEvent],
) -> String {
    let base = output::load_csv(label, path);
    let mut out = String::with_capacity(base.len() + 64 * path.len());
    let mut row = 0usize;
    let mut header_done = false;
    for line in base.lines() {
        if line.starts_with('#') {
            out.push_str(line);
            out.push('\n');
            continue;
        }
        if !header_done {
            out.push_str("# conditions: the boundary conditions the point was solved under\n");
            for e in events {
                out.push_str(&format!(
                    "# event: from point {} (eps asked {}): {}\n",
                    e.from_point,
                    asked(e.parameter),
                    output::csv::comment_safe(&e.what)
                ));
            }
            out.push_str(line);
            out.push_str(",conditions\n");
            header_done = true;
            continue;
        }
        out.push_str(line);
        out.push(',');
        if let Some(bc) = conditions.get(row) {
            out.push_str(&bc.label());
        }
        out.push('\n');
        row += 1;
    }
    out
}

/// The load parameter an event asked for, to 6 decimals (short where that would be long).
fn asked(parameter: f64) -> String {
    if parameter.is_finite() && parameter.abs() < 1e6 {
        format!("{parameter:.6}")
    } else {
        crate::case::num(parameter)
    }
}

/// Writes the tables of `export` into `dir` (those of [`names`], as `spira run` writes
/// them); returns the files written.
pub fn write(dir: &Path, export: &Export) -> std::io::Result<Vec<PathBuf>> {
    let last = export
        .path
        .last()
        .ok_or_else(|| std::io::Error::other("no converged state yet"))?;
    let label = export.label;
    let mut texts = vec![
        output::state_csv(label, export.snapshot),
        load_csv(label, export.path, export.conditions, export.events),
        output::reactions_csv(label, export.path),
    ];
    if !export.critical.is_empty() {
        texts.push(output::critical_csv(label, export.critical));
        for (k, (c, m)) in export.critical.iter().zip(export.modes).enumerate() {
            texts.push(output::mode_table(label, k, c, &m.vertices));
        }
    }
    let names = names(
        label,
        last.step,
        last.compression_ratio,
        export.critical.len(),
    );
    if texts.len() != names.len() {
        return Err(std::io::Error::other(format!(
            "{} critical points but {} modes",
            export.critical.len(),
            export.modes.len()
        )));
    }
    // no table with a cell that holds no number, as `spira run` writes none
    for text in &texts {
        output::check_finite(text).map_err(std::io::Error::other)?;
    }
    std::fs::create_dir_all(dir)?;
    let mut files = Vec::new();
    for (name, text) in names.iter().zip(texts) {
        let file = dir.join(name);
        output::write_atomic(&file, &text)?;
        files.push(file);
    }
    Ok(files)
}
