//! The work the solver thread is asked for, and the scheduling of the requests that pile
//! up while a solve runs: every step asked for is solved, a run of other changes only for
//! its last.

use crate::case::{Case, DesignKey};
use crate::model::boundary::BoundaryConditions;
use std::collections::VecDeque;

/// Work for the solver. A load parameter `λ` is the continuation parameter of the case's
/// control: the compression ratio `ε` under displacement control, `P/Pcrit` under load
/// control.
#[derive(Clone, Debug, PartialEq)]
pub enum Job {
    /// Build a new simulation from `case` (its `n` and boundary conditions) and solve the
    /// natural state at `λ = 0`.
    Start(Box<Case>),
    /// Continue the path to load parameter `λ`.
    Advance(f64),
    /// Continue the path towards load parameter `parameter` and stop after `steps`
    /// accepted internal steps, leaving the next internal step `step_length` long: a step
    /// that was cancelled part of the way, replayed to the state it reached.
    AdvancePart { parameter: f64, part: Part },
    /// Leave the path at bifurcation `index` (of the simulation's critical points) onto
    /// its branch, on the side `sign` (±1), and continue along it to load parameter
    /// `parameter` (with `part`: only that part of the way, as [`Job::AdvancePart`]).
    Switch {
        index: usize,
        sign: f64,
        parameter: f64,
        part: Option<Part>,
    },
    /// Change the boundary conditions and re-solve at the current `λ` from the current state.
    SetBoundary(BoundaryConditions),
    /// A work-precision study of `case`'s path (on the precision thread).
    Precision(Box<Case>),
    /// The critical curve of a scene in one of its design keys (on the curve thread).
    Curve(Box<CurveJob>),
}

/// The critical curve of the scene `case`: its first critical point continued in `key`
/// from the key's value to `(1 ± width)` times it, `rows_each` rows on each side (the
/// value itself one of them).
#[derive(Clone, Debug, PartialEq)]
pub struct CurveJob {
    pub case: Case,
    pub key: DesignKey,
    pub width: f64,
    pub rows_each: usize,
}

impl Job {
    /// Whether `later`, queued right after this job, makes it of no use: a change of the
    /// conditions or a branch switch replaced by another of the same kind. A step is never
    /// replaced: each one asked for is a point of the path.
    fn replaced_by(&self, later: &Job) -> bool {
        matches!(
            (self, later),
            (Job::SetBoundary(_), Job::SetBoundary(_)) | (Job::Switch { .. }, Job::Switch { .. })
        )
    }

    /// What the solver is doing, for the status line, with `symbol` the load parameter's
    /// (`ε` under displacement control).
    pub fn describe(&self, symbol: &str) -> String {
        match self {
            Job::Start(case) => format!("natural state, n = {}", case.geometry.helices),
            Job::Advance(parameter) | Job::AdvancePart { parameter, .. } => {
                format!("{symbol} → {parameter:.5}")
            }
            Job::Switch {
                index, parameter, ..
            } => {
                format!("branch of critical point {index}, {symbol} → {parameter:.5}")
            }
            Job::SetBoundary(_) => "new boundary conditions".to_string(),
            Job::Precision(case) => {
                format!("work-precision study, n = {}", case.geometry.helices)
            }
            Job::Curve(c) => format!("critical curve in {}", c.key.key()),
        }
    }
}

/// The part of the way a stopped solve got: `steps` accepted internal steps, and the
/// length of the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    pub steps: usize,
    pub step_length: f64,
}

/// A job tagged with the app's generation (bumped by every [`Job::Start`]) and a sequence
/// number (increasing over all requests), which the answers carry back.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub generation: u64,
    pub seq: u64,
    pub job: Job,
}

/// Drops the requests a later one replaces: everything before the last `Start` (a new
/// simulation), then a change of the conditions or a branch switch directly followed by
/// another of its kind. Steps ([`Job::Advance`]) are all kept, so that quick key presses
/// give as many points as slow ones; the survivors keep their order.
pub fn coalesce(queue: &mut VecDeque<Request>) {
    if let Some(last_start) = queue.iter().rposition(|r| matches!(r.job, Job::Start(_))) {
        queue.drain(..last_start);
    }
    let jobs: Vec<Job> = queue.iter().map(|r| r.job.clone()).collect();
    let mut k = 0;
    queue.retain(|_| {
        let keep = jobs
            .get(k + 1)
            .is_none_or(|later| !jobs[k].replaced_by(later));
        k += 1;
        keep
    });
}
