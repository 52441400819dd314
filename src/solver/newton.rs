//! Newton's method on the KKT system `R(x) = 0`.

use super::linear::{relative_residual, LinearError, SparseLu};
use crate::discretisation::system::{DiscreteModel, System};

/// Newton settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Converged when `‖R‖∞` falls below this (N, N m and m mixed: the residual of the
    /// balance equations and of the constraints).
    pub tolerance: f64,
    /// Iterations before giving up.
    pub max_iterations: usize,
    /// A linear solve whose relative residual exceeds this marks the matrix singular.
    pub singular_threshold: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            tolerance: 1e-9,
            max_iterations: 12,
            singular_threshold: 1e-6,
        }
    }
}

/// Why Newton stopped without converging.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum NewtonError {
    #[error("Newton did not converge in {iterations} iterations (residual {residual:.2e})")]
    NotConverged { iterations: usize, residual: f64 },
    #[error("Newton diverged at iteration {iteration} (residual {residual:.2e})")]
    Diverged { iteration: usize, residual: f64 },
    #[error("at Newton iteration {iteration}: {source}")]
    Linear {
        iteration: usize,
        #[source]
        source: LinearError,
    },
}

/// A converged Newton solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonReport {
    pub iterations: usize,
    /// `‖R‖∞` at the solution.
    pub residual: f64,
    /// Elastic energy at the solution (J).
    pub energy: f64,
}

/// Buffers and factorisation for one [`System`]; the hot loop allocates nothing.
pub struct Workspace {
    pub residual: Vec<f64>,
    pub values: Vec<f64>,
    pub delta: Vec<f64>,
    rhs: Vec<f64>,
    pub lu: SparseLu,
    /// A factorisation is held (of the Jacobian at some recent iterate) and may be reused.
    pub fresh: bool,
}

impl Workspace {
    pub fn new(system: &System) -> Workspace {
        Workspace {
            residual: vec![0.0; system.n],
            values: system.new_values(),
            delta: vec![0.0; system.n],
            rhs: vec![0.0; system.n],
            lu: SparseLu::default(),
            fresh: false,
        }
    }

    /// Factorises the KKT matrix at `x`.
    pub fn factorize_at(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
    ) -> Result<(), LinearError> {
        system.evaluate(model, x, &mut self.residual, &mut self.values);
        self.fresh = false;
        self.lu.factorize(system.matrix(&self.values))?;
        self.fresh = true;
        Ok(())
    }

    /// Solves with the current factorisation and checks the solve.
    pub fn solve_checked(
        &mut self,
        system: &System,
        rhs: &[f64],
        out: &mut [f64],
        threshold: f64,
    ) -> Result<(), LinearError> {
        out.copy_from_slice(rhs);
        self.lu.solve(out);
        let rel = relative_residual(system.matrix(&self.values), out, rhs);
        if rel.is_nan() || rel > threshold {
            return Err(LinearError::Singular {
                relative_residual: rel,
            });
        }
        Ok(())
    }
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(
        0.0f64,
        |m, x| if x.is_nan() { f64::NAN } else { m.max(x.abs()) },
    )
}

/// Newton iterations from `x` until `‖R‖∞ ≤ tolerance`. On error `x` holds the last
/// iterate, which the caller must discard.
///
/// Modified Newton: a factorisation already in `ws` (e.g. the Jacobian at the last
/// converged state, used for the predictor) is reused while it contracts the residual by
/// at least `REFACTOR_RATIO` per iteration; otherwise the Jacobian is refactorised at the
/// current iterate, so the method falls back to full Newton where it must.
pub fn solve(
    model: &DiscreteModel,
    system: &System,
    x: &mut [f64],
    ws: &mut Workspace,
    settings: &NewtonSettings,
) -> Result<NewtonReport, NewtonError> {
    const REFACTOR_RATIO: f64 = 0.25;
    let mut first = f64::NAN;
    let mut previous = f64::INFINITY;
    let mut stale = false; // the factorisation is not of the current iterate
    let mut last = f64::NAN;
    for it in 0..=settings.max_iterations {
        let ev = system.residual(model, x, &mut ws.residual);
        let r = norm_inf(&ws.residual);
        if it == 0 {
            first = r;
        }
        last = r;
        if r <= settings.tolerance {
            return Ok(NewtonReport {
                iterations: it,
                residual: r,
                energy: ev.energy,
            });
        }
        let diverging = !r.is_finite() || (it > 0 && r > 1e6 * first.max(settings.tolerance));
        if diverging && (!stale || !r.is_finite()) {
            return Err(NewtonError::Diverged {
                iteration: it,
                residual: r,
            });
        }
        if it == settings.max_iterations {
            break;
        }
        // refactorise unless a factorisation is at hand and still contracting well
        let contracting = r <= REFACTOR_RATIO * previous;
        if !ws.fresh || (stale && !contracting) {
            system.evaluate(model, x, &mut ws.residual, &mut ws.values);
            ws.fresh = false;
            ws.lu
                .factorize(system.matrix(&ws.values))
                .map_err(|source| NewtonError::Linear {
                    iteration: it,
                    source,
                })?;
            ws.fresh = true;
        }
        previous = r;
        for (d, r) in ws.delta.iter_mut().zip(&ws.residual) {
            *d = -r;
        }
        let rhs = std::mem::take(&mut ws.delta);
        let mut delta = std::mem::take(&mut ws.rhs);
        let checked = ws.solve_checked(system, &rhs, &mut delta, settings.singular_threshold);
        ws.rhs = rhs;
        ws.delta = delta;
        checked.map_err(|source| NewtonError::Linear {
            iteration: it,
            source,
        })?;
        for (xi, di) in x.iter_mut().zip(&ws.delta) {
            *xi += di;
        }
        stale = true;
    }
    Err(NewtonError::NotConverged {
        iterations: settings.max_iterations,
        residual: last,
    })
}
