//! Branch switching at a critical point: within the model solved (along the engine's
//! critical mode, or along the directions of the plane of a double point's modes) and from
//! a reduced model onto the whole assembly (along the mode rebuilt there). Where a plane of
//! modes offers several directions, they are tried in the order of the energy of the first
//! step along them.

use super::problem::LoadedAssembly;
use super::{Simulation, SolveError};
use crate::discretisation::system::System;
use crate::results::CriticalPoint;
use crate::solver::continuation::{ContinuationError, StopReason};
use crate::solver::problem::Problem;

impl Simulation {
    /// Leaves the path at bifurcation `index` (of [`Simulation::critical_points`]) along
    /// its critical mode, in the direction `sign` (±1), by an arclength step of `h`
    /// measured along the mode; continuation then goes on in arclength steps along the new
    /// branch. A reduced model stays the model solved for a mode it keeps (a symmetric
    /// pair's of wavenumber 0); for any other mode (wavenumber `p ≠ 0`) the path moves onto
    /// the full model, from the critical state expanded onto every rod, along the mode
    /// rebuilt on the whole assembly.
    pub fn switch_branch(&mut self, index: usize, sign: f64, h: f64) -> Result<(), SolveError> {
        let breaking = self
            .critical
            .get(index)
            .filter(|c| !self.reduction().keeps(c))
            .cloned();
        // a critical point of a problem the path has left cannot be switched at
        let left = self
            .critical
            .get(index)
            .is_some_and(|c| c.state.len() != self.system().n && breaking.is_none());
        if left {
            return Err(self.refused(StopReason::LeftProblem { index }));
        }
        let Some(cp) = breaking else {
            if let Some(cp) = self.critical.get(index).cloned() {
                if let Some(second) = cp
                    .second_mode
                    .as_ref()
                    .filter(|_| cp.assembly_mode.is_none())
                {
                    return self.switch_in_plane(&cp, &cp.mode, second, sign, h);
                }
            }
            return self
                .path
                .switch_branch(index, sign, h)
                .map_err(|e| self.error(e));
        };
        self.switch_to_whole(&cp, sign, h)
    }

    /// The path's error for a switch refused at the current state.
    fn refused(&self, reason: StopReason) -> SolveError {
        let lambda = self.parameter();
        self.error(ContinuationError {
            reached: lambda,
            target: lambda,
            step: 0.0,
            reason,
        })
    }

    /// Leaves the critical point `cp` of the reduced model solved, whose mode breaks the
    /// reduction, on the whole assembly: from the critical state expanded there, along the
    /// mode rebuilt there (or the directions of the plane of a double point's two modes).
    fn switch_to_whole(&mut self, cp: &CriticalPoint, sign: f64, h: f64) -> Result<(), SolveError> {
        let whole = self.reduction().whole(self.model());
        let (Some(mode), Some(full)) = (cp.assembly_mode.as_ref(), whole) else {
            return Err(self.refused(StopReason::SymmetricPair));
        };
        let bc = self.boundary_conditions();
        let loads = self.loads().clone();
        let natural = System::new(&full, bc, &full.natural_state(), &loads, cp.parameter);
        let expand = |x: &[f64]| {
            let mut out = vec![0.0; natural.n];
            let (model, system) = (self.model(), self.system());
            self.reduction()
                .expand_state(model, system, x, &full, &natural, &mut out);
            out
        };
        let x = expand(&cp.state);
        // the reduced model's last accepted state on the whole assembly: a regular state
        // of the same path to re-solve the critical state from
        let near = expand(self.state());
        // the supports hold what they hold at the critical state, as the reduced model's did
        let system = System::new(&full, bc, &x[..full.n_primal], &loads, cp.parameter);
        // the branches of a double point leave it along particular directions of its
        // plane (where the symmetry's higher-order terms are extremal, at multiples of
        // π/2m for a wavenumber-1 mode): the directions φ = jπ/2m are tried in turn
        // — the one in which the energy falls most first (the block eigenvector's complex
        // phase, which fixes φ = 0, is arbitrary; the energy of the first step is not)
        let m = full.rods.len() / 2;
        let directions = in_plane(mode, cp.second_mode.as_deref(), m);
        let order = {
            let mut probe = LoadedAssembly::new(full.clone(), system.clone());
            by_energy(&mut probe, &x, cp.parameter, &directions, sign, h)
        };
        let threads = self.threads;
        in_turn(order, |j| {
            let problem = LoadedAssembly::new(full.clone(), system.clone()).with_threads(threads);
            let reduced = (self.model().clone(), self.system().clone());
            self.path.switch_onto_problem(
                problem,
                x.clone(),
                cp.parameter,
                &directions[j],
                sign,
                h,
                Some(near.clone()),
            )?;
            self.reduced = Some(Box::new(reduced));
            Ok(())
        })
        .map_err(|e| self.error(e))
    }

    /// Leaves the double critical point `cp` of the model solved along a direction of the
    /// plane of its modes `a`, `b`: the directions `φ = jπ/2m` (`cos φ a + sin φ b`, `m`
    /// half the rods) are tried in turn, the one in which the energy of the first step falls
    /// most first, as for a reduced model's double point (the phase of the modes in their
    /// plane is arbitrary; the energy is not).
    fn switch_in_plane(
        &mut self,
        cp: &CriticalPoint,
        a: &[f64],
        b: &[f64],
        sign: f64,
        h: f64,
    ) -> Result<(), SolveError> {
        let m = (self.model().rods.len() / 2).max(1);
        let directions = in_plane(a, Some(b), m);
        let rods = self.path.problem_mut();
        let order = by_energy(rods, &cp.state, cp.parameter, &directions, sign, h);
        let (x, lambda) = (self.path.state().x.clone(), self.path.state().lambda);
        self.path.problem_mut().restore(&x, lambda);
        in_turn(order, |j| {
            self.path
                .switch_onto(&cp.state, cp.parameter, &directions[j], sign, h)
        })
        .map_err(|e| self.error(e))
    }
}

/// The directions to leave a critical point along: its mode `a` alone, or with the other
/// mode `b` of a double point the `2m` directions `cos φ a + sin φ b`, `φ = jπ/2m`
/// (`b` padded with zeros to the length of `a`).
fn in_plane(a: &[f64], b: Option<&[f64]>, m: usize) -> Vec<Vec<f64>> {
    let Some(b) = b else {
        return vec![a.to_vec()];
    };
    (0..2 * m)
        .map(|j| {
            let phi = j as f64 * std::f64::consts::PI / (2 * m) as f64;
            let (c, s) = (phi.cos(), phi.sin());
            a.iter()
                .zip(b.iter().chain(std::iter::repeat(&0.0)))
                .map(|(a, b)| c * a + s * b)
                .collect()
        })
        .collect()
}

/// The indices of `directions` in the order of the energy of `problem` at `x` moved by
/// `sign h` along each (load parameter `lambda`; directions padded with zeros to the
/// length of `x`), lowest first; a direction whose energy is not finite comes last. The
/// problem keeps the tip load of the last probe.
fn by_energy(
    problem: &mut impl Problem,
    x: &[f64],
    lambda: f64,
    directions: &[Vec<f64>],
    sign: f64,
    h: f64,
) -> Vec<usize> {
    let mut residual = vec![0.0; x.len()];
    let mut order: Vec<(f64, usize)> = directions
        .iter()
        .enumerate()
        .map(|(j, d)| {
            let moved: Vec<f64> = x
                .iter()
                .zip(d.iter().chain(std::iter::repeat(&0.0)))
                .map(|(v, d)| v + sign * h * d)
                .collect();
            let e = problem.residual(&moved, lambda, &mut residual);
            (if e.is_finite() { e } else { f64::INFINITY }, j)
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    order.into_iter().map(|(_, j)| j).collect()
}

/// `switch` along the directions of `order` in turn until one succeeds; the last failure
/// when none does.
fn in_turn(
    order: Vec<usize>,
    mut switch: impl FnMut(usize) -> Result<(), ContinuationError>,
) -> Result<(), ContinuationError> {
    let mut last = None;
    for j in order {
        match switch(j) {
            Ok(()) => return Ok(()),
            Err(e) => last = Some(e),
        }
    }
    Err(last.expect("at least one direction tried"))
}
