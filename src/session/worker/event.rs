//! What the solver thread reports: converged states and how each job went.

use crate::case::DesignKey;
use crate::model::boundary::BoundaryConditions;
use crate::results::{CriticalPoint, LoadPoint, ModeShape, ModeVertex, Snapshot, StepBulk};
use crate::simulation::curve::{CurveProgress, CurveRow};
use crate::solver::interrupt::Interruption;
use crate::study::{MeshChoice, Study};
use std::time::Duration;

/// A converged state as the screen needs it.
#[derive(Clone, Debug)]
pub struct Solved {
    pub point: LoadPoint,
    pub snapshot: Snapshot,
    /// The bulk of every rod of the state (`discretisation::bulk`).
    pub bulk: StepBulk,
    /// The conditions the state is under.
    pub boundary: BoundaryConditions,
    /// Internal continuation step length at this state.
    pub step_length: f64,
    /// Wall time of the job that produced it.
    pub time: Duration,
    /// Critical points crossed on the way to this state (without their state and mode).
    pub critical: Vec<CriticalPoint>,
    /// The mode of each of [`Solved::critical`], in the same order.
    pub modes: Vec<CriticalMode>,
    /// Whether the state is of the symmetric pair (else of the whole assembly).
    pub pair: bool,
}

/// A critical point's mode as the screen and the export need it.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalMode {
    /// The mode on the geometry of the critical state (for a symmetric pair, on the whole
    /// assembly): what the preview draws.
    pub shape: ModeShape,
    /// Its centreline displacement at the element vertices: the rows of `mode-<k>.csv`.
    pub vertices: Vec<ModeVertex>,
}

/// A critical curve of the scene, as far as it got.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveDone {
    pub key: DesignKey,
    /// Its rows in increasing order of the key.
    pub rows: Vec<CurveRow>,
    /// The load parameter's name and unit.
    pub parameter_label: String,
    /// Why a side stopped short of its end, per side that did.
    pub stopped: Vec<String>,
    /// It was cancelled (the rows are those found before).
    pub cancelled: bool,
}

/// What the solver thread reports.
#[derive(Clone, Debug)]
pub enum WorkerEvent {
    /// The job of request `seq` has started.
    Started {
        generation: u64,
        seq: u64,
        job: String,
    },
    /// A converged state; `done` is false when a failed job got part of the way and the
    /// failure follows.
    Solved {
        generation: u64,
        seq: u64,
        done: bool,
        state: Box<Solved>,
    },
    /// The job needed no solve (e.g. the conditions asked for are already in force).
    Unchanged { generation: u64, seq: u64 },
    /// The job of request `seq` is still solving: an internal step was accepted at load
    /// parameter `parameter` (`ε` under displacement control), `elapsed` after the job
    /// started.
    Progress {
        generation: u64,
        seq: u64,
        parameter: f64,
        steps: usize,
        elapsed: Duration,
    },
    /// The job of request `seq` was stopped from outside (cancelled, or out of time) after
    /// `steps` accepted internal steps of its continuation, with `step_length` the length
    /// of the next one: what a replay needs to reach the same state. `steps` is `None`
    /// when the job stopped before it changed anything (a branch switch that did not get
    /// onto the branch). Sent before the job's [`WorkerEvent::Failed`].
    Stopped {
        generation: u64,
        seq: u64,
        steps: Option<usize>,
        step_length: f64,
    },
    /// The job failed; the last converged state (if any) stays, under `boundary`.
    /// `interrupted` says when it was stopped from outside (cancelled, or out of time).
    Failed {
        generation: u64,
        seq: u64,
        reason: String,
        boundary: Option<BoundaryConditions>,
        interrupted: Option<Interruption>,
    },
    /// The case gives an accuracy: the mesh chosen for it (before the natural state).
    MeshChosen {
        generation: u64,
        seq: u64,
        choice: Box<MeshChoice>,
    },
    /// A work-precision study has solved `done` of its `total` meshes.
    PrecisionProgress {
        generation: u64,
        seq: u64,
        done: usize,
        total: usize,
    },
    /// A work-precision study is finished, or why it failed.
    Precision {
        generation: u64,
        seq: u64,
        study: Result<Box<Study>, String>,
    },
    /// A critical curve has got this far.
    CurveProgress {
        generation: u64,
        seq: u64,
        progress: CurveProgress,
    },
    /// A critical curve is finished (or stopped, or cancelled), or why there is none.
    Curve {
        generation: u64,
        seq: u64,
        outcome: Result<CurveDone, String>,
    },
}

impl WorkerEvent {
    pub fn generation(&self) -> u64 {
        match self {
            WorkerEvent::Started { generation, .. }
            | WorkerEvent::Solved { generation, .. }
            | WorkerEvent::Unchanged { generation, .. }
            | WorkerEvent::Stopped { generation, .. }
            | WorkerEvent::Failed { generation, .. }
            | WorkerEvent::Progress { generation, .. }
            | WorkerEvent::MeshChosen { generation, .. }
            | WorkerEvent::PrecisionProgress { generation, .. }
            | WorkerEvent::Precision { generation, .. }
            | WorkerEvent::CurveProgress { generation, .. }
            | WorkerEvent::Curve { generation, .. } => *generation,
        }
    }
}
