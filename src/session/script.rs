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

use super::export::{self, SessionEvent};
use super::worker::{self, Job, Part, WorkerEvent};
use crate::case::Case;
use crate::model::boundary::BoundaryConditions;
use crate::model::loading::Component;
use crate::results::{LoadPoint, Snapshot};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One job of a session, as a script says it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case")]
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

/// Why a session could not be saved, read or replayed.
#[derive(Debug, thiserror::Error)]
pub enum ScriptError {
    #[error("reading or writing {path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("session file {path}: {source}")]
    Parse {
        path: PathBuf,
        #[source]
        source: toml::de::Error,
    },
    #[error("writing the session: {0}")]
    Serialise(#[from] toml::ser::Error),
    #[error(
        "session file {path} is of version {version}; this spira reads versions 1 to {VERSION}"
    )]
    Version { path: PathBuf, version: u32 },
    #[error("the session has no start action")]
    NoStart,
    #[error("replaying the session: {0}")]
    Failed(String),
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
            Job::Precision(_) => None,
        }
    }

    /// The job that replays the action.
    fn job(&self, case: &Case) -> Job {
        let part = |steps: Option<usize>, step_length: Option<f64>| {
            steps.map(|steps| Part {
                steps,
                step_length: step_length.unwrap_or(0.0),
            })
        };
        match *self {
            Action::Start {
                helices,
                ref boundary,
                load,
            } => {
                let mut c = case.with_helices(helices);
                c.boundary = *boundary;
                // a load the scene cannot carry is refused before the jobs run (`replay`)
                if let Ok(stepped) = c.with_stepped(load) {
                    c = stepped;
                }
                Job::Start(Box::new(c))
            }
            Action::Advance {
                parameter,
                steps,
                step_length,
            } => match part(steps, step_length) {
                Some(part) => Job::AdvancePart { parameter, part },
                None => Job::Advance(parameter),
            },
            Action::Switch {
                index,
                sign,
                parameter,
                steps,
                step_length,
            } => Job::Switch {
                index,
                sign,
                parameter,
                part: part(steps, step_length),
            },
            Action::Boundary { boundary } => Job::SetBoundary(boundary),
        }
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
        let text = std::fs::read_to_string(path).map_err(|source| ScriptError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Script::parse(&text, path)
    }

    /// A session from the text of a session file (`path` names it in errors), of any
    /// version up to [`VERSION`].
    pub fn parse(text: &str, path: &Path) -> Result<Script, ScriptError> {
        let script: Script = toml::from_str(text).map_err(|source| ScriptError::Parse {
            path: path.to_path_buf(),
            source,
        })?;
        if !(1..=VERSION).contains(&script.version) {
            return Err(ScriptError::Version {
                path: path.to_path_buf(),
                version: script.version,
            });
        }
        Ok(script)
    }

    pub fn write(&self, path: &Path) -> Result<(), ScriptError> {
        let text = self.to_toml()?;
        crate::output::write_atomic(path, &text).map_err(|source| ScriptError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// What a replay reached: the path, the conditions of each point and the last state.
#[derive(Clone, Debug)]
pub struct Replayed {
    pub path: Vec<LoadPoint>,
    pub conditions: Vec<BoundaryConditions>,
    pub snapshot: Snapshot,
    /// The failures on the way (as the explorer showed them).
    pub failures: Vec<String>,
}

/// Runs `script` on `case` (the case its `case` names) through the solver's code.
pub fn replay(script: &Script, case: &Case) -> Result<Replayed, ScriptError> {
    if !matches!(script.actions.first(), Some(Action::Start { .. })) {
        return Err(ScriptError::NoStart);
    }
    for (k, action) in script.actions.iter().enumerate() {
        if let Action::Start { load, helices, .. } = *action {
            if let Err(why) = case.with_helices(helices).with_stepped(load) {
                return Err(ScriptError::Failed(format!(
                    "action {} (start stepping the {}): {why}",
                    k + 1,
                    load.name()
                )));
            }
        }
    }
    let jobs: Vec<Job> = script.actions.iter().map(|a| a.job(case)).collect();
    let mut path = Vec::new();
    let mut conditions = Vec::new();
    let mut snapshot = None;
    let mut failures = Vec::new();
    for event in worker::run_jobs(jobs) {
        match event {
            WorkerEvent::Solved { state, .. } => {
                path.push(state.point);
                conditions.push(state.boundary);
                snapshot = Some(state.snapshot);
            }
            WorkerEvent::Failed { reason, .. } => failures.push(reason),
            _ => {}
        }
    }
    let snapshot = snapshot.ok_or_else(|| ScriptError::Failed(failures.join("; ")))?;
    Ok(Replayed {
        path,
        conditions,
        snapshot,
        failures,
    })
}

/// Replays `script` on `case` and writes the explorer's export of its last state into
/// `dir`.
pub fn replay_into(script: &Script, case: &Case, dir: &Path) -> Result<Vec<PathBuf>, ScriptError> {
    let r = replay(script, case)?;
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
