//! A whole load path from a case: the headless face shared by the CLI, the benchmark and
//! the tests.

use crate::case::Case;
use crate::results::{LoadPoint, Snapshot};
use crate::solver::continuation::{SolveError, Statistics};
use std::time::{Duration, Instant};

/// What a path produced: every converged output step (step 0 is the natural state), the
/// last converged state, statistics, and the error that stopped it early, if any.
#[derive(Clone, Debug)]
pub struct PathOutcome {
    pub points: Vec<LoadPoint>,
    pub snapshot: Snapshot,
    pub stats: Statistics,
    /// System size (unknowns including multipliers).
    pub unknowns: usize,
    pub error: Option<SolveError>,
}

/// Solves `case` from `ε = 0` through the output values of `eps`, calling `on_step` with
/// each converged output point and the wall time of that step. A failure at `ε = 0` is an
/// error; a later failure ends the path and is returned in [`PathOutcome::error`], and
/// the last converged state (between two output values) becomes the last point, so that
/// the points and the snapshot describe the same state.
pub fn run_path(
    case: &Case,
    eps: &[f64],
    mut on_step: impl FnMut(&LoadPoint, Duration),
) -> Result<PathOutcome, SolveError> {
    let t0 = Instant::now();
    let mut sim = case.simulation()?;
    let first = sim.load_point(0);
    on_step(&first, t0.elapsed());
    let mut points = vec![first];
    let mut error = None;
    for (k, &e) in eps.iter().enumerate() {
        let t = Instant::now();
        if let Err(err) = sim.advance_to(e) {
            if (sim.parameter() - points.last().map_or(0.0, |p| p.parameter)).abs() > 0.0 {
                let p = sim.load_point(k + 1);
                on_step(&p, t.elapsed());
                points.push(p);
            }
            error = Some(err);
            break;
        }
        let p = sim.load_point(k + 1);
        on_step(&p, t.elapsed());
        points.push(p);
    }
    Ok(PathOutcome {
        points,
        snapshot: sim.snapshot(),
        stats: sim.stats,
        unknowns: sim.system().n,
        error,
    })
}
