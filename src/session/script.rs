//! A session as a small TOML script of the jobs the solver ran, saved by the explorer and
//! replayed headless by `spira replay SESSION.toml --out DIR` through the same solver code
//! ([`worker::run_jobs`]), so the replay writes the explorer's CSVs.

use super::export::{self, SessionEvent};
use super::worker::{self, Job, WorkerEvent};
use crate::case::Case;
use crate::model::boundary::BoundaryConditions;
use crate::results::{LoadPoint, Snapshot};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One job of a session, as a script says it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case")]
pub enum Action {
    /// A new simulation with `helices` helices under `boundary`, at `ε = 0`.
    Start {
        helices: usize,
        boundary: BoundaryConditions,
    },
    /// Continue the path to `ε = eps`.
    Advance { eps: f64 },
    /// Change the boundary conditions at the current `ε`.
    Boundary { boundary: BoundaryConditions },
}

/// A saved session.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Script {
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
            }),
            Job::Advance(eps) => Some(Action::Advance { eps: *eps }),
            Job::SetBoundary(bc) => Some(Action::Boundary { boundary: *bc }),
            Job::Precision(_) => None,
        }
    }

    fn job(&self, case: &Case) -> Job {
        match self {
            Action::Start { helices, boundary } => {
                let mut c = case.with_helices(*helices);
                c.boundary = *boundary;
                Job::Start(Box::new(c))
            }
            Action::Advance { eps } => Job::Advance(*eps),
            Action::Boundary { boundary } => Job::SetBoundary(*boundary),
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

    pub fn read(path: &Path) -> Result<Script, ScriptError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScriptError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        toml::from_str(&text).map_err(|source| ScriptError::Parse {
            path: path.to_path_buf(),
            source,
        })
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
