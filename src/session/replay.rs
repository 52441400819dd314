//! A session file read with the places of its actions, and replayed: every action checked
//! before anything runs ([`check`]), then run one at a time through the solver thread's
//! code; an action that cannot be done is refused with the explorer's message, naming the
//! file, the action and its line, and nothing is written.

use super::check;
use super::error::ScriptError;
use super::export;
use super::script::{Action, Script, VERSION};
use super::worker::{Runner, WorkerEvent};
use crate::case::Case;
use crate::model::boundary::BoundaryConditions;
use crate::output::csv::comment_safe;
use crate::results::{LoadPoint, Snapshot};
use std::path::{Path, PathBuf};

/// A session file as read: its script, the file's name for messages and the line of each
/// action.
#[derive(Clone, Debug, PartialEq)]
pub struct Session {
    pub script: Script,
    /// The file, as messages name it.
    pub file: String,
    /// The line (from 1) where each action starts.
    pub lines: Vec<usize>,
}

impl Session {
    /// Reads a session file of any version up to [`VERSION`].
    pub fn read(path: &Path) -> Result<Session, ScriptError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScriptError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Session::parse(&text, path)
    }

    /// A session from the text of a session file (`path` names it in errors), of any
    /// version up to [`VERSION`].
    pub fn parse(text: &str, path: &Path) -> Result<Session, ScriptError> {
        let file = path.display().to_string();
        let spans = check::action_spans(text);
        let script: Script = toml::from_str(text).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            // the place the `toml` crate gives for an error in an array of tables is the
            // array's: the action at fault is found by reading each on its own
            let (line, action, message) = match check::first_bad_action(text) {
                Some((k, message)) => (session_line(text, &spans, k), Some(k + 1), message),
                None => (
                    check::line_of(text, at),
                    check::action_at(text, &spans, at).map(|k| k + 1),
                    e.message().trim().to_string(),
                ),
            };
            ScriptError::Parse {
                file: file.clone(),
                line,
                action,
                message: comment_safe(&message),
            }
        })?;
        if !(1..=VERSION).contains(&script.version) {
            let line = text
                .lines()
                .position(|l| {
                    l.trim_start()
                        .strip_prefix("version")
                        .is_some_and(|r| r.trim_start().starts_with('='))
                })
                .map_or(1, |i| i + 1);
            return Err(ScriptError::Version {
                file,
                line,
                version: script.version,
            });
        }
        let lines = spans
            .iter()
            .map(|s| check::line_of(text, s.start))
            .collect();
        Ok(Session {
            script,
            file,
            lines,
        })
    }

    /// `script` as the file `file` would hold it once saved (the lines of its actions are
    /// those of [`Script::to_toml`]).
    pub fn of(script: Script, file: &Path) -> Session {
        let lines = script
            .to_toml()
            .map(|text| {
                check::action_spans(&text)
                    .iter()
                    .map(|s| check::line_of(&text, s.start))
                    .collect()
            })
            .unwrap_or_default();
        Session {
            script,
            file: file.display().to_string(),
            lines,
        }
    }

    /// The line of action `k` (from 0; the first line when it is not known).
    pub fn line(&self, k: usize) -> usize {
        self.lines.get(k).copied().unwrap_or(1)
    }

    /// Action `k` (from 0) refused before it ran, for `message`.
    pub(super) fn refused(&self, k: usize, message: String) -> ScriptError {
        ScriptError::Refused {
            file: self.file.clone(),
            line: self.line(k),
            number: k + 1,
            kind: self.script.actions.get(k).map_or("start", Action::kind),
            message: comment_safe(&message),
        }
    }

    /// Action `k` (from 0) that the solver could not do, for `reason`.
    fn failed(&self, k: usize, reason: String) -> ScriptError {
        ScriptError::Failed {
            file: self.file.clone(),
            line: self.line(k),
            number: k + 1,
            kind: self.script.actions.get(k).map_or("start", Action::kind),
            reason: comment_safe(&reason),
        }
    }
}

/// The line of action `k` (from 0) of `text` whose actions start at `spans`.
fn session_line(text: &str, spans: &[std::ops::Range<usize>], k: usize) -> usize {
    spans.get(k).map_or(1, |s| check::line_of(text, s.start))
}

/// What a replay reached: the path, the conditions of each point and the last state.
#[derive(Clone, Debug)]
pub struct Replayed {
    pub path: Vec<LoadPoint>,
    pub conditions: Vec<BoundaryConditions>,
    pub snapshot: Snapshot,
}

/// Runs `session` on `case` (the case its `case` names) through the solver's code, every
/// action checked first; an action that cannot be done ends the replay with its refusal.
pub fn replay(session: &Session, case: &Case) -> Result<Replayed, ScriptError> {
    let jobs = check::jobs(session, case)?;
    let mut runner = Runner::new();
    let mut path = Vec::new();
    let mut conditions = Vec::new();
    let mut snapshot = None;
    for (k, (action, job)) in session.script.actions.iter().zip(jobs).enumerate() {
        if let Action::Switch { index, .. } = *action {
            let found = runner.critical_points();
            if index >= found {
                return Err(session.refused(k, no_critical_point(index, found)));
            }
        }
        for event in runner.run(job) {
            match event {
                WorkerEvent::Solved { state, .. } => {
                    path.push(state.point);
                    conditions.push(state.boundary);
                    snapshot = Some(state.snapshot);
                }
                // a part of the way ends on the interrupt raised after its steps
                WorkerEvent::Failed {
                    reason,
                    interrupted,
                    ..
                } if interrupted.is_none() || !action.is_part() => {
                    return Err(session.failed(k, reason));
                }
                _ => {}
            }
        }
    }
    let snapshot =
        snapshot.ok_or_else(|| session.failed(0, "no converged state was reached".into()))?;
    Ok(Replayed {
        path,
        conditions,
        snapshot,
    })
}

/// "index: no critical point k": the path has found `found` so far.
fn no_critical_point(index: usize, found: usize) -> String {
    match found {
        0 => format!("index: the path has found no critical point to switch at, found index {index}"),
        1 => format!("index: the path has found one critical point (index 0), found index {index}"),
        _ => format!(
            "index: the path has found {found} critical points (indices 0 to {}), found index {index}",
            found - 1
        ),
    }
}

/// Replays `session` on `case` and writes the explorer's export of its last state into
/// `dir`.
pub fn replay_into(
    session: &Session,
    case: &Case,
    dir: &Path,
) -> Result<Vec<PathBuf>, ScriptError> {
    let r = replay(session, case)?;
    let script = &session.script;
    export::write(
        dir,
        &script.label,
        &r.snapshot,
        &r.path,
        &r.conditions,
        &script.events,
    )
    .map_err(|source| ScriptError::Io {
        path: dir.to_path_buf(),
        source,
    })
}
