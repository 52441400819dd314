//! Stability of an equilibrium from the inertia of its KKT matrix, by a sparse `LDLᵀ`
//! (docs/theory.md §5, "Stability"), and the eigenvalues that place its critical points.
//!
//! An equilibrium is stable when the Hessian `H` of the Lagrangian is positive definite on
//! the tangent space `J v = 0` of the constraints. The KKT matrix `K = [[H, Jᵀ], [J, 0]]`
//! has inertia `(p, m + q, z)` where `q` is the number of negative directions of `Zᵀ H Z`
//! and `m` the number of (independent) constraints. `K` has zero diagonal entries, so it is
//! factorised in the augmented, regularised form
//!
//! `K_ρδ = [[H + ρ JᵀC⁻¹J, Jᵀ], [J, −δ C]]`,
//!
//! whose inertia equals `inertia(H + (ρ + 1/δ) JᵀC⁻¹J) + (0, m, 0)`; for a large penalty
//! `ρ + 1/δ` the first term counts `q` negative directions (Sylvester's law of inertia and
//! Debreu's lemma). The matrix is quasi-definite at stable states, so a symmetric `LDLᵀ`
//! without pivoting exists for any fill-reducing ordering.
//!
//! `C = diag(c_i)` makes the regularisation free of units: some constraints are on
//! rotations only (unit quaternions, rotational supports: dimensionless), the others on
//! positions (inextensibility, joints, positional supports: m), so `c_i = 1` for the
//! first and `c_i = ℓ²` for the second, `ℓ` the rod length. With `ρ` the Hessian's mean
//! diagonal and `δ = 10⁻⁸/ρ`, a change of units (lengths ×s, stiffnesses ×s²) scales
//! `K_ρδ` symmetrically and leaves counts and eigenvalues as they are (a penalty `δ I`
//! in metres would be 10⁶ times weaker in millimetres).
//!
//! The work is split by operation, as faer splits its `LDLᵀ`: `structure` is the symbolic
//! analysis every matrix of one pattern shares (the augmented pattern, its ordering, the
//! symbolic factor: [`KktStructure`]), `inertia` the numeric factorisation, its inertia and
//! the refined solves ([`InertiaCounter`]), `eigen` the eigenvalue searches on them, and
//! this module the stability of the states of one pattern ([`KktStability`]).

mod eigen;
mod inertia;
mod structure;

pub use super::ldl::Scalar;
pub use eigen::{RoughLowest, WarmStart};
pub use inertia::{Inertia, InertiaCounter};
pub use structure::{InertiaError, KktStructure};

use faer::sparse::SymbolicSparseColMat;
use std::sync::{Arc, OnceLock};

/// The stability of the states of one KKT pattern: the inertia counter (built on first
/// use) and the metric of its eigenproblem, with the count's rounding band.
pub struct KktStability<T: Scalar = f64> {
    counter: Option<Box<InertiaCounter<T>>>,
    /// The pattern's structure, built on first use by this stability or by any that
    /// shares it ([`KktStability::sharing`]).
    structure: Arc<OnceLock<Result<Arc<KktStructure>, InertiaError>>>,
    /// Diagonal metric `M` of the eigenproblem over the primal unknowns.
    metric: Vec<f64>,
    /// Mean of the metric's non-zero weights.
    mean_metric: f64,
    /// Length `ℓ` that weighs position unknowns against rotations in the regularisation
    /// (m; the rod length).
    length: f64,
    /// A warm start handed over before the counter was built, for it.
    pending: WarmStart<T>,
}

impl<T: Scalar> KktStability<T> {
    /// For KKT matrices whose first `metric.len()` unknowns are primal, with the eigenvalue
    /// problem `H v = μ M v`, `M = diag(metric)` (zero on position unknowns), and `length`
    /// the model's length scale `ℓ` (the rod length, m).
    pub fn new(metric: Vec<f64>, length: f64) -> KktStability<T> {
        let mean_metric =
            metric.iter().sum::<f64>() / metric.iter().filter(|&&m| m > 0.0).count().max(1) as f64;
        KktStability {
            counter: None,
            structure: Arc::default(),
            metric,
            mean_metric,
            length,
            pending: WarmStart::default(),
        }
    }

    /// The stability of other matrices of the same pattern and metric (of real or
    /// complex entries), sharing this one's structure: the pattern's symbolic analysis is
    /// done once for all of them.
    pub fn sharing<U: Scalar>(&self) -> KktStability<U> {
        KktStability {
            counter: None,
            structure: Arc::clone(&self.structure),
            metric: self.metric.clone(),
            mean_metric: self.mean_metric,
            length: self.length,
            pending: WarmStart::default(),
        }
    }

    /// Counts the eigenvalues of the constrained Hessian below `−τ`, `τ = 1e-9 ρ / m̄` (`ρ`
    /// the mean diagonal of the Hessian, `m̄` the mean metric weight): the rounding level
    /// of the regularised LDLᵀ's pivots in eigenvalue units, which grows as the mesh is
    /// refined. Eigenvalues closer to zero than the count can resolve — a neutral direction
    /// such as a buckled isotropic rod turning about its axis, or the two halves of a
    /// double critical eigenvalue — count as stable, so a double eigenvalue crosses as one
    /// event; critical points are then placed by a secant on the eigenvalue itself.
    pub fn unstable_directions(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Result<usize, InertiaError> {
        let mean_metric = self.mean_metric;
        let (counter, metric) = self.counter_and_metric(pattern)?;
        let tau = 1e-9 * counter.hessian_scale(kkt) / mean_metric;
        let inertia = counter.inertia(kkt, -tau, metric)?;
        Ok(counter.unstable_directions(inertia).max(0) as usize)
    }

    /// The unstable directions (as [`KktStability::unstable_directions`] counts them) and
    /// the number of eigenvalues below `sigma`, by one factorisation where one answers
    /// both: no eigenvalue below `σ ≥ −τ` means none below `−τ`, and none below `−τ ≥ σ`
    /// none below `σ`.
    pub fn unstable_and_below(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        sigma: f64,
    ) -> Result<(usize, usize), InertiaError> {
        let tau = self.rounding_band(pattern, kkt)?;
        if sigma >= -tau {
            let below = self.count_below(pattern, kkt, sigma)?;
            if below == 0 {
                return Ok((0, 0));
            }
            Ok((self.unstable_directions(pattern, kkt)?, below))
        } else {
            let unstable = self.unstable_directions(pattern, kkt)?;
            if unstable == 0 {
                return Ok((0, 0));
            }
            Ok((unstable, self.count_below(pattern, kkt, sigma)?))
        }
    }

    /// `τ = 1e-9 ρ / m̄`: the rounding band of the count (see
    /// [`KktStability::unstable_directions`]) in eigenvalue units.
    pub fn rounding_band(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Result<f64, InertiaError> {
        let mean_metric = self.mean_metric;
        let counter = self.counter(pattern)?;
        Ok(1e-9 * counter.hessian_scale(kkt) / mean_metric)
    }

    /// Number of eigenvalues of the constrained Hessian below `sigma`.
    pub fn count_below(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        sigma: f64,
    ) -> Result<usize, InertiaError> {
        let (counter, metric) = self.counter_and_metric(pattern)?;
        let inertia = counter.inertia(kkt, sigma, metric)?;
        Ok(counter.unstable_directions(inertia).max(0) as usize)
    }

    /// Takes the neutral modes `modes` (primal unknowns) that the matrices' gauge rows hold
    /// at a point out of the metric of the following counts and searches, so that they give
    /// the eigenvalues of the modes orthogonal to them (see [`inertia::HeldModes`]); none
    /// restores the metric.
    pub fn hold_modes(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        modes: &[Vec<f64>],
    ) -> Result<(), InertiaError> {
        let (counter, metric) = self.counter_and_metric(pattern)?;
        counter.hold_modes(metric, modes);
        Ok(())
    }

    fn counter(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<&mut InertiaCounter<T>, InertiaError> {
        Ok(self.counter_and_metric(pattern)?.0)
    }

    /// The structure of matrices of `pattern` (built on first use).
    pub fn structure_for(
        &self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<Arc<KktStructure>, InertiaError> {
        self.structure
            .get_or_init(|| KktStructure::new(pattern, &self.metric, self.length).map(Arc::new))
            .clone()
    }

    /// The inertia counter (built on first use) and the metric, borrowed together.
    fn counter_and_metric(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<(&mut InertiaCounter<T>, &[f64]), InertiaError> {
        if self.counter.is_none() {
            let structure = self.structure_for(pattern)?;
            let mut counter = Box::new(InertiaCounter::with_structure(structure)?);
            counter.swap_warm_start(&mut self.pending);
            self.counter = Some(counter);
        }
        let counter = self.counter.as_mut().expect("built above");
        Ok((counter, &self.metric))
    }
}

impl<T: Scalar> KktStability<T> {
    /// Exchanges the warm start of inverse iteration (the last mode and lowest eigenvalue)
    /// with `warm` (so that one factorisation pattern can serve several matrices, each with
    /// its own warm start).
    pub fn swap_warm_start(&mut self, warm: &mut WarmStart<T>) {
        match self.counter.as_mut() {
            Some(c) => c.swap_warm_start(warm),
            None => std::mem::swap(&mut self.pending, warm),
        }
    }

    /// The mode (primal unknowns, unit norm in the metric) of the last eigenvalue nearest
    /// zero found; empty before one is found.
    pub fn nearest_zero_mode(&self) -> &[T] {
        self.counter
            .as_ref()
            .map_or(&[], |c| c.nearest_zero_mode.as_slice())
    }

    /// Lowest eigenvalue of the constrained Hessian (J/m in the rods' metric).
    pub fn lowest_eigenvalue(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<f64> {
        self.lowest_eigenvalue_after(pattern, kkt, None)
    }

    /// As [`KktStability::lowest_eigenvalue`], going on from a rough estimate of the same
    /// values when there is one.
    pub fn lowest_eigenvalue_after(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        rough: Option<RoughLowest>,
    ) -> Option<f64> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.lowest_eigenvalue(kkt, metric, rough)
    }

    /// A rough upper estimate of the lowest eigenvalue (see
    /// [`InertiaCounter::rough_lowest`]).
    pub fn rough_lowest(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<RoughLowest> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.rough_lowest(kkt, metric)
    }

    /// The eigenvalue nearest zero orthogonal to `first` and its mode (see
    /// [`InertiaCounter::nearest_zero_orthogonal_to`]).
    pub fn nearest_zero_orthogonal_to(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        first: &[T],
    ) -> Option<(f64, Vec<T>)> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.nearest_zero_orthogonal_to(kkt, metric, first)
    }

    /// The eigenvalue of the constrained Hessian nearest zero.
    pub fn eigenvalue_nearest_zero(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<f64> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.eigenvalue_nearest_zero(kkt, metric)
    }
}
