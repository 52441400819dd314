//! How the stability of a state of the model solved is judged on the whole assembly it
//! stands for: negative eigenvalues of the Hessian of the Lagrangian on the tangent space
//! of the constraints (docs/theory.md §5), counted on the model's own KKT matrix
//! ([`JudgeOnItself`]) or on independent blocks of the whole assembly's
//! ([`super::blocks::JudgeByBlocks`] for a cyclic pair).

use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::system::System;
use crate::solver::stability::{InertiaError, KktStability, KktStructure};
use faer::sparse::SymbolicSparseColMat;
use std::sync::Arc;

/// The stability of one block of a state: the whole of a model judged on itself
/// (wavenumber 0), or one Bloch block of a cyclic pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockStability {
    pub wavenumber: usize,
    /// How many wavenumbers the block stands for (`p` and `m − p`).
    pub multiplicity: usize,
    pub unstable_directions: usize,
    /// The block's lowest eigenvalue (J/m), when it was computed: the lowest of the state's
    /// blocks always is, a block known to have none below it is not.
    pub lowest_eigenvalue: Option<f64>,
}

/// Judges the stability of states of one model under one system (the KKT values do not
/// depend on the load parameter: it enters the residual only), with its own workspaces and
/// warm starts kept from state to state.
pub trait StabilityJudge: Send {
    /// The stability of every distinct block at `x`, with the lowest eigenvalue over the
    /// blocks when `eigenvalue` is asked for.
    fn blocks(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError>;

    /// The eigenvalue nearest zero at `x` of the block a critical-point search focuses on,
    /// or over every block, with its wavenumber and the block's mode (the block's primal
    /// unknowns: the model's, or real then imaginary parts for a complex block).
    fn nearest_zero_with_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
    ) -> Option<(f64, usize, Vec<f64>)>;

    /// The eigenvector (the block's primal unknowns) of the eigenvalue nearest zero of
    /// block `p` at `x`: a critical mode of wavenumber `p`.
    fn block_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        p: usize,
    ) -> Option<Vec<f64>> {
        self.focus(Some(p));
        let found = self.nearest_zero_with_mode(model, system, x);
        self.focus(None);
        found.map(|(_, _, mode)| mode)
    }

    /// At a double critical point (count change 2): the mode of the other eigenvalue
    /// nearest zero at `x`, orthogonal in the metric to `first`, scaled as `first` over the
    /// primal unknowns. `None` by default (the double modes of a complex Bloch block are
    /// the two halves of one complex mode).
    fn second_mode(
        &mut self,
        _model: &DiscreteModel,
        _system: &System,
        _x: &[f64],
        _first: &[f64],
    ) -> Option<Vec<f64>> {
        None
    }

    /// Whether the blocks are of distinct wavenumbers (reported with the lowest eigenvalue).
    fn has_wavenumbers(&self) -> bool {
        false
    }

    /// Whether every change of the count is a critical point of its own (see
    /// [`crate::solver::problem::Problem::counts_points`]).
    fn counts_points(&self) -> bool {
        true
    }

    /// How many wavenumbers block `p` stands for.
    fn multiplicity(&self, _p: usize) -> usize {
        1
    }

    /// The block a critical-point search looks at (`None`: every block).
    fn focus(&mut self, _p: Option<usize>) {}

    /// The structure of the KKT matrices of `pattern` the judge factorises (see
    /// [`crate::solver::problem::Problem::kkt_structure`]).
    fn kkt_structure(&self, pattern: &SymbolicSparseColMat<usize>) -> Option<Arc<KktStructure>>;

    /// The number of threads the blocks are shared out on (at least one).
    fn set_threads(&mut self, _threads: usize) {}
}

/// All the cores of the machine: the default number of threads of the block work.
pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The model judged on its own KKT matrix: one block of wavenumber 0.
pub struct JudgeOnItself {
    stability: KktStability,
    residual: Vec<f64>,
    values: Vec<f64>,
}

impl JudgeOnItself {
    pub fn new(model: &DiscreteModel, system: &System) -> JudgeOnItself {
        JudgeOnItself {
            stability: KktStability::new(metric(model), model.length()),
            residual: vec![0.0; system.n],
            values: system.new_values(),
        }
    }
}

impl StabilityJudge for JudgeOnItself {
    fn blocks(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        let JudgeOnItself {
            stability,
            residual,
            values,
        } = self;
        system.evaluate(model, x, residual, values);
        let pattern = system.pattern();
        let lowest_eigenvalue = if eigenvalue {
            stability.lowest_eigenvalue(pattern, values)
        } else {
            None
        };
        let unstable_directions =
            if clearly_stable(lowest_eigenvalue, stability.rounding_band(pattern, values)?) {
                0
            } else {
                stability.unstable_directions(pattern, values)?
            };
        Ok(vec![BlockStability {
            wavenumber: 0,
            multiplicity: 1,
            unstable_directions,
            lowest_eigenvalue,
        }])
    }

    fn nearest_zero_with_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
    ) -> Option<(f64, usize, Vec<f64>)> {
        system.evaluate(model, x, &mut self.residual, &mut self.values);
        let mu = self
            .stability
            .eigenvalue_nearest_zero(system.pattern(), &self.values)?;
        Some((mu, 0, self.stability.nearest_zero_mode().to_vec()))
    }

    fn second_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        first: &[f64],
    ) -> Option<Vec<f64>> {
        system.evaluate(model, x, &mut self.residual, &mut self.values);
        let (_, mut mode) =
            self.stability
                .nearest_zero_orthogonal_to(system.pattern(), &self.values, first)?;
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let scale = norm(&first[..mode.len()]) / norm(&mode);
        if !scale.is_finite() {
            return None;
        }
        mode.iter_mut().for_each(|v| *v *= scale);
        Some(mode)
    }

    /// The structure of the model's own pattern, metric and length.
    fn kkt_structure(&self, pattern: &SymbolicSparseColMat<usize>) -> Option<Arc<KktStructure>> {
        self.stability.structure_for(pattern).ok()
    }
}

/// Tributary arc length of every primal unknown: the metric of the eigenproblem
/// (quaternion unknowns weighted by their node's share of the rod, positions zero).
pub(super) fn metric(model: &DiscreteModel) -> Vec<f64> {
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

/// Whether a state whose lowest eigenvalue is `lowest` has no unstable direction without
/// a count: the count is of the eigenvalues below `−τ` (`tau`, its rounding band), and none
/// is below the lowest. (Near a critical point the lowest eigenvalue, from unregularised
/// Rayleigh quotients, is the sharper of the two: the count's pivots round at about `τ`.)
pub(super) fn clearly_stable(lowest: Option<f64>, tau: f64) -> bool {
    lowest.is_some_and(|l| l > -tau)
}

/// The lowest computed eigenvalue over `blocks`, with its wavenumber.
pub(super) fn lowest_of(blocks: &[BlockStability]) -> Option<(f64, usize)> {
    blocks
        .iter()
        .filter_map(|s| s.lowest_eigenvalue.map(|l| (l, s.wavenumber)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}
