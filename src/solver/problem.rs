//! What the continuation engine solves: a nonlinear system `R(x, λ) = 0` in unknowns `x`
//! (primal unknowns first, then Lagrange multipliers) and one load parameter `λ`, with a
//! sparse symmetric Jacobian, and hooks for the stability of its solutions.
//!
//! The rod assemblies implement it ([`crate::simulation`]), and so do the canonical problems
//! the engine is tested on by itself (a fold, a pitchfork, the Bratu problem: `tests/`).

use super::stability::{InertiaError, KktStructure};
use crate::results::Stability;
use faer::sparse::SymbolicSparseColMat;
use std::sync::Arc;

/// A system `R(x, λ) = 0` that a continuation follows in `λ`.
///
/// `R` is the gradient of a Lagrangian (so the Jacobian `K = ∂R/∂x` is symmetric); the
/// problem owns whatever it needs to evaluate it and may keep state that depends on the
/// last evaluation (the engine calls [`Problem::restore`] with the converged point after
/// every trial, accepted or not).
pub trait Problem {
    /// Number of unknowns, multipliers included.
    fn unknowns(&self) -> usize;

    /// Number of primal unknowns (the first ones): the arclength norm runs over these.
    fn primal_unknowns(&self) -> usize;

    /// Sparsity pattern of the Jacobian `∂R/∂x`, fixed for the life of the problem.
    fn pattern(&self) -> &SymbolicSparseColMat<usize>;

    /// `R(x, λ)` into `residual`; returns the energy of the state (0 where there is none).
    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64;

    /// `R(x, λ)` into `residual` and the values of `∂R/∂x` (in the order of
    /// [`Problem::pattern`]) into `jacobian`; returns the energy.
    fn jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: &mut [f64],
    ) -> f64;

    /// Weights `w` that make each row of `R` a pure number for Newton's convergence test
    /// (`max_i |w_i R_i| ≤ tolerance`), so that the test does not depend on the units the
    /// problem is written in: 1 by default (a problem already dimensionless).
    fn residual_weights(&self, weights: &mut [f64]) {
        weights.fill(1.0);
    }

    /// For a Jacobian that is a KKT matrix (its first [`Problem::primal_unknowns`] rows
    /// primal, the others constraint rows with a zero diagonal block), the structure of
    /// its regularised form (see [`KktStructure::new`]), shared with the problem's own
    /// stability: Newton's method then factorises it by a regularised symmetric `LDLᵀ`,
    /// and by sparse LU where that fails or for `None` (the default).
    fn kkt_structure(&self) -> Option<Arc<KktStructure>> {
        None
    }

    /// `∂R/∂λ` at `(x, λ)` into `out`.
    fn load_derivative(&mut self, x: &[f64], lambda: f64, out: &mut [f64]);

    /// Whether `∂R/∂λ` is the same at every `(x, λ)` (the load enters linearly), so that the
    /// engine evaluates it once and solves with it once per factorisation.
    fn load_derivative_is_constant(&self) -> bool {
        false
    }

    /// Number of unstable directions of the state `x`: negative eigenvalues of the Hessian
    /// of the Lagrangian on the tangent space of the constraints. An error (a zero pivot)
    /// means the state is on, or within rounding of, a critical point.
    fn unstable_directions(&mut self, x: &[f64], lambda: f64) -> Result<usize, InertiaError>;

    /// The lowest eigenvalue of that constrained Hessian, where it can be computed.
    fn lowest_eigenvalue(&mut self, x: &[f64], lambda: f64) -> Option<f64>;

    /// The scale of that constrained Hessian's eigenvalues, in their units (for the rods
    /// `B1/L²`, N: energy per squared rotation per arc length): an eigenvalue below
    /// [`crate::solver::continuation::NEUTRAL_FRACTION`] of it at both ends of a step whose
    /// count changed is a neutral direction, not a crossing. 1 by default.
    fn eigenvalue_scale(&self) -> f64 {
        1.0
    }

    /// The eigenvalue of that constrained Hessian nearest zero: it crosses zero at a
    /// critical point, so a secant on it places the point.
    fn eigenvalue_nearest_zero(&mut self, x: &[f64], lambda: f64) -> Option<f64>;

    /// The stability of the state `x`: its unstable directions, and its lowest eigenvalue
    /// when `eigenvalue` is asked for. A problem that can answer both with less work than
    /// the two questions apart overrides this.
    fn stability(
        &mut self,
        x: &[f64],
        lambda: f64,
        eigenvalue: bool,
    ) -> Result<Stability, InertiaError> {
        let unstable_directions = self.unstable_directions(x, lambda)?;
        Ok(Stability {
            unstable_directions,
            lowest_eigenvalue: if eigenvalue {
                self.lowest_eigenvalue(x, lambda)
            } else {
                None
            },
            lowest_wavenumber: None,
        })
    }

    /// Before a critical point crossed by the accepted step from `x0` to `x1` is located:
    /// a problem whose stability is judged by independent blocks focuses its eigenvalue
    /// nearest zero on the block whose count changed, and returns that block's index
    /// (0 for a problem of one block).
    fn focus_on_crossing(&mut self, _x0: &[f64], _x1: &[f64]) -> usize {
        0
    }

    /// After the location: every block counts again.
    fn clear_focus(&mut self) {}

    /// Whether every change of the count of unstable directions is a critical point of its
    /// own, so that two changes crossed by one step are located apart. A count that samples
    /// a continuum (an infinite tube's Bloch phases, where a band that widens past the next
    /// sampled phase adds to it) says no: the first change is the point. Yes by default.
    fn counts_points(&self) -> bool {
        true
    }

    /// Why the state `x` is outside the problem's physical domain (for the rods: the tips
    /// at or below the base, two sliding crossings of one rod run into each other), or
    /// `None` inside it. A step that leaves it is halved until it is the smallest step, so the
    /// path stops on the domain's edge (to the smallest step). Every state is
    /// inside by default.
    fn out_of_domain(&self, _x: &[f64]) -> Option<&'static str> {
        None
    }

    /// Back to the converged point `(x, λ)` after a trial step (accepted or rejected) or the
    /// probes of a critical-point search: whatever the problem keeps of its last evaluation
    /// is reset to that point.
    fn restore(&mut self, _x: &[f64], _lambda: f64) {}
}
