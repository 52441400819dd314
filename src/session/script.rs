//! A session as a small TOML script of the jobs the solver ran, saved by the explorer and
//! replayed headless by `spira replay SESSION.toml --out DIR` through the same solver code
//! ([`worker::run_jobs`]), so the replay writes the explorer's CSVs.
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
pub use super::replay::{replay, replay_into, Replayed, Session};
use super::worker::Job;
use crate::model::boundary::BoundaryConditions;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One job of a session, as a script says it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Action {
    /// A new simulation with `helices` helices under `boundary`, at `λ = 0`.
    Start {
        helices: usize,
        boundary: BoundaryConditions,
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
            Job::Precision(_) => None,
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
    /// next `step_length` long (see [`WorkerEvent::Stopped`]).
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
