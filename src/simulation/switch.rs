//! Branch switching at a critical point: within the model solved (along the engine's
//! critical mode, or along the directions of the plane of a double point's modes) and from
//! a reduced model onto the whole assembly (along the mode rebuilt there). Where a plane of
//! modes offers several directions, they are tried in the order of the energy of the first
//! step along them.

use super::problem::LoadedAssembly;
use super::{Simulation, SolveError};
use crate::discretisation::constraints;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::mirror::Mirror;
use crate::discretisation::system::System;
use crate::results::CriticalPoint;
use crate::solver::continuation::{ContinuationError, StopReason};
use crate::solver::problem::Problem;
use std::f64::consts::{FRAC_PI_2, PI};

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
                    self.switch_in_plane(&cp, &cp.mode, second, sign, h)?;
                    return self.fix_phase();
                }
            }
            self.path
                .switch_branch(index, sign, h)
                .map_err(|e| self.error(e))?;
            return self.fix_phase();
        };
        self.switch_to_whole(&cp, sign, h)
    }

    /// On a branch that has left the axis of a problem that turns freely about it
    /// ([`DiscreteModel::turns_freely_about_axis`]), the phase condition that fixes the
    /// state on its circle of equal states: the branch is then followed as any other,
    /// without the neutral direction the circle gives every state of it. Nothing changes
    /// for any other problem, or when the condition is already held.
    ///
    /// [`DiscreteModel::turns_freely_about_axis`]: crate::discretisation::discrete_model::DiscreteModel::turns_freely_about_axis
    pub(super) fn fix_phase(&mut self) -> Result<(), SolveError> {
        if self.system().has_phase() || !self.model().turns_freely_about_axis(self.loads()) {
            return Ok(());
        }
        let Some(phase) = constraints::axis_phase(self.model(), self.state()) else {
            return Ok(());
        };
        let system = self.system().with_phase(self.model(), self.state(), phase);
        let Some(row) = system.phase_row() else {
            return Ok(());
        };
        let problem = LoadedAssembly::new(self.model().clone(), system).with_threads(self.threads);
        self.path.constrain(problem, row).map_err(|e| self.error(e))
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
        let (directions, across) = in_plane(&full, mode, cp.second_mode.as_deref(), m);
        let order = {
            let mut probe = LoadedAssembly::new(full.clone(), system.clone());
            by_energy(&mut probe, &x, cp.parameter, &directions, sign, h)
        };
        let threads = self.threads;
        let j = in_turn(order, |j| {
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
        .map_err(|e| self.error(e))?;
        self.hold_across(across.get(j), &x)
    }

    /// After a switch along a fixed line of the mirror: holds the component of the state
    /// along `across` (the direction of the plane the mirror reverses) at its value in the
    /// critical state `x` — a phase condition that the branch, kept by the mirror,
    /// satisfies with no force, and that removes the nearly neutral direction in which it
    /// would turn in the plane (the cyclic symmetry fixes that turn only at high order).
    fn hold_across(&mut self, across: Option<&Vec<f64>>, x: &[f64]) -> Result<(), SolveError> {
        // the mirrors' two kinds of branch differ at the order m of the cyclic symmetry:
        // up to the quartic terms that shape the branch (m ≤ 4) the turn in the plane is a
        // direction like any other, counted; beyond, it is nearly neutral, and held
        if self.model().rods.len() / 2 < NEARLY_CONTINUOUS {
            return Ok(());
        }
        let mirror = Mirror::of(self.model());
        let phase = across
            .zip(mirror.as_ref())
            .and_then(|(d, mirror)| constraints::mirror_phase(self.model(), mirror, d, x));
        let Some(phase) = phase.filter(|_| !self.system().has_phase()) else {
            return Ok(());
        };
        let system = self.system().with_phase(self.model(), self.state(), phase);
        let Some(row) = system.phase_row() else {
            return Ok(());
        };
        let problem = LoadedAssembly::new(self.model().clone(), system).with_threads(self.threads);
        self.path.constrain(problem, row).map_err(|e| self.error(e))
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
        let (directions, across) = in_plane(self.model(), a, Some(b), m);
        let rods = self.path.problem_mut();
        let order = by_energy(rods, &cp.state, cp.parameter, &directions, sign, h);
        let (x, lambda) = (self.path.state().x.clone(), self.path.state().lambda);
        self.path.problem_mut().restore(&x, lambda);
        let j = in_turn(order, |j| {
            self.path
                .switch_onto(&cp.state, cp.parameter, &directions[j], sign, h)
        })
        .map_err(|e| self.error(e))?;
        self.hold_across(across.get(j), &cp.state)
    }
}

/// The order `m` of the cyclic symmetry from which a wavenumber-1 double point is held in
/// its mirror's plane after a switch (see `hold_across`): the energy of a turn of the
/// branch in the plane of its modes is then of order `A^m` in its amplitude `A`, beyond the
/// quartic terms that shape the branch.
const NEARLY_CONTINUOUS: usize = 5;

/// The directions to leave a critical point along, and for each the direction of the plane
/// the branch must not turn in (empty when there is none to hold): its mode `a` alone, or
/// with the other mode `b` of a double point (`b` padded with zeros to the length of `a`)
/// the directions `cos φ a + sin φ b` where the branches of the `m`-fold symmetric tube
/// leave — for `m ≥ NEARLY_CONTINUOUS`, the fixed lines of its mirrors, `φ = θ + jπ/m`
/// from the line `θ` of the mirror `y ↦ −y` of `model` ([`Mirror`]), each with the
/// direction at `φ + π/2` its mirror reverses, where the tube and its conditions have that
/// mirror; else `2m` directions `φ = jπ/2m` from `a`, among which the energy of the first
/// step chooses.
fn in_plane(
    model: &DiscreteModel,
    a: &[f64],
    b: Option<&[f64]>,
    m: usize,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let Some(b) = b else {
        return (vec![a.to_vec()], Vec::new());
    };
    let mut b = b.to_vec();
    b.resize(a.len(), 0.0);
    let combine =
        |c: [f64; 2]| -> Vec<f64> { a.iter().zip(&b).map(|(a, b)| c[0] * a + c[1] * b).collect() };
    // (for m ≤ 4 the path finds its line itself: the turn in the plane is no flatter than
    // any other direction of the branch)
    let mirrored = Mirror::of(model)
        .filter(|_| m >= NEARLY_CONTINUOUS)
        .and_then(|mirror| mirror.fixed_line(model, a, &b));
    if let Some(plane) = mirrored {
        let phi = |j: usize| plane.theta + j as f64 * PI / m as f64;
        let along = (0..m).map(|j| combine(plane.along(phi(j)))).collect();
        let across = (0..m)
            .map(|j| combine(plane.along(phi(j) + FRAC_PI_2)))
            .collect();
        return (along, across);
    }
    let along = (0..2 * m)
        .map(|j| {
            let phi = j as f64 * PI / (2 * m) as f64;
            combine([phi.cos(), phi.sin()])
        })
        .collect();
    (along, Vec::new())
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

/// `switch` along the directions of `order` in turn until one succeeds, returning its
/// index; the last failure when none does.
fn in_turn(
    order: Vec<usize>,
    mut switch: impl FnMut(usize) -> Result<(), ContinuationError>,
) -> Result<usize, ContinuationError> {
    let mut last = None;
    for j in order {
        match switch(j) {
            Ok(()) => return Ok(j),
            Err(e) => last = Some(e),
        }
    }
    Err(last.expect("at least one direction tried"))
}
