//! A session replayed: every action checked before anything runs (`check`), then run one
//! at a time through the solver thread's code; an action that cannot be done is refused
//! with the explorer's message, naming the file, the action and its line, and nothing is
//! written.

use super::check;
use super::error::ScriptError;
use super::export;
use super::script::{Action, Session};
use super::worker::{CriticalMode, Runner, WorkerEvent};
use crate::case::Case;
use crate::model::boundary::BoundaryConditions;
use crate::results::{CriticalPoint, LoadPoint, Snapshot};
use std::path::{Path, PathBuf};

/// What a replay reached: the path, the conditions of each point, the last state, and
/// the critical points crossed with their modes.
#[derive(Clone, Debug)]
pub struct Replayed {
    pub path: Vec<LoadPoint>,
    pub conditions: Vec<BoundaryConditions>,
    pub snapshot: Snapshot,
    pub critical: Vec<CriticalPoint>,
    pub modes: Vec<CriticalMode>,
}

/// Runs `session` on `case` (the case its `case` names) through the solver's code, every
/// action checked first; an action that cannot be done ends the replay with its refusal.
pub fn replay(session: &Session, case: &Case) -> Result<Replayed, ScriptError> {
    let jobs = check::jobs(session, case)?;
    let mut runner = Runner::new();
    let mut path = Vec::new();
    let mut conditions = Vec::new();
    let mut snapshot = None;
    let (mut critical, mut modes) = (Vec::new(), Vec::new());
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
                    critical.extend(state.critical);
                    modes.extend(state.modes);
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
        critical,
        modes,
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
        &export::Export {
            label: &script.label,
            snapshot: &r.snapshot,
            path: &r.path,
            conditions: &r.conditions,
            events: &script.events,
            critical: &r.critical,
            modes: &r.modes,
        },
    )
    .map_err(|source| ScriptError::Io {
        path: dir.to_path_buf(),
        source,
    })
}
