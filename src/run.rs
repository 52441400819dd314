//! A whole load path from a case: the headless face shared by the CLI, the benchmark and
//! the tests.

use crate::case::Case;
use crate::discretisation::bulk;
use crate::model::loading::Branch;
use crate::results::{CriticalKind, CriticalPoint};
use crate::results::{LoadPoint, ModeShape, Snapshot, StepBulk};
use crate::simulation::beam::{self, StepBeam};
use crate::simulation::cell::{self, StepDispersion};
use crate::simulation::flaw::ImperfectPath;
use crate::simulation::Simulation;
use crate::simulation::SolveError;
use crate::solver::continuation::Observer;
use crate::solver::continuation::StopReason;
use crate::solver::interrupt::Interrupt;
use crate::solver::stats::Statistics;
use std::time::{Duration, Instant};

/// Arclength (unit-norm mode over the primal unknowns) of the first step off a bifurcation.
pub const BRANCH_STEP: f64 = 0.05;

/// What a path produced: every converged output step (step 0 is the natural state), the
/// last converged state, statistics, the critical points found, and the error that stopped
/// it early, if any.
#[derive(Clone, Debug)]
pub struct PathOutcome {
    pub points: Vec<LoadPoint>,
    pub snapshot: Snapshot,
    pub stats: Statistics,
    /// System size (unknowns including multipliers).
    pub unknowns: usize,
    pub critical: Vec<CriticalPoint>,
    /// The bulk of every rod at every point of `points` (same order).
    pub bulk: Vec<StepBulk>,
    /// Each critical point's mode on the geometry of its state (same order as `critical`).
    pub modes: Vec<ModeShape>,
    /// The discrete model (for mode output).
    pub model: crate::discretisation::discrete_model::DiscreteModel,
    /// For the cell of an infinite tube: the dispersion of every output point's state, on
    /// [`cell::PHASES`] axial phases (empty for a finite assembly).
    pub dispersion: Vec<StepDispersion>,
    /// For the cell of an infinite tube: the tube as a beam at every output point (empty
    /// for a finite assembly).
    pub beam: Vec<StepBeam>,
    /// Index (in `critical`) of the bifurcation where the path left the fundamental branch.
    pub switched_at: Option<usize>,
    pub error: Option<SolveError>,
    /// For an imperfect case: where its path turns, against the perfect critical point.
    pub imperfection: Option<ImperfectPath>,
}

/// Solves `case` from the natural state through the output values `targets` of its load
/// parameter, calling `on_step` with each converged output point and the wall time of that
/// step. At the first bifurcation the path switches branch if the case asks for it. A
/// failure at the start is an error; a later failure ends the path and is returned in
/// [`PathOutcome::error`], and the last converged state (between two output values) becomes
/// the last point, so that the points and the snapshot describe the same state.
pub fn run_path(
    case: &Case,
    targets: &[f64],
    on_step: impl FnMut(&LoadPoint, Duration),
) -> Result<PathOutcome, SolveError> {
    run_path_with(case, targets, None, None, on_step)
}

/// As [`run_path`], stopping (with the path so far, as after a failure) when `interrupt`
/// is raised, and telling `observer` of every accepted internal step.
pub fn run_path_with(
    case: &Case,
    targets: &[f64],
    interrupt: Option<Interrupt>,
    observer: Option<Observer>,
    mut on_step: impl FnMut(&LoadPoint, Duration),
) -> Result<PathOutcome, SolveError> {
    run_path_steps(case, targets, interrupt, observer, |step| {
        on_step(step.point, step.time)
    })
}

/// What [`run_path_steps`] tells of each converged output point.
#[derive(Clone, Copy, Debug)]
pub struct Step<'a> {
    pub point: &'a LoadPoint,
    /// The shape of the state there.
    pub snapshot: &'a Snapshot,
    /// Its bulk.
    pub bulk: &'a StepBulk,
    /// Wall time of the step.
    pub time: Duration,
}

/// As [`run_path_with`], telling `on_step` of each output point's shape and bulk too (a
/// caller that writes every step's shape keeps them; the outcome keeps only the last).
pub fn run_path_steps(
    case: &Case,
    targets: &[f64],
    interrupt: Option<Interrupt>,
    observer: Option<Observer>,
    mut on_step: impl FnMut(&Step),
) -> Result<PathOutcome, SolveError> {
    let t0 = Instant::now();
    // the interrupt is in force from the natural state's solve on
    let mut sim = Simulation::from_case_with(case, interrupt, observer)?;
    let mut bulks: Vec<StepBulk> = Vec::new();
    let mut dispersion: Vec<StepDispersion> = Vec::new();
    let mut beam: Vec<StepBeam> = Vec::new();
    let mut report = |sim: &Simulation, p: &LoadPoint, time: Duration| {
        dispersion.extend(step_dispersion(sim, p));
        beam.extend(step_beam(sim, p));
        let snapshot = sim.snapshot();
        let b = bulk::step_bulk(sim.model(), &snapshot, p);
        on_step(&Step {
            point: p,
            snapshot: &snapshot,
            bulk: &b,
            time,
        });
        bulks.push(b);
    };
    let first = sim.load_point(0);
    report(&sim, &first, t0.elapsed());
    let mut points = vec![first];
    let mut error = None;
    let mut switched_at = None;
    let sign = match case.loading.branch {
        Branch::Fundamental => None,
        Branch::Switch => Some(1.0),
        Branch::SwitchNegative => Some(-1.0),
    };
    for (k, &target) in targets.iter().enumerate() {
        let t = Instant::now();
        if let Err(err) = advance_switching(&mut sim, target, sign, &mut switched_at) {
            if (sim.parameter() - points.last().map_or(0.0, |p| p.parameter)).abs() > 0.0 {
                let p = sim.load_point(k + 1);
                report(&sim, &p, t.elapsed());
                points.push(p);
            }
            // the error speaks of the path's target, not of the output step on the way
            let target = targets.last().copied().unwrap_or(err.target);
            error = Some(SolveError { target, ..err });
            break;
        }
        let p = sim.load_point(k + 1);
        report(&sim, &p, t.elapsed());
        points.push(p);
    }
    // a run asked to switch that never did has not answered its question
    if error.is_none() && sign.is_some() && switched_at.is_none() {
        error = Some(SolveError {
            control: sim.control(),
            reached: sim.parameter(),
            compression_ratio: sim.compression_ratio(),
            target: targets.last().copied().unwrap_or(0.0),
            step: 0.0,
            reason: StopReason::NoBifurcation,
        });
    }
    let modes = sim
        .critical_points()
        .iter()
        .map(|c| sim.mode_shape(c))
        .collect();
    let imperfection = sim
        .flaw()
        .map(|f| ImperfectPath::of(f, sim.critical_points(), &points));
    Ok(PathOutcome {
        imperfection,
        bulk: bulks,
        dispersion,
        beam,
        modes,
        points,
        snapshot: sim.snapshot(),
        stats: sim.statistics(),
        unknowns: sim.system().n,
        critical: sim.critical_points().to_vec(),
        model: sim.model().clone(),
        switched_at,
        error,
    })
}

/// Advances `sim` to `target`; when a `sign` asks to switch branch and the path has not
/// yet (`switched_at`), it leaves the path at the first bifurcation found, in that
/// direction, and goes on to `target` on the new branch.
fn advance_switching(
    sim: &mut Simulation,
    target: f64,
    sign: Option<f64>,
    switched_at: &mut Option<usize>,
) -> Result<(), SolveError> {
    sim.advance_to(target)?;
    let Some(sign) = sign.filter(|_| switched_at.is_none()) else {
        return Ok(());
    };
    let found = sim
        .critical_points()
        .iter()
        .position(|c| c.kind == CriticalKind::Bifurcation);
    let Some(i) = found else {
        return Ok(());
    };
    *switched_at = Some(i);
    // the points the output step located past the switch point are of the path left there
    sim.keep_critical_points(i + 1);
    sim.switch_branch(i, sign, BRANCH_STEP)?;
    sim.advance_to(target)
}

/// For the cell of an infinite tube, the tube as a beam at the state of output point `p`
/// (`None` too where its stiffnesses cannot be computed: a singular tangent).
fn step_beam(sim: &Simulation, p: &LoadPoint) -> Option<StepBeam> {
    let (model, system, x) = (sim.model(), sim.system(), sim.state());
    let stiffness = beam::beam_stiffness(model, system, x).ok()?;
    let curvature = beam::bending_by_curvature(model, system, x);
    Some(StepBeam {
        step: p.step,
        stiffness,
        bending: beam::bending_of(model, system, x),
        bending_curvature: curvature.as_ref().ok().map(|b| b.stiffness),
        bending_curvature_refused: curvature.err().map(|e| e.to_string()),
    })
}

/// For the cell of an infinite tube, the dispersion of the state of output point `p`.
fn step_dispersion(sim: &Simulation, p: &LoadPoint) -> Option<StepDispersion> {
    Some(StepDispersion {
        step: p.step,
        eps: p.compression_ratio,
        dispersion: sim.dispersion(cell::PHASES)?,
    })
}
