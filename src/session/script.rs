//! A session as a small TOML script of the jobs the solver ran, saved by the explorer and
//! replayed headless by `spira replay SESSION.toml --out DIR` through the same solver code
//! (`worker::run_jobs`), so the replay writes the explorer's CSVs.
//!
//! The format has a version ([`VERSION`]). Version 2 names the load parameter `λ` (the
//! compression ratio `ε` under displacement control, `P/Pcrit` under load control)
//! `parameter`, in the actions and the events:
//!
//! ```toml
//! version = 2
//! label = "thesis"
//!
//! [[events]]
//! from_point = 1
//! parameter = 0.0
//! what = "tip translation slide"
//!
//! [[actions]]
//! do = "advance"
//! parameter = 0.05
//! ```
//!
//! Version 1 (no `version` key) called it `eps`; it is still read.

pub use super::error::ScriptError;
use super::export::SessionEvent;
use super::worker::Job;
use crate::model::boundary::BoundaryConditions;
use crate::model::loading::Component;
use crate::output::csv::comment_safe;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// One job of a session, as a script says it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Action {
    /// A new simulation with `helices` helices under `boundary`, at `λ = 0`.
    Start {
        helices: usize,
        boundary: BoundaryConditions,
        /// The load component stepped (axial when not given).
        #[serde(default = "axial", skip_serializing_if = "is_axial")]
        load: Component,
    },
    /// Continue the path to load parameter `parameter`; with `steps`, stop after that many
    /// accepted internal steps with the next one `step_length` long (a step the explorer's
    /// user cancelled part of the way, replayed to the state it reached).
    Advance {
        #[serde(alias = "eps")]
        parameter: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        steps: Option<usize>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step_length: Option<f64>,
    },
    /// Switch onto the branch of bifurcation `index` (of the critical points found since
    /// the start, from 0) on the side `sign` (±1), and follow it to load parameter
    /// `parameter`.
    Switch {
        index: usize,
        sign: f64,
        #[serde(alias = "eps")]
        parameter: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        steps: Option<usize>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step_length: Option<f64>,
    },
    /// Change the boundary conditions at the current `λ`.
    Boundary { boundary: BoundaryConditions },
}

fn axial() -> Component {
    Component::Axial
}

fn is_axial(c: &Component) -> bool {
    *c == Component::Axial
}

/// The version of the session format written: 2 names the load parameter `parameter`
/// (version 1, without a `version` key, named it by its symbol under displacement control).
pub const VERSION: u32 = 2;

/// A saved session.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Script {
    /// The version of the format the file was written in (1 when it has no `version` key).
    #[serde(default = "first_version")]
    pub version: u32,
    /// The case file (`None`: the built-in case).
    pub case: Option<PathBuf>,
    /// The keys of the case overridden on the command line (`--set key=value`), applied to
    /// the case before the actions.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub set: Vec<String>,
    /// The case label the exports are named after.
    pub label: String,
    /// The session's events since the last start (for the load table's header).
    #[serde(default)]
    pub events: Vec<SessionEvent>,
    /// The jobs since the last start, in the order the solver ran them.
    pub actions: Vec<Action>,
}

/// The version of a file without a `version` key.
fn first_version() -> u32 {
    1
}

impl Action {
    /// The script's action for a job (`None` for jobs a replay does not need).
    pub fn of(job: &Job) -> Option<Action> {
        match job {
            Job::Start(case) => Some(Action::Start {
                helices: case.geometry.helices,
                boundary: case.boundary,
                load: case.loading.parameter,
            }),
            Job::Advance(parameter) => Some(Action::Advance {
                parameter: *parameter,
                steps: None,
                step_length: None,
            }),
            Job::AdvancePart { parameter, part } => Some(Action::Advance {
                parameter: *parameter,
                steps: Some(part.steps),
                step_length: Some(part.step_length),
            }),
            Job::Switch {
                index,
                sign,
                parameter,
                part,
            } => Some(Action::Switch {
                index: *index,
                sign: *sign,
                parameter: *parameter,
                steps: part.map(|p| p.steps),
                step_length: part.map(|p| p.step_length),
            }),
            Job::SetBoundary(bc) => Some(Action::Boundary { boundary: *bc }),
            Job::Precision(_) | Job::Curve(_) => None,
        }
    }

    /// The action's `do`.
    pub fn kind(&self) -> &'static str {
        match self {
            Action::Start { .. } => "start",
            Action::Advance { .. } => "advance",
            Action::Switch { .. } => "switch",
            Action::Boundary { .. } => "boundary",
        }
    }

    /// Whether the action is a part of the way (stopped after its `steps`).
    pub(super) fn is_part(&self) -> bool {
        matches!(
            self,
            Action::Advance { steps: Some(_), .. } | Action::Switch { steps: Some(_), .. }
        )
    }

    /// The action stopped from outside after `steps` accepted internal steps with the
    /// next `step_length` long (see `WorkerEvent::Stopped`).
    pub fn stopped_after(&mut self, at: usize, length: f64) {
        match self {
            Action::Advance {
                steps, step_length, ..
            }
            | Action::Switch {
                steps, step_length, ..
            } => {
                *steps = Some(at);
                *step_length = Some(length);
            }
            Action::Start { .. } | Action::Boundary { .. } => {}
        }
    }
}

impl Script {
    /// The script of the jobs `ran` (only those from the last start on are kept).
    pub fn of(
        case: Option<PathBuf>,
        label: String,
        events: Vec<SessionEvent>,
        ran: &[Job],
    ) -> Script {
        let from = ran
            .iter()
            .rposition(|j| matches!(j, Job::Start(_)))
            .unwrap_or(0);
        Script {
            version: VERSION,
            case,
            set: Vec::new(),
            label,
            events,
            actions: ran[from..].iter().filter_map(Action::of).collect(),
        }
    }

    pub fn to_toml(&self) -> Result<String, ScriptError> {
        Ok(format!(
            "# spira session: replay with `spira replay FILE --out DIR`\n{}",
            toml::to_string(self)?
        ))
    }

    /// Reads a session file of any version up to [`VERSION`].
    pub fn read(path: &Path) -> Result<Script, ScriptError> {
        Session::read(path).map(|s| s.script)
    }

    /// A session from the text of a session file (`path` names it in errors), of any
    /// version up to [`VERSION`].
    pub fn parse(text: &str, path: &Path) -> Result<Script, ScriptError> {
        Session::parse(text, path).map(|s| s.script)
    }

    pub fn write(&self, path: &Path) -> Result<(), ScriptError> {
        let text = self.to_toml()?;
        crate::output::write_atomic(path, &text).map_err(|source| ScriptError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

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
        let spans = action_spans(text);
        let script: Script = read_script(text).map_err(|(e, key)| {
            let at = e.span().map_or(0, |s| s.start);
            // the place the `toml` crate gives for an error in an array of tables is the
            // array's: the action at fault is found by reading each on its own
            let (line, action, key, message) = match first_bad_action(text) {
                Some((k, message)) => (session_line(text, &spans, k), Some(k + 1), None, message),
                None => (
                    line_of(text, at),
                    action_at(text, &spans, at).map(|k| k + 1),
                    key,
                    e.message().trim().to_string(),
                ),
            };
            ScriptError::Parse {
                file: file.clone(),
                line,
                action,
                key,
                message: comment_safe(&crate::case::plain_types(&message)),
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
                newest: VERSION,
            });
        }
        let lines = spans.iter().map(|s| line_of(text, s.start)).collect();
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
                action_spans(&text)
                    .iter()
                    .map(|s| line_of(&text, s.start))
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
    pub(super) fn failed(&self, k: usize, reason: String) -> ScriptError {
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
    spans.get(k).map_or(1, |s| line_of(text, s.start))
}

/// The actions of a session file as TOML values with their places, read leniently (any
/// other key is ignored) to say where an action is.
#[derive(Deserialize)]
struct Layout {
    #[serde(default)]
    actions: Vec<Spanned<toml::Value>>,
}

/// Where the actions of `text` start (byte ranges: the `[[actions]]` header, or the inline
/// table); none when the text is not TOML or its `actions` not an array.
pub(super) fn action_spans(text: &str) -> Vec<Range<usize>> {
    toml::from_str::<Layout>(text)
        .map(|l| l.actions.iter().map(Spanned::span).collect())
        .unwrap_or_default()
}

/// The first action of `text` (from 0) that is not an action on its own, and why: the
/// place of an error the `toml` crate gives for an array of tables is the array's.
pub(super) fn first_bad_action(text: &str) -> Option<(usize, String)> {
    let layout = toml::from_str::<Layout>(text).ok()?;
    layout.actions.into_iter().enumerate().find_map(|(k, a)| {
        a.into_inner()
            .try_into::<Action>()
            .err()
            .map(|e| (k, e.message().trim().to_string()))
    })
}

/// The script of a session file's text, or the `toml` crate's error with the dotted key
/// (outside the actions) it is about, when it is about one.
fn read_script(text: &str) -> Result<Script, (toml::de::Error, Option<String>)> {
    let document = toml::Deserializer::parse(text).map_err(|e| (e, None))?;
    serde_path_to_error::deserialize(document).map_err(|e| {
        use serde_path_to_error::Segment;
        let keys: Vec<&str> = e
            .path()
            .iter()
            .filter_map(|s| match s {
                Segment::Map { key } if !key.starts_with("$__") => Some(key.as_str()),
                _ => None,
            })
            .collect();
        let key = (!keys.is_empty() && keys[0] != "actions").then(|| keys.join("."));
        (e.into_inner(), key)
    })
}

/// The line (from 1) of byte `at` of `text`.
pub(super) fn line_of(text: &str, at: usize) -> usize {
    let at = at.min(text.len());
    text.as_bytes()[..at]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The action (from 0) whose text holds byte `at`: the last one starting before it, unless
/// it is an inline table that ends before `at` or a table of another name comes between.
pub(super) fn action_at(text: &str, spans: &[Range<usize>], at: usize) -> Option<usize> {
    let k = spans.iter().rposition(|s| s.start <= at)?;
    let span = &spans[k];
    let own = text.get(span.clone())?;
    if own.starts_with('{') {
        return (at < span.end).then_some(k);
    }
    let between = text.get(span.start..at.min(text.len()))?;
    let foreign = between.lines().skip(1).any(|l| {
        let t = l.trim_start();
        t.starts_with('[') && !t.starts_with("[actions") && !t.starts_with("[[actions")
    });
    (!foreign).then_some(k)
}
