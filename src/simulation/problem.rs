//! The discrete assembly as a continuation problem: the KKT system of a discrete model under
//! boundary conditions, loaded through its tips by the load parameter (docs/theory.md §3, §5).
//!
//! Under displacement control `λ = ε`, the compression ratio, and the tips are held at
//! `h = h0 (1 − ε)`; under load control `λ = P / Pcrit`, a dead compressive load on every
//! tip over the Euler load. Stability is judged on the whole assembly, by the judge of the
//! model's reduction ([`super::reduction`]).

use super::judge::{all_cores, lowest_of, BlockStability, StabilityJudge};
use super::reduction::{self, CriticalModes, Reduction};
use crate::discretisation::discrete_model::{DiscreteModel, End};
use crate::discretisation::system::System;
use crate::results::Stability;
use crate::solver::continuation::Critical;
use crate::solver::problem::Problem;
use crate::solver::stability::{InertiaError, KktStructure};
use faer::sparse::SymbolicSparseColMat;
use std::sync::Arc;

/// A discrete model under its supports and loads (its system's, functions of the load
/// parameter): what the continuation follows.
pub struct LoadedAssembly {
    pub(super) model: DiscreteModel,
    pub(super) system: System,
    /// How the model stands for the whole assembly.
    reduction: Box<dyn Reduction>,
    /// Where stability is judged: the whole assembly the model stands for.
    judge: Box<dyn StabilityJudge>,
}

/// Mean tip height over the rods of `model` in state `x` (m).
pub fn mean_tip_height(model: &DiscreteModel, x: &[f64]) -> f64 {
    let n = model.rods.len() as f64;
    model
        .rods
        .iter()
        .enumerate()
        .map(|(id, r)| model.vertex(x, id, r.end_vertex(End::Tip))[2])
        .sum::<f64>()
        / n
}

impl LoadedAssembly {
    /// The problem of `system` (built on `model`, loaded by the system's loads), its block
    /// work on all the cores.
    pub fn new(model: DiscreteModel, system: System) -> LoadedAssembly {
        let reduction = reduction::of(&model);
        let judge = reduction.judge(&model, &system, all_cores());
        LoadedAssembly {
            model,
            system,
            reduction,
            judge,
        }
    }

    /// The same problem with its block work (a cyclic pair's Bloch blocks) shared out on
    /// `threads` threads (at least one).
    pub fn with_threads(mut self, threads: usize) -> LoadedAssembly {
        self.set_threads(threads);
        self
    }

    /// Shares the block work (a cyclic pair's Bloch blocks) out on `threads` threads (at
    /// least one) from now on.
    pub fn set_threads(&mut self, threads: usize) {
        self.judge.set_threads(threads);
    }

    /// How the model solved stands for the whole assembly.
    pub fn reduction(&self) -> &dyn Reduction {
        self.reduction.as_ref()
    }

    /// The stability of every distinct block at `x` (the KKT values do not depend on the
    /// load parameter: it enters the residual only), with the lowest eigenvalue over the
    /// blocks when `eigenvalue` is asked for; one block of wavenumber 0 for a model judged
    /// on itself.
    pub fn block_stability(
        &mut self,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        self.judge.blocks(&self.model, &self.system, x, eigenvalue)
    }

    /// The lowest eigenvalue over the blocks at `x` and its wavenumber.
    pub fn lowest_eigenvalue_with_wavenumber(&mut self, x: &[f64]) -> Option<(f64, usize)> {
        lowest_of(&self.block_stability(x, true).ok()?)
    }

    /// The eigenvalue nearest zero at `x` of the block a critical-point search focuses on,
    /// or over every block, with its wavenumber and the block's mode (primal unknowns of
    /// the block: the model's, or real then imaginary parts for a complex block).
    pub fn nearest_zero_with_mode(&mut self, x: &[f64]) -> Option<(f64, usize, Vec<f64>)> {
        self.judge
            .nearest_zero_with_mode(&self.model, &self.system, x)
    }

    /// The eigenvector (primal unknowns of the block) of the eigenvalue nearest zero of
    /// block `p` at `x`: a critical mode of wavenumber `p`.
    pub fn block_mode(&mut self, x: &[f64], p: usize) -> Option<Vec<f64>> {
        self.judge.block_mode(&self.model, &self.system, x, p)
    }

    /// The eigenvalue nearest zero of block `p` at `x` (J/m; for a stable state the block's
    /// lowest) and its mode, as [`LoadedAssembly::nearest_zero_with_mode`] gives them.
    pub fn block_nearest_zero(&mut self, x: &[f64], p: usize) -> Option<(f64, Vec<f64>)> {
        self.judge.focus(Some(p));
        let found = self.nearest_zero_with_mode(x);
        self.judge.focus(None);
        found.map(|(mu, _, mode)| (mu, mode))
    }

    /// The modes of the critical point `critical`, on the whole assembly for a reduced
    /// model.
    pub fn critical_modes(&mut self, critical: &Critical) -> CriticalModes {
        self.reduction
            .critical_modes(&self.model, &self.system, self.judge.as_mut(), critical)
    }

    /// Per block, the unstable directions at `x` (for the wavenumber whose count changes).
    fn counts(&mut self, x: &[f64]) -> Option<Vec<usize>> {
        self.block_stability(x, false)
            .ok()
            .map(|v| v.iter().map(|s| s.unstable_directions).collect())
    }
}

/// Euler load of the model's rods, `Pcrit = B1 (2π/L)²` (N): the unit of `λ` under load
/// control.
pub fn pcrit(model: &DiscreteModel) -> f64 {
    model.stiffness.euler_load(model.length())
}

impl Problem for LoadedAssembly {
    fn unknowns(&self) -> usize {
        self.system.n
    }

    /// The mean tip above the base (`h > 0`), for a tube; any state of straight rods on
    /// the axis, whose ends are points that may pass each other (the elastica's loops).
    fn out_of_domain(&self, x: &[f64]) -> Option<&'static str> {
        let on_axis = self.model.rods.iter().all(|r| r.helix.radius == 0.0);
        if !on_axis && mean_tip_height(&self.model, x) <= 0.0 {
            return Some("the tip at or below the base");
        }
        if crossings_pass(&self.model, x) {
            return Some("two sliding crossings of one rod meet: the two rods of one hand that make them touch there, and the model has no contact between them (past it they would pass through each other)");
        }
        None
    }

    fn primal_unknowns(&self) -> usize {
        self.model.n_primal
    }

    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        self.system.pattern()
    }

    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        self.system.set_parameter(lambda);
        self.system.residual(&self.model, x, residual).energy
    }

    fn jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: &mut [f64],
    ) -> f64 {
        self.system.set_parameter(lambda);
        self.system
            .evaluate(&self.model, x, residual, jacobian)
            .energy
    }

    fn eigenvalue_scale(&self) -> f64 {
        self.model.stiffness.b1 / self.model.length().powi(2)
    }

    /// The structure of the stability's real blocks: the model's own pattern, metric and
    /// length.
    fn kkt_structure(&self) -> Option<Arc<KktStructure>> {
        self.judge.kkt_structure(self.system.pattern())
    }

    fn residual_weights(&self, weights: &mut [f64]) {
        self.system.residual_weights(&self.model, weights);
    }

    /// From the loads at `lambda`.
    fn load_derivative(&mut self, x: &[f64], lambda: f64, out: &mut [f64]) {
        self.system.load_derivative(&self.model, x, lambda, out);
    }

    fn load_derivative_is_constant(&self) -> bool {
        self.system.load_derivative_is_constant()
    }

    fn unstable_directions(&mut self, x: &[f64], _lambda: f64) -> Result<usize, InertiaError> {
        Ok(self
            .block_stability(x, false)?
            .iter()
            .map(|s| s.multiplicity * s.unstable_directions)
            .sum())
    }

    fn lowest_eigenvalue(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        self.lowest_eigenvalue_with_wavenumber(x).map(|(l, _)| l)
    }

    fn stability(
        &mut self,
        x: &[f64],
        _lambda: f64,
        eigenvalue: bool,
    ) -> Result<Stability, InertiaError> {
        let blocks = self.block_stability(x, eigenvalue)?;
        let lowest = lowest_of(&blocks);
        Ok(Stability {
            unstable_directions: blocks
                .iter()
                .map(|s| s.multiplicity * s.unstable_directions)
                .sum(),
            lowest_eigenvalue: lowest.map(|(l, _)| l),
            lowest_wavenumber: lowest
                .filter(|_| self.judge.has_wavenumbers())
                .map(|(_, p)| p),
        })
    }

    /// The eigenvalue nearest zero of the focused block, or over the blocks.
    fn eigenvalue_nearest_zero(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        self.nearest_zero_with_mode(x).map(|(mu, _, _)| mu)
    }

    /// The first wavenumber whose count differs between `x0` and `x1`.
    fn focus_on_crossing(&mut self, x0: &[f64], x1: &[f64]) -> usize {
        let (Some(a), Some(b)) = (self.counts(x0), self.counts(x1)) else {
            return 0;
        };
        if !self.judge.has_wavenumbers() {
            return 0;
        }
        let p = a.iter().zip(&b).position(|(u, v)| u != v).unwrap_or(0);
        self.judge.focus(Some(p));
        p
    }

    fn clear_focus(&mut self) {
        self.judge.focus(None);
    }

    fn counts_points(&self) -> bool {
        self.judge.counts_points()
    }

    /// The system keeps the tip load of the converged point (reactions are read from it).
    fn restore(&mut self, _x: &[f64], lambda: f64) {
        self.system.set_parameter(lambda);
    }
}

/// Whether two sliding crossings of one rod have met or passed each other in the state `x`:
/// along every rod the contacts' arc lengths keep the order of their natural ones, which two
/// rods of one hand crossing it at the same point would break.
fn crossings_pass(model: &DiscreteModel, x: &[f64]) -> bool {
    let mut contacts: Vec<(usize, f64, f64)> = Vec::new();
    for (k, &joint) in model.slides.iter().enumerate() {
        let j = &model.assembly.joints[joint];
        for (side, rod) in [j.right, j.left].into_iter().enumerate() {
            contacts.push((rod, j.s, x[model.slide_dof(k, side)]));
        }
    }
    contacts.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    contacts
        .windows(2)
        .any(|w| w[0].0 == w[1].0 && w[1].2 <= w[0].2)
}
