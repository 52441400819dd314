//! Newton's method on `R(x, λ) = 0` bordered by the step equation of a continuation step,
//! with the sparse factorisation reused while it contracts the residual (modified Newton).

use super::interrupt::{Interrupt, Interruption};
use super::linear::{relative_residual, LinearError, SparseLu};
use super::problem::Problem;
use super::stability::InertiaCounter;
use faer::sparse::SparseColMatRef;

/// Newton settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Converged when the weighted residual `max_i |w_i R_i|` falls below this, with the
    /// weights of [`Problem::residual_weights`] that make every row a pure number (for the
    /// rods: moments over `B1/L`, forces over `B1/L²`, lengths over `L`), so that changing
    /// the units of force or length changes nothing.
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
    /// A state whose residual is small but whose energy or unknowns are not finite
    /// numbers: rejected like a failed iteration.
    #[error("Newton reached a state with a non-finite {what} at iteration {iteration}")]
    NonFinite {
        iteration: usize,
        what: &'static str,
    },
    #[error("interrupted at Newton iteration {iteration}: {why}")]
    Interrupted { iteration: usize, why: Interruption },
    /// A converged corrector that moved the state from the predicted one by more than half
    /// the predictor's length: it left the path it was predicted on (onto another branch).
    #[error("the corrector moved the state {correction:.2} times the predictor's length off the path predicted")]
    LeftPath { correction: f64 },
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
    /// Energy at the solution (J for the rods).
    pub energy: f64,
}

/// The step equation of a continuation step, `t_xᵀ (x − x0) + t_λ (λ − λ0) = ds` over the
/// primal unknowns. Natural-parameter steps are `t_x = 0, t_λ = 1`.
#[derive(Clone, Copy, Debug)]
pub struct StepEquation<'a> {
    /// `t_x` over the primal unknowns, or `None` for a natural-parameter step (`t_x = 0`).
    pub tx: Option<&'a [f64]>,
    pub tl: f64,
    pub x0: &'a [f64],
    pub l0: f64,
    pub ds: f64,
}

impl<'a> StepEquation<'a> {
    /// The natural-parameter step from `x0` that holds `λ = l0 + ds`.
    pub fn natural(x0: &'a [f64], l0: f64, ds: f64) -> StepEquation<'a> {
        StepEquation {
            tx: None,
            tl: 1.0,
            x0,
            l0,
            ds,
        }
    }

    /// `t_xᵀ (x − x0) + t_λ (λ − λ0) − ds`.
    fn residual(&self, x: &[f64], lambda: f64) -> f64 {
        let along = self.tx.map_or(0.0, |tx| {
            tx.iter()
                .zip(x)
                .zip(self.x0)
                .map(|((t, xi), x0)| t * (xi - x0))
                .sum::<f64>()
        });
        along + self.tl * (lambda - self.l0) - self.ds
    }

    /// `t_xᵀ v`.
    fn along(&self, v: &[f64]) -> f64 {
        self.tx
            .map_or(0.0, |tx| tx.iter().zip(v).map(|(t, vi)| t * vi).sum())
    }

    /// Whether `λ` may move by itself (an arclength step): then `K⁻¹ ∂R/∂λ` is needed from
    /// the first iteration.
    fn has_tangent_part(&self) -> bool {
        self.tx.is_some_and(|tx| tx.iter().any(|&t| t != 0.0))
    }
}

/// Buffers and factorisation of Newton's method for one problem's pattern; the hot loop
/// allocates nothing.
pub struct Newton {
    residual: Vec<f64>,
    /// The problem's weights of the residual rows for the convergence test.
    weights: Vec<f64>,
    /// Jacobian values in the problem's pattern, of the last factorisation.
    values: Vec<f64>,
    delta: Vec<f64>,
    /// Right-hand side of a solve.
    rhs: Vec<f64>,
    /// Scratch for the check of each linear solve.
    check: Vec<f64>,
    /// `∂R/∂λ` and `K⁻¹(−∂R/∂λ)` for the current factorisation, when computed.
    load_derivative: Vec<f64>,
    load_solution: Vec<f64>,
    load_solution_valid: bool,
    load_derivative_valid: bool,
    lu: SparseLu,
    /// The regularised symmetric `LDLᵀ` of a problem whose Jacobian is a KKT matrix (see
    /// [`Problem::kkt_structure`]), tried before LU at every factorisation once a first
    /// LU has passed and unless exact solves are asked for.
    kkt: Option<Box<InertiaCounter>>,
    /// Which factorisation holds the current Jacobian.
    active: Factor,
    /// Whether a factorisation by LU has succeeded: the first is by LU, which finds a
    /// singular system (redundant constraints, a free rigid motion) that the regularised
    /// `LDLᵀ` would solve as if it were regular.
    lu_passed: bool,
    /// Every factorisation by LU (see [`Newton::set_exact`]).
    exact: bool,
    /// Numeric factorisations done (of either kind).
    factorisations: usize,
    /// A factorisation is held (of the Jacobian at some recent iterate) and may be reused.
    fresh: bool,
}

/// The factorisation that holds the current Jacobian.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Factor {
    Lu,
    Kkt,
}

/// Corrections of a regularised `LDLᵀ` solve against the unregularised matrix: the
/// regularisation at `1e-8` of the Hessian's scale leaves an error of that order, one
/// correction its square, far below what Newton's iterations need (each solve is checked).
const KKT_REFINEMENTS: usize = 1;

impl Newton {
    pub fn new<P: Problem>(problem: &P) -> Newton {
        let n = problem.unknowns();
        let kkt = problem
            .kkt_structure()
            .and_then(|s| InertiaCounter::with_structure(s).ok().map(Box::new));
        Newton {
            residual: vec![0.0; n],
            weights: vec![1.0; n],
            values: vec![0.0; problem.pattern().row_idx().len()],
            delta: vec![0.0; n],
            rhs: vec![0.0; n],
            check: vec![0.0; n],
            load_derivative: vec![0.0; n],
            load_solution: vec![0.0; n],
            load_solution_valid: false,
            load_derivative_valid: false,
            lu: SparseLu::default(),
            kkt,
            active: Factor::Lu,
            lu_passed: false,
            exact: false,
            factorisations: 0,
            fresh: false,
        }
    }

    /// Numeric factorisations done by this solver.
    pub fn factorisations(&self) -> usize {
        self.factorisations
    }

    /// Counts `earlier` factorisations as this solver's own (a solver that replaces one).
    pub fn carry_count(&mut self, earlier: usize) {
        self.factorisations = earlier;
    }

    /// The factorisation held is not to be reused (the next solve starts elsewhere).
    pub fn discard_factorisation(&mut self) {
        self.fresh = false;
    }

    fn matrix<'a, P: Problem>(&'a self, problem: &'a P) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(problem.pattern().as_ref(), &self.values)
    }

    /// Factorises the Jacobian at `(x, λ)`.
    pub fn factorize_at<P: Problem>(
        &mut self,
        problem: &mut P,
        x: &[f64],
        lambda: f64,
    ) -> Result<(), LinearError> {
        problem.jacobian(x, lambda, &mut self.residual, &mut self.values);
        self.fresh = false;
        self.load_solution_valid = false;
        self.factorisations += 1;
        let symmetric = self.lu_passed
            && !self.exact
            && self
                .kkt
                .as_mut()
                .is_some_and(|k| k.factorize_kkt(&self.values).is_ok());
        if symmetric {
            self.active = Factor::Kkt;
        } else {
            self.factorize_lu(problem)?;
        }
        self.fresh = true;
        Ok(())
    }

    /// LU of the Jacobian values held.
    fn factorize_lu<P: Problem>(&mut self, problem: &P) -> Result<(), LinearError> {
        let matrix = SparseColMatRef::new(problem.pattern().as_ref(), &self.values);
        self.lu.factorize(matrix)?;
        self.active = Factor::Lu;
        Ok(())
    }

    /// Whether every factorisation is to be by LU (exact solves: the location of critical
    /// points) or the regularised `LDLᵀ` may be tried first.
    pub fn set_exact(&mut self, exact: bool) {
        self.exact = exact;
    }

    /// Whether the solve by LU that a problem starts with passed its check.
    fn note_lu_check(&mut self, passed: bool) {
        if self.active == Factor::Lu && passed {
            self.lu_passed = true;
        }
    }

    /// `out = K⁻¹ rhs` with the current factorisation, unchecked.
    fn solve_unchecked(&mut self, rhs: &[f64], out: &mut [f64]) {
        match (self.active, self.kkt.as_mut()) {
            (Factor::Kkt, Some(kkt)) => kkt.solve_kkt(rhs, out, KKT_REFINEMENTS),
            _ => {
                out.copy_from_slice(rhs);
                self.lu.solve(out);
            }
        }
    }

    /// Solves `K out = rhs` with the current factorisation and checks the solve against
    /// `threshold` (relative residual).
    fn solve_checked<P: Problem>(
        &mut self,
        problem: &P,
        rhs: &[f64],
        out: &mut [f64],
        threshold: f64,
    ) -> Result<(), LinearError> {
        self.solve_unchecked(rhs, out);
        let mut check = std::mem::take(&mut self.check);
        let mut rel = relative_residual(self.matrix(problem), out, rhs, &mut check);
        let failed = |rel: f64| rel.is_nan() || rel > threshold;
        if failed(rel) && self.active == Factor::Kkt {
            // the regularised LDLᵀ lost accuracy (pivots near zero): LU of the same matrix
            self.factorisations += 1;
            if let Err(e) = self.factorize_lu(problem) {
                self.check = check;
                return Err(e);
            }
            self.solve_unchecked(rhs, out);
            rel = relative_residual(self.matrix(problem), out, rhs, &mut check);
        }
        self.check = check;
        self.note_lu_check(!failed(rel));
        if failed(rel) {
            return Err(LinearError::Singular {
                relative_residual: rel,
            });
        }
        Ok(())
    }

    /// `dx/dλ = K⁻¹(−∂R/∂λ)` at `(x, λ)`, factorising there; the factorisation is kept for
    /// the next corrector.
    pub fn tangent<P: Problem>(
        &mut self,
        problem: &mut P,
        x: &[f64],
        lambda: f64,
        threshold: f64,
    ) -> Result<Vec<f64>, LinearError> {
        self.factorize_at(problem, x, lambda)?;
        self.update_load_derivative(problem, x, lambda);
        let rhs: Vec<f64> = self.load_derivative.iter().map(|v| -v).collect();
        let mut t = vec![0.0; rhs.len()];
        self.solve_checked(problem, &rhs, &mut t, threshold)?;
        Ok(t)
    }

    /// A near-null vector of the Jacobian at `(x, λ)` by inverse iteration (30 passes from a
    /// fixed start), scaled to unit norm over the primal unknowns.
    pub fn null_vector<P: Problem>(
        &mut self,
        problem: &mut P,
        x: &[f64],
        lambda: f64,
    ) -> Option<Vec<f64>> {
        let np = problem.primal_unknowns();
        let n = problem.unknowns();
        // by LU: the regularised LDLᵀ's refinement against a singular matrix does not
        // converge to the null vector
        let exact = std::mem::replace(&mut self.exact, true);
        let factorised = self.factorize_at(problem, x, lambda);
        self.exact = exact;
        factorised.ok()?;
        let mut v: Vec<f64> = (0..n)
            .map(|i| {
                if i < np {
                    1.0 + (i % 5) as f64 * 0.3
                } else {
                    0.0
                }
            })
            .collect();
        let mut w = vec![0.0; n];
        for _ in 0..30 {
            self.solve_unchecked(&v, &mut w);
            std::mem::swap(&mut v, &mut w);
            let norm = (0..np).map(|i| v[i] * v[i]).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return None;
            }
            v.iter_mut().for_each(|x| *x /= norm);
        }
        Some(v)
    }

    /// `∂R/∂λ` at `(x, λ)` into `self.load_derivative`: once for problems where it is
    /// constant, at every call otherwise.
    fn update_load_derivative<P: Problem>(&mut self, problem: &mut P, x: &[f64], lambda: f64) {
        if problem.load_derivative_is_constant() && self.load_derivative_valid {
            return;
        }
        problem.load_derivative(x, lambda, &mut self.load_derivative);
        self.load_derivative_valid = true;
        self.load_solution_valid = false;
    }

    /// `K b = −∂R/∂λ` with the current factorisation, into `self.load_solution`.
    fn solve_load<P: Problem>(&mut self, problem: &P, threshold: f64) -> Result<(), LinearError> {
        for (r, v) in self.rhs.iter_mut().zip(&self.load_derivative) {
            *r = -v;
        }
        let (rhs, mut out) = (
            std::mem::take(&mut self.rhs),
            std::mem::take(&mut self.load_solution),
        );
        let checked = self.solve_checked(problem, &rhs, &mut out, threshold);
        (self.rhs, self.load_solution) = (rhs, out);
        checked?;
        self.load_solution_valid = true;
        Ok(())
    }

    /// `K a = −R` with the current factorisation, into `self.delta`.
    fn solve_residual<P: Problem>(
        &mut self,
        problem: &P,
        threshold: f64,
    ) -> Result<(), LinearError> {
        for (r, v) in self.rhs.iter_mut().zip(&self.residual) {
            *r = -v;
        }
        let (rhs, mut a) = (
            std::mem::take(&mut self.rhs),
            std::mem::take(&mut self.delta),
        );
        let checked = self.solve_checked(problem, &rhs, &mut a, threshold);
        (self.rhs, self.delta) = (rhs, a);
        checked
    }

    /// Newton iterations on `R(x, λ) = 0` bordered by the step equation `step`, from
    /// `(x, λ)` until `‖R‖∞ ≤ tolerance`. On error `x` and `λ` hold the last iterate, which
    /// the caller must discard.
    ///
    /// Modified Newton: a factorisation already held (e.g. the Jacobian at the last
    /// converged state, used for the predictor) is reused while it contracts the residual by
    /// at least `REFACTOR_RATIO` per iteration; otherwise the Jacobian is refactorised at the
    /// current iterate, so the method falls back to full Newton where it must. Each solve is
    /// bordered: `K a = −R`, `K b = −∂R/∂λ`, then `δλ` from the step equation and
    /// `δx = a + δλ b`.
    pub fn solve<P: Problem>(
        &mut self,
        problem: &mut P,
        x: &mut [f64],
        lambda: &mut f64,
        step: &StepEquation,
        settings: &NewtonSettings,
        interrupt: Option<&Interrupt>,
    ) -> Result<NewtonReport, NewtonError> {
        const REFACTOR_RATIO: f64 = 0.25;
        let threshold = settings.singular_threshold;
        let np = problem.primal_unknowns();
        let mut first = f64::NAN;
        let mut previous = f64::INFINITY;
        let mut stale = false; // the factorisation is not of the current iterate
        let mut last = f64::NAN;
        // the problem's constraints (and so its rows) may have changed since the last solve
        problem.residual_weights(&mut self.weights);
        for it in 0..=settings.max_iterations {
            if let Some(why) = interrupt.and_then(Interrupt::check) {
                return Err(NewtonError::Interrupted { iteration: it, why });
            }
            let energy = problem.residual(x, *lambda, &mut self.residual);
            let reported = norm_inf(&self.residual);
            // the convergence test, free of the units of force and length
            let r = weighted_norm(&self.residual, &self.weights);
            if it == 0 {
                first = r;
            }
            last = reported;
            let step_eq = step.residual(&x[..np], *lambda);
            if r <= settings.tolerance && step_eq.abs() <= 1e-10 * (1.0 + step.ds.abs()) {
                return converged(x, *lambda, energy, reported, it);
            }
            let diverging = !r.is_finite() || (it > 0 && r > 1e6 * first.max(settings.tolerance));
            if diverging && (!stale || !r.is_finite()) {
                return Err(NewtonError::Diverged {
                    iteration: it,
                    residual: reported,
                });
            }
            if it == settings.max_iterations {
                break;
            }
            let linear = |source| NewtonError::Linear {
                iteration: it,
                source,
            };
            // refactorise unless a factorisation is at hand and still contracting well
            let contracting = r <= REFACTOR_RATIO * previous;
            if !self.fresh || (stale && !contracting) {
                self.factorize_at(problem, x, *lambda).map_err(linear)?;
            }
            previous = r;
            self.update_load_derivative(problem, x, *lambda);
            // K b = −∂R/∂λ, once per factorisation where ∂R/∂λ is constant
            if !self.load_solution_valid && step.has_tangent_part() {
                self.solve_load(problem, threshold).map_err(linear)?;
            }
            self.solve_residual(problem, threshold).map_err(linear)?;
            self.bordered_update(problem, x, lambda, step, step_eq, threshold)
                .map_err(linear)?;
            stale = true;
        }
        Err(NewtonError::NotConverged {
            iterations: settings.max_iterations,
            residual: last,
        })
    }

    /// The bordered update from the solutions `a` (in `self.delta`) of `K a = −R` and `b`
    /// (in `self.load_solution`) of `K b = −∂R/∂λ`: `δλ` from the step equation `step`
    /// linearised about its residual `step_eq`, then `x += a + δλ b` and `λ += δλ`.
    fn bordered_update<P: Problem>(
        &mut self,
        problem: &P,
        x: &mut [f64],
        lambda: &mut f64,
        step: &StepEquation,
        step_eq: f64,
        threshold: f64,
    ) -> Result<(), LinearError> {
        let np = problem.primal_unknowns();
        // δλ from the linearised step equation
        let (ta, tb) = if self.load_solution_valid {
            (
                step.along(&self.delta[..np]),
                step.along(&self.load_solution[..np]),
            )
        } else {
            (0.0, 0.0)
        };
        let denominator = tb + step.tl;
        if denominator.abs() < 1e-14 {
            return Err(LinearError::Singular {
                relative_residual: f64::INFINITY,
            });
        }
        let dl = (-step_eq - ta) / denominator;
        if dl != 0.0 {
            // δx = a + δλ b; in natural-parameter steps b is computed only when λ moves
            if !self.load_solution_valid {
                self.solve_load(problem, threshold)?;
            }
            for (d, bi) in self.delta.iter_mut().zip(&self.load_solution) {
                *d += dl * bi;
            }
        }
        for (xi, di) in x.iter_mut().zip(&self.delta) {
            *xi += di;
        }
        *lambda += dl;
        Ok(())
    }
}

/// The report of a solve converged at iteration `iteration` to `(x, λ)` with `energy` and
/// the residual's `‖R‖∞` `residual`, or an error if any of them is not finite.
fn converged(
    x: &[f64],
    lambda: f64,
    energy: f64,
    residual: f64,
    iteration: usize,
) -> Result<NewtonReport, NewtonError> {
    let what = if !energy.is_finite() {
        Some("energy")
    } else if !lambda.is_finite() || x.iter().any(|v| !v.is_finite()) {
        Some("unknown")
    } else {
        None
    };
    if let Some(what) = what {
        return Err(NewtonError::NonFinite { iteration, what });
    }
    Ok(NewtonReport {
        iterations: iteration,
        residual,
        energy,
    })
}

/// `max_i |w_i r_i|` (NaN if any row is).
fn weighted_norm(r: &[f64], w: &[f64]) -> f64 {
    r.iter().zip(w).fold(0.0f64, |m, (x, w)| {
        if x.is_nan() {
            f64::NAN
        } else {
            m.max((w * x).abs())
        }
    })
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(
        0.0f64,
        |m, x| if x.is_nan() { f64::NAN } else { m.max(x.abs()) },
    )
}
