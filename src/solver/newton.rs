//! Newton's method on the KKT system `R(x) = 0`.

use super::linear::{relative_residual, LinearError, SparseLu};
use crate::discretisation::model::DiscreteModel;
use crate::discretisation::system::System;
use crate::model::loading::TipLoad;

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
    /// Right-hand side of the Newton solve.
    rhs: Vec<f64>,
    /// Scratch for the check of each linear solve.
    check: Vec<f64>,
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
            check: vec![0.0; system.n],
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
        let rel = relative_residual(system.matrix(&self.values), out, rhs, &mut self.check);
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

/// The extra equation of a continuation step, `t_xᵀ (x − x0) + t_λ (λ − λ0) = ds` over
/// the primal unknowns, and `∂R/∂λ`. Natural-parameter steps are `t_x = 0, t_λ = 1`.
pub struct Border<'a> {
    pub tx: &'a [f64],
    pub tl: f64,
    pub x0: &'a [f64],
    pub l0: f64,
    pub ds: f64,
    /// `∂R/∂λ` over all unknowns (constant: the load enters linearly).
    pub dr_dl: &'a [f64],
}

/// Newton iterations on `R(x, λ) = 0` bordered by the step equation of `border`, from
/// `(x, λ)` until `‖R‖∞ ≤ tolerance`; `load(λ)` sets the system's tip load. On error `x`
/// and `λ` hold the last iterate, which the caller must discard.
///
/// Modified Newton: a factorisation already in `ws` (e.g. the Jacobian at the last
/// converged state, used for the predictor) is reused while it contracts the residual by
/// at least `REFACTOR_RATIO` per iteration; otherwise the Jacobian is refactorised at the
/// current iterate, so the method falls back to full Newton where it must. Each solve is
/// bordered: `K a = −R`, `K b = −∂R/∂λ`, then `δλ` from the step equation and `δx = a + δλ b`.
#[allow(clippy::too_many_arguments)]
pub fn solve(
    model: &DiscreteModel,
    system: &mut System,
    x: &mut [f64],
    lambda: &mut f64,
    load: &dyn Fn(f64) -> TipLoad,
    border: &Border,
    ws: &mut Workspace,
    settings: &NewtonSettings,
) -> Result<NewtonReport, NewtonError> {
    const REFACTOR_RATIO: f64 = 0.25;
    let np = model.n_primal;
    let mut first = f64::NAN;
    let mut previous = f64::INFINITY;
    let mut stale = false; // the factorisation is not of the current iterate
    let mut last = f64::NAN;
    let mut b: Option<Vec<f64>> = None; // K⁻¹(−∂R/∂λ) for the current factorisation
    for it in 0..=settings.max_iterations {
        system.set_tip_load(load(*lambda));
        let ev = system.residual(model, x, &mut ws.residual);
        let r = norm_inf(&ws.residual);
        if it == 0 {
            first = r;
        }
        last = r;
        let step_eq: f64 = (0..np)
            .map(|i| border.tx[i] * (x[i] - border.x0[i]))
            .sum::<f64>()
            + border.tl * (*lambda - border.l0)
            - border.ds;
        if r <= settings.tolerance && step_eq.abs() <= 1e-10 * (1.0 + border.ds.abs()) {
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
            b = None;
        }
        previous = r;
        let linear = |source| NewtonError::Linear {
            iteration: it,
            source,
        };
        // K b = −∂R/∂λ, once per factorisation (∂R/∂λ is constant)
        let load_solution = |ws: &mut Workspace| -> Result<Vec<f64>, LinearError> {
            let rhs: Vec<f64> = border.dr_dl.iter().map(|v| -v).collect();
            let mut out = vec![0.0; system.n];
            ws.solve_checked(system, &rhs, &mut out, settings.singular_threshold)?;
            Ok(out)
        };
        if b.is_none() && border.tx.iter().any(|&t| t != 0.0) {
            b = Some(load_solution(ws).map_err(linear)?);
        }
        // K a = −R, into ws.delta, with ws.rhs as the right-hand side
        for (r, v) in ws.rhs.iter_mut().zip(&ws.residual) {
            *r = -v;
        }
        let (rhs, mut a) = (std::mem::take(&mut ws.rhs), std::mem::take(&mut ws.delta));
        let checked = ws.solve_checked(system, &rhs, &mut a, settings.singular_threshold);
        (ws.rhs, ws.delta) = (rhs, a);
        checked.map_err(linear)?;
        // δλ from the linearised step equation
        let (ta, tb) = match &b {
            Some(b) => (
                (0..np).map(|i| border.tx[i] * ws.delta[i]).sum::<f64>(),
                (0..np).map(|i| border.tx[i] * b[i]).sum::<f64>(),
            ),
            None => (0.0, 0.0),
        };
        let denominator = tb + border.tl;
        if denominator.abs() < 1e-14 {
            return Err(NewtonError::Linear {
                iteration: it,
                source: LinearError::Singular {
                    relative_residual: f64::INFINITY,
                },
            });
        }
        let dl = (-step_eq - ta) / denominator;
        if dl != 0.0 {
            // δx = a + δλ b; in natural-parameter steps b is computed only when λ moves
            if b.is_none() {
                b = Some(load_solution(ws).map_err(linear)?);
            }
            let bb = b.as_ref().expect("computed above");
            for (d, bi) in ws.delta.iter_mut().zip(bb) {
                *d += dl * bi;
            }
        }
        for (xi, di) in x.iter_mut().zip(&ws.delta) {
            *xi += di;
        }
        *lambda += dl;
        stale = true;
    }
    Err(NewtonError::NotConverged {
        iterations: settings.max_iterations,
        residual: last,
    })
}
