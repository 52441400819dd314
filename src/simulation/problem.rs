//! The discrete assembly as a continuation problem: the KKT system of a discrete model under
//! boundary conditions, loaded through its tips by the load parameter (DESIGN.md §3, §5).
//!
//! Under displacement control `λ = ε`, the compression ratio, and the tips are held at
//! `h = h0 (1 − ε)`; under load control `λ = P / Pcrit`, a dead compressive load on every
//! tip over the Euler load. Stability is judged on the full assembly: for a symmetric pair,
//! on the full model at the pair's state expanded (a symmetric state can lose stability to
//! modes that break the symmetry).

use crate::discretisation::model::{DiscreteModel, End};
use crate::discretisation::symmetry::expand_state;
use crate::discretisation::system::System;
use crate::model::loading::{Control, TipLoad};
use crate::solver::problem::Problem;
use crate::solver::stability::{InertiaError, KktStability};
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
    Full(Box<FullModel>),
}

/// The full model behind a symmetric pair.
struct FullModel {
    model: DiscreteModel,
    system: System,
    stability: KktStability,
    /// The pair's state expanded to the full model.
    expanded: Vec<f64>,
    residual: Vec<f64>,
    values: Vec<f64>,
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
        let judge = match model.full_model() {
            Some(full) => {
                let x0 = full.natural_state();
                let tip = tip_load(&full, control, 0.0);
                let full_system = System::new(&full, system.bc, &x0, tip);
                Judge::Full(Box::new(FullModel {
                    stability: KktStability::new(metric(&full)),
                    expanded: vec![0.0; full_system.n],
                    residual: vec![0.0; full_system.n],
                    values: full_system.new_values(),
                    model: full,
                    system: full_system,
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

    /// Whether stability is judged on a full model standing behind a symmetric pair.
    pub fn is_symmetric_pair(&self) -> bool {
        matches!(self.judge, Judge::Full(_))
    }

    /// The KKT values at state `x` of the model stability is judged on (independent of the
    /// load parameter: it enters the residual only), with that model's pattern and
    /// stability counter.
    fn judged(&mut self, x: &[f64]) -> (&SymbolicSparseColMat<usize>, &[f64], &mut KktStability) {
        match &mut self.judge {
            Judge::Own {
                stability,
                residual,
                values,
            } => {
                self.system.evaluate(&self.model, x, residual, values);
                (self.system.pattern(), values, stability)
            }
            Judge::Full(f) => {
                let f = f.as_mut();
                expand_state(
                    &self.model,
                    &self.system,
                    x,
                    &f.model,
                    &f.system,
                    &mut f.expanded,
                );
                f.system
                    .evaluate(&f.model, &f.expanded, &mut f.residual, &mut f.values);
                (f.system.pattern(), &f.values, &mut f.stability)
            }
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
        let (pattern, values, stability) = self.judged(x);
        stability.unstable_directions(pattern, values)
    }

    fn lowest_eigenvalue(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        let (pattern, values, stability) = self.judged(x);
        stability.lowest_eigenvalue(pattern, values)
    }

    fn eigenvalue_nearest_zero(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        let (pattern, values, stability) = self.judged(x);
        stability.eigenvalue_nearest_zero(pattern, values)
    }

    /// The system keeps the tip load of the converged point (reactions are read from it).
    fn restore(&mut self, _x: &[f64], lambda: f64) {
        self.system.set_tip_load(self.tip_load(lambda));
    }
}
