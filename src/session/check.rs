//! A session's actions checked before anything runs, by the case reader's limits and the
//! explorer's rules: a start goes through the case reader's checks of a number of helices
//! and of supports, a load parameter must be one the case admits, a branch is taken on the
//! side +1 or −1, new supports may leave no rigid motion free.

use super::error::ScriptError;
use super::script::{Action, Session};
use super::worker::{Job, Part};
use crate::case::{available_memory, num, Case, STEP_RANGE};

/// The jobs of `session`'s actions on `case`, every action checked first: the first one a
/// start, each start's number of helices and supports through the case reader's checks and
/// its size within the memory, each load parameter within the case's range, each side of a
/// branch ±1, each step length within the case reader's range, each change of supports
/// without a free rigid motion.
pub(super) fn jobs(session: &Session, case: &Case) -> Result<Vec<Job>, ScriptError> {
    let actions = &session.script.actions;
    if !matches!(actions.first(), Some(Action::Start { .. })) {
        return Err(ScriptError::NoStart {
            file: session.file.clone(),
            line: session.line(0),
        });
    }
    let mut current = case.clone();
    let mut jobs = Vec::with_capacity(actions.len());
    for (k, action) in actions.iter().enumerate() {
        let refuse = |message: String| session.refused(k, message);
        jobs.push(match *action {
            Action::Start {
                helices,
                boundary,
                load,
            } => {
                current = start_case(case, helices, boundary, load).map_err(refuse)?;
                Job::Start(Box::new(current.clone()))
            }
            Action::Advance {
                parameter,
                steps,
                step_length,
            } => {
                check_parameter(&current, parameter).map_err(refuse)?;
                match part(steps, step_length).map_err(refuse)? {
                    Some(part) => Job::AdvancePart { parameter, part },
                    None => Job::Advance(parameter),
                }
            }
            Action::Switch {
                index,
                sign,
                parameter,
                steps,
                step_length,
            } => {
                if sign != 1.0 && sign != -1.0 {
                    return Err(refuse(format!(
                        "sign: expected the side of the branch, 1 or -1, found {}",
                        num(sign)
                    )));
                }
                check_parameter(&current, parameter).map_err(refuse)?;
                Job::Switch {
                    index,
                    sign,
                    parameter,
                    part: part(steps, step_length).map_err(refuse)?,
                }
            }
            Action::Boundary { boundary } => {
                if let Some(motion) = current.free_motion(&boundary) {
                    return Err(refuse(format!(
                        "boundary: {} ({})",
                        motion.message,
                        boundary.label()
                    )));
                }
                current.boundary = boundary;
                Job::SetBoundary(boundary)
            }
        });
    }
    Ok(jobs)
}

/// The case of a start action: `case` with `helices` helices under `boundary`, refused as
/// the case reader refuses a file's `geometry.helices` and `[boundary]`, and when the
/// model the explorer solves would not fit in the memory.
fn start_case(
    case: &Case,
    helices: usize,
    boundary: crate::model::boundary::BoundaryConditions,
    load: crate::model::loading::Component,
) -> Result<Case, String> {
    let c = case
        .with_helices_checked(helices)
        .map_err(|r| format!("helices = {helices}: {}", r.message))?;
    let mut c = c
        .with_stepped(load)
        .map_err(|why| format!("load = \"{}\": {why}", load.name()))?;
    if let Some(motion) = c.free_motion(&boundary) {
        return Err(format!(
            "boundary: {} ({})",
            motion.message,
            boundary.label()
        ));
    }
    c.boundary = boundary;
    c.for_explorer()
        .size_estimate()
        .check_fits(available_memory())
        .map_err(|e| format!("helices = {helices}: {e}"))?;
    Ok(c)
}

/// A load parameter the case admits (finite, and within the geometry's limits under
/// displacement control).
fn check_parameter(case: &Case, parameter: f64) -> Result<(), String> {
    case.check_target(parameter)
        .map_err(|e| format!("parameter: {e}"))
}

/// The part of the way a stopped action got, with its step length in the case reader's
/// range of steps.
fn part(steps: Option<usize>, step_length: Option<f64>) -> Result<Option<Part>, String> {
    let (lo, hi) = STEP_RANGE;
    match (steps, step_length) {
        (_, Some(h)) if !(h >= lo && h <= hi) => Err(format!(
            "step_length: expected a positive step in the load parameter from {} to {}, found {}",
            num(lo),
            num(hi),
            num(h)
        )),
        (None, Some(_)) => Err("step_length is given without steps (a part of the way is the steps taken and the length of the next)".into()),
        (Some(steps), h) => Ok(Some(Part {
            steps,
            step_length: h.unwrap_or(0.0),
        })),
        (None, None) => Ok(None),
    }
}
