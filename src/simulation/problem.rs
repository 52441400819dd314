//! The discrete assembly as a continuation problem: the KKT system of a discrete model under
//! boundary conditions, loaded through its tips by the load parameter (DESIGN.md §3, §5).
//!
//! Under displacement control `λ = ε`, the compression ratio, and the tips are held at
//! `h = h0 (1 − ε)`; under load control `λ = P / Pcrit`, a dead compressive load on every
//! tip over the Euler load. Stability is judged on the full assembly: for a symmetric pair,
//! by the Bloch blocks of its KKT matrix, one per wavenumber (a symmetric state can lose
//! stability to modes that break the symmetry; they live in the blocks `p ≠ 0`).

use crate::discretisation::model::{DiscreteModel, End};
use crate::discretisation::symmetry::BlochBlocks;
use crate::discretisation::system::System;
use crate::model::loading::{Control, TipLoad};
use crate::solver::problem::Problem;
use crate::solver::stability::{InertiaError, KktStability, WarmStart};
use faer::sparse::SymbolicSparseColMat;

/// A discrete model under boundary conditions and a control of its tips.
pub struct RodProblem {
    pub(super) model: DiscreteModel,
    pub(super) system: System,
    pub(super) control: Control,
    /// `∂R/∂λ`: constant, since the load parameter enters the tip constraints or the dead
    /// load linearly.
    load_derivative: Vec<f64>,
    /// Where stability is judged: this model, or the full model behind a symmetric pair.
    judge: Judge,
}

/// The model on which stability is judged, with its buffers.
enum Judge {
    Own {
        stability: KktStability,
        residual: Vec<f64>,
        values: Vec<f64>,
    },
    Blocks(Box<Blocks>),
}

/// The Bloch blocks of a symmetric pair, one per wavenumber (DESIGN.md §7).
struct Blocks {
    bloch: BlochBlocks,
    /// The real blocks `p = 0` and `p = m/2`, in the pair's pattern.
    zero: KktStability,
    half: KktStability,
    /// The complex blocks, written as real ones; one factorisation pattern for all, with a
    /// warm start of inverse iteration for each wavenumber.
    complex: KktStability,
    warm: Vec<WarmStart>,
    residual: Vec<f64>,
    /// The pair's KKT values, and a block's.
    pair: Vec<f64>,
    real: Vec<f64>,
    realified: Vec<f64>,
    /// The wavenumber of the lowest eigenvalue found last.
    lowest_wavenumber: usize,
}

/// Tributary arc length of every primal unknown: the metric of the eigenproblem
/// (quaternion unknowns weighted by their node's share of the rod, positions zero).
fn metric(model: &DiscreteModel) -> Vec<f64> {
    let mut m = vec![0.0; model.n_primal];
    let p = model.order.degree();
    for rod in &model.rods {
        for e in 0..rod.mesh.elements() {
            let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
            for a in 0..=p {
                let w = if a == 0 || a == p {
                    h / (2.0 * p as f64)
                } else {
                    h / p as f64
                };
                for k in 0..4 {
                    m[rod.q_dof(e * p + a, k)] += w;
                }
            }
        }
    }
    m
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

impl RodProblem {
    /// The problem of `system` (built on `model`) under `control`.
    pub fn new(model: DiscreteModel, system: System, control: Control) -> RodProblem {
        let rate = TipLoad::rate(control, model.height0(), pcrit(&model));
        let load_derivative = system
            .load_derivative(&model)
            .into_iter()
            .map(|v| v * rate)
            .collect();
        let judge = match BlochBlocks::new(&model, &system) {
            Some(bloch) => {
                let metric = metric(&model);
                let warm = vec![WarmStart::default(); bloch.m / 2 + 1];
                Judge::Blocks(Box::new(Blocks {
                    complex: KktStability::with_copies(bloch.realified_metric(&metric), 2),
                    realified: vec![0.0; bloch.realified_pattern().row_idx().len()],
                    zero: KktStability::new(metric.clone()),
                    half: KktStability::new(metric),
                    bloch,
                    warm,
                    residual: vec![0.0; system.n],
                    pair: system.new_values(),
                    real: system.new_values(),
                    lowest_wavenumber: 0,
                }))
            }
            None => Judge::Own {
                stability: KktStability::new(metric(&model)),
                residual: vec![0.0; system.n],
                values: system.new_values(),
            },
        };
        RodProblem {
            model,
            system,
            control,
            load_derivative,
            judge,
        }
    }

    /// The tip loading at load parameter `lambda`.
    pub fn tip_load(&self, lambda: f64) -> TipLoad {
        tip_load(&self.model, self.control, lambda)
    }

    /// Whether this is a symmetric pair, its stability judged by Bloch blocks.
    pub fn is_symmetric_pair(&self) -> bool {
        matches!(self.judge, Judge::Blocks(_))
    }

    /// `f` applied to the stability of every block at state `x` (the KKT values do not
    /// depend on the load parameter: it enters the residual only): of the model itself,
    /// or of each wavenumber `p` of a symmetric pair, with the number of wavenumbers the
    /// block stands for.
    fn each_block<T>(
        &mut self,
        x: &[f64],
        mut f: impl FnMut(&SymbolicSparseColMat<usize>, &[f64], &mut KktStability) -> T,
    ) -> Vec<(usize, usize, T)> {
        match &mut self.judge {
            Judge::Own {
                stability,
                residual,
                values,
            } => {
                self.system.evaluate(&self.model, x, residual, values);
                vec![(0, 1, f(self.system.pattern(), values, stability))]
            }
            Judge::Blocks(b) => {
                let b = b.as_mut();
                self.system
                    .evaluate(&self.model, x, &mut b.residual, &mut b.pair);
                let pattern = self.system.pattern();
                let mut out = Vec::new();
                for p in b.bloch.wavenumbers() {
                    let value = b.block(pattern, p, &mut f);
                    out.push((p, b.bloch.multiplicity(p), value));
                }
                out
            }
        }
    }

    /// Unstable directions of every distinct block at `x`: `(wavenumber, multiplicity,
    /// count)`; one block of wavenumber 0 for a model without the symmetry.
    pub fn unstable_directions_per_block(
        &mut self,
        x: &[f64],
    ) -> Result<Vec<(usize, usize, usize)>, InertiaError> {
        self.each_block(x, |pattern, values, s| {
            s.unstable_directions(pattern, values)
        })
        .into_iter()
        .map(|(p, k, c)| c.map(|c| (p, k, c)))
        .collect()
    }

    /// The lowest eigenvalue over the blocks at `x` and its wavenumber. Only the block that
    /// had the lowest eigenvalue last time is iterated on for sure; every other block is
    /// first asked, by one inertia count, whether it has an eigenvalue below that one.
    pub fn lowest_eigenvalue_with_wavenumber(&mut self, x: &[f64]) -> Option<(f64, usize)> {
        let b = match &mut self.judge {
            Judge::Own { .. } => {
                let all = self.each_block(x, |pat, v, s| s.lowest_eigenvalue(pat, v));
                return all
                    .into_iter()
                    .next()
                    .and_then(|(p, _, l)| l.map(|l| (l, p)));
            }
            Judge::Blocks(b) => b.as_mut(),
        };
        self.system
            .evaluate(&self.model, x, &mut b.residual, &mut b.pair);
        let pattern = self.system.pattern();
        let first = b.lowest_wavenumber;
        let mut best = (
            b.block(pattern, first, |pat, v, s| s.lowest_eigenvalue(pat, v))?,
            first,
        );
        for p in b.bloch.wavenumbers().filter(|&p| p != first) {
            let below = b.block(pattern, p, |pat, v, s| s.count_below(pat, v, best.0));
            if below.ok()? > 0 {
                let l = b.block(pattern, p, |pat, v, s| s.lowest_eigenvalue(pat, v))?;
                if l < best.0 {
                    best = (l, p);
                }
            }
        }
        b.lowest_wavenumber = best.1;
        Some(best)
    }
}

impl Blocks {
    /// `f` on block `p` at the pair's KKT values in `self.pair`.
    fn block<T>(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        p: usize,
        f: impl FnOnce(&SymbolicSparseColMat<usize>, &[f64], &mut KktStability) -> T,
    ) -> T {
        if p == 0 {
            f(pattern, &self.pair, &mut self.zero)
        } else if self.bloch.is_real(p) {
            self.bloch.real_block(p, &self.pair, &mut self.real);
            f(pattern, &self.real, &mut self.half)
        } else {
            self.bloch.complex_block(p, &self.pair, &mut self.realified);
            self.complex.swap_warm_start(&mut self.warm[p]);
            let v = f(
                self.bloch.realified_pattern(),
                &self.realified,
                &mut self.complex,
            );
            self.complex.swap_warm_start(&mut self.warm[p]);
            v
        }
    }
}

/// Euler load of the model's rods, `Pcrit = B1 (2π/L)²` (N): the unit of `λ` under load
/// control.
pub fn pcrit(model: &DiscreteModel) -> f64 {
    model.stiffness.euler_load(model.length())
}

fn tip_load(model: &DiscreteModel, control: Control, lambda: f64) -> TipLoad {
    TipLoad::at(control, lambda, model.height0(), pcrit(model))
}

impl Problem for RodProblem {
    fn unknowns(&self) -> usize {
        self.system.n
    }

    fn primal_unknowns(&self) -> usize {
        self.model.n_primal
    }

    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        self.system.pattern()
    }

    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        self.system.set_tip_load(self.tip_load(lambda));
        self.system.residual(&self.model, x, residual).energy
    }

    fn jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: &mut [f64],
    ) -> f64 {
        self.system.set_tip_load(self.tip_load(lambda));
        self.system
            .evaluate(&self.model, x, residual, jacobian)
            .energy
    }

    fn load_derivative(&mut self, _x: &[f64], _lambda: f64, out: &mut [f64]) {
        out.copy_from_slice(&self.load_derivative);
    }

    fn load_derivative_is_constant(&self) -> bool {
        true
    }

    fn unstable_directions(&mut self, x: &[f64], _lambda: f64) -> Result<usize, InertiaError> {
        Ok(self
            .unstable_directions_per_block(x)?
            .iter()
            .map(|(_, k, c)| k * c)
            .sum())
    }

    fn lowest_eigenvalue(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        self.lowest_eigenvalue_with_wavenumber(x).map(|(l, _)| l)
    }

    /// Over the blocks, the eigenvalue nearest zero.
    fn eigenvalue_nearest_zero(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        let all = self.each_block(x, |pattern, values, s| {
            s.eigenvalue_nearest_zero(pattern, values)
        });
        let mut nearest: Option<f64> = None;
        for (_, _, mu) in all {
            let mu = mu?;
            if nearest.is_none_or(|best| mu.abs() < best.abs()) {
                nearest = Some(mu);
            }
        }
        nearest
    }

    /// The system keeps the tip load of the converged point (reactions are read from it).
    fn restore(&mut self, _x: &[f64], lambda: f64) {
        self.system.set_tip_load(self.tip_load(lambda));
    }
}
