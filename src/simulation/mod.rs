//! Continuation in a load parameter `λ` (DESIGN.md §3, §5): under displacement control
//! `λ = ε`, the compression ratio; under load control `λ = P / Pcrit`, the compressive dead
//! load on every tip over the Euler load. Tangent predictor, modified-Newton corrector,
//! adaptive step length with cut-backs, pseudo-arclength steps where natural ones fail
//! (folds), the stability of every converged state, critical points located by bisection
//! on the count of unstable directions, and branch switching at bifurcations.

use crate::discretisation::fields;
use crate::discretisation::model::{DiscreteModel, End};
use crate::discretisation::symmetry::expand_state;
use crate::discretisation::system::System;
use crate::model::boundary::BoundaryConditions;
use crate::model::loading::{Control, TipLoad};
use crate::results::{CriticalKind, CriticalPoint, LoadPoint, Snapshot, Stability};
use crate::solver::continuation::{ContinuationSettings, SolveError, Statistics, StopReason};
use crate::solver::inertia::{InertiaCounter, InertiaError};
use crate::solver::linear::LinearError;
use crate::solver::newton::{self, Border, NewtonError, NewtonReport, Workspace};
use std::time::Instant;

/// A discrete model under boundary conditions, at a converged state, that can be moved
/// along its load path.
pub struct Simulation {
    pub model: DiscreteModel,
    system: System,
    ws: Workspace,
    control: Control,
    /// Converged state: primal unknowns then multipliers.
    x: Vec<f64>,
    /// Load parameter of `x`.
    lambda: f64,
    /// `dx/dλ` at the converged state, when known.
    tangent: Option<Vec<f64>>,
    /// The converged point before this one, for secant predictors in arclength mode.
    previous: Option<(Vec<f64>, f64)>,
    /// Step length: in `λ` for natural steps, in arclength otherwise.
    step: f64,
    arclength: bool,
    last: NewtonReport,
    pub settings: ContinuationSettings,
    pub stats: Statistics,
    inertia: Option<InertiaCounter>,
    stability: Option<Stability>,
    critical: Vec<CriticalPoint>,
    /// For a symmetric pair: the full model, on which stability is judged (a symmetric
    /// state can lose stability to modes that break the symmetry).
    full: Option<FullModel>,
}

/// The full model behind a symmetric pair, for stability checks.
struct FullModel {
    model: DiscreteModel,
    system: System,
}

/// The step equation `t_xᵀ (x − x0) + t_λ (λ − λ0) = ds` of a corrector.
#[derive(Clone, Copy)]
struct StepEquation<'a> {
    tx: &'a [f64],
    tl: f64,
    x0: &'a [f64],
    l0: f64,
    ds: f64,
}

/// A trial step's outcome (not yet accepted).
struct Trial {
    x: Vec<f64>,
    lambda: f64,
    report: NewtonReport,
}

impl Simulation {
    /// The case's simulation at its natural state (`ε = 0`, solved), under the case's
    /// boundary conditions, control and solver settings.
    pub fn from_case(case: &crate::case::Case) -> Result<Simulation, SolveError> {
        let model = case.model();
        let x0 = model.natural_state();
        Simulation::from_state(model, case.boundary, case.loading.control, x0, case.solver)
    }

    /// Starts from the natural state at `ε = 0` under displacement control and solves it.
    pub fn new(
        model: DiscreteModel,
        bc: BoundaryConditions,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        let x0 = model.natural_state();
        Simulation::from_state(model, bc, Control::Displacement, x0, settings)
    }

    /// Starts from a given primal state `x` (nodal quaternions and positions, e.g. of
    /// other helices than the natural ones) and solves it: the supports hold the ends
    /// where `x` puts them; under displacement control `ε` is that of `x`'s tip height,
    /// under load control the load starts at zero.
    pub fn from_state(
        model: DiscreteModel,
        bc: BoundaryConditions,
        control: Control,
        mut x: Vec<f64>,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        x.truncate(model.n_primal);
        let height = mean_tip_height(&model, &x);
        let lambda = match control {
            Control::Displacement => 1.0 - height / model.height0(),
            Control::Force => 0.0,
        };
        let tip_load = tip_load(&model, control, lambda);
        let system = System::new(&model, bc, &x, tip_load);
        let full = model.full_model().map(|m| {
            let x0 = m.natural_state();
            let system = System::new(&m, bc, &x0, tip_load);
            FullModel { model: m, system }
        });
        x.resize(system.n, 0.0);
        let ws = Workspace::new(&system);
        let mut sim = Simulation {
            model,
            system,
            ws,
            control,
            x,
            lambda,
            tangent: None,
            previous: None,
            step: settings.initial_step,
            arclength: false,
            last: NewtonReport {
                iterations: 0,
                residual: 0.0,
                energy: 0.0,
            },
            settings,
            stats: Statistics::default(),
            inertia: None,
            stability: None,
            critical: Vec::new(),
            full,
        };
        sim.correct_in_place()?;
        sim.update_stability(true);
        Ok(sim)
    }

    /// The perfect-helix equilibria of DESIGN.md §6 (Love): every rod held at both ends
    /// (clamped, no joints) on the helix of the given radius and pitch parameter (m) with
    /// its own arc length, chirality and base angle, and solved there.
    pub fn held_on_helices(
        model: DiscreteModel,
        radius: f64,
        pitch: f64,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        let targets: Vec<crate::model::helix::Helix> = model
            .rods
            .iter()
            .map(|r| crate::model::helix::Helix {
                radius,
                pitch,
                ..r.helix
            })
            .collect();
        let x = model.helix_state(&targets);
        let bc = BoundaryConditions {
            joints: false,
            ..Default::default()
        };
        Simulation::from_state(model, bc, Control::Displacement, x, settings)
    }

    /// Euler load of a clamped–clamped rod, `Pcrit = B1 (2π/L)²` (N): the unit of `λ`
    /// under load control.
    pub fn pcrit(&self) -> f64 {
        self.model.stiffness.euler_load(self.model.length())
    }

    pub fn control(&self) -> Control {
        self.control
    }

    /// Current load parameter `λ`.
    pub fn parameter(&self) -> f64 {
        self.lambda
    }

    /// Compression ratio of the current state, from the mean tip height.
    pub fn eps(&self) -> f64 {
        1.0 - mean_tip_height(&self.model, &self.x) / self.model.height0()
    }

    /// Tip height `h = h0 (1 − ε)` (m) at compression ratio `eps`.
    pub fn height_at(&self, eps: f64) -> f64 {
        self.model.height0() * (1.0 - eps)
    }

    pub fn boundary_conditions(&self) -> BoundaryConditions {
        self.system.bc
    }

    pub fn system(&self) -> &System {
        &self.system
    }

    /// The converged state vector.
    pub fn state(&self) -> &[f64] {
        &self.x
    }

    /// The current internal step length.
    pub fn step_length(&self) -> f64 {
        self.step
    }

    /// Whether steps are pseudo-arclength ones.
    pub fn is_arclength(&self) -> bool {
        self.arclength
    }

    /// Newton report of the solve that produced the current state.
    pub fn last_solve(&self) -> NewtonReport {
        self.last
    }

    /// Stability of the current state, when tracked and computable.
    pub fn stability(&self) -> Option<Stability> {
        self.stability
    }

    /// Critical points located so far.
    pub fn critical_points(&self) -> &[CriticalPoint] {
        &self.critical
    }

    fn tip_load(&self, lambda: f64) -> TipLoad {
        tip_load(&self.model, self.control, lambda)
    }

    /// `∂R/∂λ`.
    fn dr_dl(&self) -> Vec<f64> {
        let factor = match self.control {
            Control::Displacement => -self.model.height0(), // dh/dε
            Control::Force => self.pcrit(),                 // dP/dλ
        };
        self.system
            .load_derivative(&self.model)
            .into_iter()
            .map(|v| v * factor)
            .collect()
    }

    fn error(&self, target: f64, step: f64, reason: StopReason) -> SolveError {
        SolveError {
            control: self.control.name(),
            reached: self.lambda,
            eps: self.eps(),
            target,
            step,
            reason,
        }
    }

    /// Runs the bordered Newton corrector from `(x, λ)`; counts its work.
    fn correct(
        &mut self,
        mut x: Vec<f64>,
        mut lambda: f64,
        step: StepEquation,
    ) -> Result<Trial, NewtonError> {
        let t0 = Instant::now();
        let dr_dl = self.dr_dl();
        let border = Border {
            tx: step.tx,
            tl: step.tl,
            x0: step.x0,
            l0: step.l0,
            ds: step.ds,
            dr_dl: &dr_dl,
        };
        let before = self.ws.lu.factorisations;
        let (model, control) = (&self.model, self.control);
        let load = |l: f64| tip_load(model, control, l);
        let out = newton::solve(
            &self.model,
            &mut self.system,
            &mut x,
            &mut lambda,
            &load,
            &border,
            &mut self.ws,
            &self.settings.newton,
        );
        self.stats.factorisations += self.ws.lu.factorisations - before;
        self.stats.time += t0.elapsed();
        // the system keeps the load of the converged state
        self.system.set_tip_load(self.tip_load(self.lambda));
        out.map(|report| {
            self.stats.iterations += report.iterations;
            Trial { x, lambda, report }
        })
    }

    /// Newton at fixed `λ` from the current state; keeps the old state on failure.
    fn correct_in_place(&mut self) -> Result<(), SolveError> {
        let zeros = vec![0.0; self.model.n_primal];
        let x0 = self.x.clone();
        let l0 = self.lambda;
        match self.correct(
            x0.clone(),
            l0,
            StepEquation {
                tx: &zeros,
                tl: 1.0,
                x0: &x0,
                l0,
                ds: 0.0,
            },
        ) {
            Ok(t) => {
                self.x = t.x;
                self.last = t.report;
                self.tangent = None;
                self.previous = None;
                Ok(())
            }
            Err(cause) => Err(self.error(l0, 0.0, StopReason::Newton { step: 0.0, cause })),
        }
    }

    /// `dx/dλ` at the current state from `K t = −∂R/∂λ`. The factorisation at the
    /// converged state is kept for the next corrector.
    fn compute_tangent(&mut self) -> Option<Vec<f64>> {
        let before = self.ws.lu.factorisations;
        let ok = self
            .ws
            .factorize_at(&self.model, &self.system, &self.x)
            .is_ok();
        self.stats.factorisations += self.ws.lu.factorisations - before;
        if !ok {
            return None;
        }
        let rhs: Vec<f64> = self.dr_dl().iter().map(|v| -v).collect();
        let mut t = vec![0.0; self.system.n];
        self.ws
            .solve_checked(
                &self.system,
                &rhs,
                &mut t,
                self.settings.newton.singular_threshold,
            )
            .ok()?;
        Some(t)
    }

    /// Unit tangent `(t_x, t_λ)` over the primal unknowns and `λ`, and the full-length
    /// predictor direction, for an arclength step heading towards increasing `dir · λ`.
    fn arclength_direction(&mut self, dir: f64) -> Option<(Vec<f64>, f64, Vec<f64>)> {
        let np = self.model.n_primal;
        let (full, dl) = match &self.previous {
            Some((xp, lp)) => {
                let d: Vec<f64> = self.x.iter().zip(xp).map(|(a, b)| a - b).collect();
                (d, self.lambda - lp)
            }
            None => {
                if self.tangent.is_none() {
                    self.tangent = self.compute_tangent();
                }
                let t = self.tangent.clone()?;
                (t.iter().map(|v| v * dir).collect(), dir)
            }
        };
        let norm = ((0..np).map(|i| full[i] * full[i]).sum::<f64>() + dl * dl).sqrt();
        if norm.is_nan() || norm <= 0.0 {
            return None;
        }
        let full: Vec<f64> = full.iter().map(|v| v / norm).collect();
        Some((full[..np].to_vec(), dl / norm, full))
    }

    /// One step of length `h` (natural: in `λ` towards `dir`; arclength: along the path).
    fn try_step(&mut self, h: f64, dir: f64) -> Result<Trial, NewtonError> {
        if self.arclength {
            let Some((tx, tl, full)) = self.arclength_direction(dir) else {
                return Err(NewtonError::Linear {
                    iteration: 0,
                    source: LinearError::Singular {
                        relative_residual: f64::INFINITY,
                    },
                });
            };
            let x: Vec<f64> = self.x.iter().zip(&full).map(|(a, t)| a + h * t).collect();
            let lambda = self.lambda + h * tl;
            let x0 = self.x.clone();
            self.correct(
                x,
                lambda,
                StepEquation {
                    tx: &tx,
                    tl,
                    x0: &x0,
                    l0: self.lambda,
                    ds: h,
                },
            )
        } else {
            if self.tangent.is_none() {
                self.tangent = self.compute_tangent();
            }
            let d = dir * h;
            let mut x = self.x.clone();
            if let Some(t) = &self.tangent {
                for (xi, ti) in x.iter_mut().zip(t) {
                    *xi += ti * d;
                }
            }
            let zeros = vec![0.0; self.model.n_primal];
            let x0 = self.x.clone();
            self.correct(
                x,
                self.lambda + d,
                StepEquation {
                    tx: &zeros,
                    tl: 1.0,
                    x0: &x0,
                    l0: self.lambda,
                    ds: d,
                },
            )
        }
    }

    fn accept(&mut self, trial: Trial) {
        let old = std::mem::replace(&mut self.x, trial.x);
        self.previous = Some((old, self.lambda));
        self.lambda = trial.lambda;
        self.system.set_tip_load(self.tip_load(self.lambda));
        self.last = trial.report;
        self.tangent = None;
        self.stats.steps += 1;
        if self.arclength {
            self.stats.arclength_steps += 1;
        }
    }

    /// Continues to load parameter `target` with as many internal steps as needed.
    /// On failure the last converged state is kept and the error says where and why.
    pub fn advance_to(&mut self, target: f64) -> Result<(), SolveError> {
        const MAX_ARCLENGTH_STEPS: usize = 2000;
        let s = self.settings;
        let mut arclength_steps = 0;
        while (target - self.lambda).abs() > 1e-14 * (1.0 + target.abs()) {
            let dir = (target - self.lambda).signum();
            let remaining = (target - self.lambda).abs();
            // `nominal` is the adaptive step; the last natural step is shortened to land
            // on the target without shrinking the step for what follows
            let mut nominal = self.step.min(s.max_step);
            let h = if self.arclength {
                nominal
            } else {
                nominal.min(remaining)
            };
            let trial = self.try_step(h, dir);
            match trial {
                Ok(t) => {
                    // an arclength step that overshoots the target: land on it exactly
                    let overshoot = self.arclength && (t.lambda - target) * dir > 0.0;
                    if overshoot {
                        self.arclength = false;
                        self.step = remaining.max(s.min_step);
                        self.ws.fresh = false;
                        continue;
                    }
                    let iterations = t.report.iterations;
                    let before = self.stability;
                    let x_before = self.x.clone();
                    let l_before = self.lambda;
                    let was_arclength = self.arclength;
                    self.accept(t);
                    if self.arclength {
                        arclength_steps += 1;
                        if arclength_steps > MAX_ARCLENGTH_STEPS {
                            return Err(self.error(
                                target,
                                h,
                                StopReason::TurnedBack {
                                    steps: MAX_ARCLENGTH_STEPS,
                                },
                            ));
                        }
                    }
                    self.update_stability(false);
                    if let (Some(b), Some(a)) = (before, self.stability) {
                        if a.unstable_directions != b.unstable_directions {
                            self.locate_critical(&x_before, l_before, was_arclength, b, a);
                        }
                    }
                    // adapt the step length to the Newton effort
                    if iterations + 1 < s.target_iterations {
                        nominal = (nominal * 1.5).min(s.max_step);
                    } else if iterations > s.target_iterations + 2 {
                        nominal = h * 0.6;
                    }
                    self.step = nominal.max(s.min_step);
                }
                Err(cause) => {
                    self.stats.rejected += 1;
                    self.ws.fresh = false;
                    if h <= s.min_step * 1.000001 {
                        if !self.arclength && s.arclength_fallback {
                            // change strategy: pseudo-arclength from here
                            self.arclength = true;
                            self.step = s.initial_step.min(s.max_step);
                            continue;
                        }
                        self.step = s.min_step;
                        return Err(self.error(target, h, StopReason::Newton { step: h, cause }));
                    }
                    self.step = (h * 0.5).max(s.min_step);
                }
            }
        }
        self.lambda = target;
        self.system.set_tip_load(self.tip_load(self.lambda));
        // the count is that of the last accepted step; the lowest eigenvalue is added at
        // output points only
        if s.track_stability && s.lowest_eigenvalue {
            self.update_stability(true);
        }
        Ok(())
    }

    /// Counts unstable directions at the current state (and the lowest eigenvalue when
    /// `eigenvalue` is set).
    fn update_stability(&mut self, eigenvalue: bool) {
        if !self.settings.track_stability {
            self.stability = None;
            return;
        }
        let count = self.unstable_directions().ok();
        self.stability = count.map(|c| Stability {
            unstable_directions: c,
            lowest_eigenvalue: if eigenvalue && self.settings.lowest_eigenvalue {
                self.lowest_eigenvalue().map(|(l, _)| l)
            } else {
                None
            },
        });
    }

    /// Number of unstable directions of the current state: negative eigenvalues of the
    /// Hessian of the Lagrangian on the tangent space of the constraints.
    pub fn unstable_directions(&mut self) -> Result<usize, InertiaError> {
        let x = self.x.clone();
        self.unstable_directions_at(&x)
    }

    /// The KKT values at state `x`, of the full model when this is a symmetric pair, with
    /// that model and its number of primal unknowns.
    fn stability_matrix(&self, x: &[f64]) -> (Vec<f64>, &DiscreteModel) {
        let (model, system, x) = match &self.full {
            Some(f) => (
                &f.model,
                &f.system,
                expand_state(&self.model, &self.system, x, &f.model, &f.system),
            ),
            None => (&self.model, &self.system, x.to_vec()),
        };
        let mut residual = vec![0.0; system.n];
        let mut values = system.new_values();
        system.evaluate(model, &x, &mut residual, &mut values);
        (values, model)
    }

    /// Counts the eigenvalues of the constrained Hessian below `−τ`, `τ = 1e-9 ρ / m̄` (`ρ`
    /// the mean diagonal of the Hessian, `m̄` the mean metric weight): the rounding level
    /// of the regularised LDLᵀ's pivots in eigenvalue units, which grows as the mesh is
    /// refined. Eigenvalues closer to zero than the count can resolve — a neutral direction
    /// such as a buckled isotropic rod turning about its axis, or the two halves of a
    /// double critical eigenvalue — count as stable, so a double eigenvalue crosses as one
    /// event; critical points are then placed by a secant on the eigenvalue itself. A
    /// symmetric pair is judged on the full model.
    fn unstable_directions_at(&mut self, x: &[f64]) -> Result<usize, InertiaError> {
        if self.inertia.is_none() {
            let counter = match &self.full {
                Some(f) => InertiaCounter::new(&f.system, f.model.n_primal)?,
                None => InertiaCounter::new(&self.system, self.model.n_primal)?,
            };
            self.inertia = Some(counter);
        }
        let (values, model) = self.stability_matrix(x);
        let metric = metric(model);
        let mean_metric =
            metric.iter().sum::<f64>() / metric.iter().filter(|&&m| m > 0.0).count().max(1) as f64;
        let counter = self.inertia.as_mut().expect("built above");
        let tau = 1e-9 * counter.hessian_scale(&values) / mean_metric;
        let inertia = counter.inertia(&values, -tau, &metric)?;
        Ok(counter.unstable_directions(inertia).max(0) as usize)
    }

    /// The eigenvalue nearest zero of the constrained Hessian at state `x` (of the full
    /// model for a symmetric pair).
    fn eigenvalue_nearest_zero_at(&mut self, x: &[f64]) -> Option<f64> {
        let (values, model) = self.stability_matrix(x);
        let metric = metric(model);
        let np = model.n_primal;
        self.inertia
            .as_mut()?
            .eigenvalue_nearest_zero(&values, &metric, np)
            .map(|(l, _)| l)
    }

    /// Lowest eigenvalue (J/m) and mode of the constrained Hessian at the current state (of
    /// the full model for a symmetric pair), by inverse iteration below the spectrum.
    fn lowest_eigenvalue(&mut self) -> Option<(f64, Vec<f64>)> {
        let x = self.x.clone();
        let (values, model) = self.stability_matrix(&x);
        let metric = metric(model);
        let np = model.n_primal;
        self.inertia
            .as_mut()?
            .lowest_eigenvalue(&values, &metric, np)
    }

    /// Locates the critical point crossed by the accepted step from `(x0, λ0)`: bisection
    /// on the change of the unstable count, then a secant on the eigenvalue nearest zero.
    fn locate_critical(
        &mut self,
        x0: &[f64],
        l0: f64,
        arclength: bool,
        before: Stability,
        after: Stability,
    ) {
        let np = self.model.n_primal;
        let saved = (
            self.x.clone(),
            self.lambda,
            self.previous.clone(),
            self.tangent.clone(),
            self.last,
            self.arclength,
        );
        // step direction from the start point, as the accepted step took it
        let x1 = self.x.clone();
        let l1 = self.lambda;
        let d: Vec<f64> = x1.iter().zip(x0).map(|(a, b)| a - b).collect();
        let norm = ((0..np).map(|i| d[i] * d[i]).sum::<f64>() + (l1 - l0).powi(2)).sqrt();
        let (mut lo, mut hi) = (0.0, 1.0); // fractions of the step
        let mut best: Option<(Vec<f64>, f64)> = Some((x1.clone(), l1));
        let mut below: Option<(Vec<f64>, f64, f64)> = None; // the state at `lo`
        let tx: Vec<f64> = if arclength {
            (0..np).map(|i| d[i] / norm).collect()
        } else {
            vec![0.0; np]
        };
        let tl = if arclength { (l1 - l0) / norm } else { 1.0 };
        // near the critical point the KKT matrix is nearly singular: linear solves there
        // have relative residuals up to cond·ε, so the probes accept them (Newton's own
        // residual test still decides convergence)
        let strict = self.settings.newton.singular_threshold;
        self.settings.newton.singular_threshold = strict.max(1e-2);
        let mut offset = 0.5;
        while hi - lo > self.settings.critical_tolerance.max(1e-14) {
            let mid = lo + offset * (hi - lo);
            let xp: Vec<f64> = x0.iter().zip(&d).map(|(a, b)| a + mid * b).collect();
            let lp = l0 + mid * (l1 - l0);
            let ds = if arclength { mid * norm } else { lp - l0 };
            self.ws.fresh = false;
            let trial = self.correct(
                xp,
                lp,
                StepEquation {
                    tx: &tx,
                    tl,
                    x0,
                    l0,
                    ds,
                },
            );
            let Ok(t) = trial else {
                // a probe exactly on the critical point may not converge: probe beside it
                if offset == 0.5 {
                    offset = 0.37;
                    continue;
                }
                break;
            };
            offset = 0.5;
            match self.unstable_directions_at(&t.x) {
                Ok(c) if c == before.unstable_directions => {
                    lo = mid;
                    below = Some((t.x, t.lambda, mid));
                }
                Ok(_) => {
                    hi = mid;
                    best = Some((t.x, t.lambda));
                }
                Err(_) => {
                    // a zero pivot: we are on the critical point
                    best = Some((t.x, t.lambda));
                    break;
                }
            }
        }
        // the counts resolve the crossing only to the rounding of the LDLᵀ near a zero
        // eigenvalue; finish with a secant on the eigenvalue nearest zero (a Rayleigh
        // quotient, accurate to the square of its vector's error), which crosses zero there
        if let Some((xl, _, fl)) = below.clone() {
            let probe = |this: &mut Self, f: f64| -> Option<(f64, Vec<f64>, f64)> {
                let xp: Vec<f64> = x0.iter().zip(&d).map(|(p, q)| p + f * q).collect();
                let lp = l0 + f * (l1 - l0);
                let ds = if arclength { f * norm } else { lp - l0 };
                this.ws.fresh = false;
                let step = StepEquation {
                    tx: &tx,
                    tl,
                    x0,
                    l0,
                    ds,
                };
                let t = this.correct(xp, lp, step).ok()?;
                let mu = this.eigenvalue_nearest_zero_at(&t.x)?;
                Some((mu, t.x, t.lambda))
            };
            let mu_l = self.eigenvalue_nearest_zero_at(&xl);
            let fb = (fl - 0.02).max(0.0);
            if let (Some(mu_a), Some((mu_b, _, _))) = (mu_l, probe(self, fb)) {
                let (mut fa, mut ma, mut fb, mut mb) = (fl, mu_a, fb, mu_b);
                for _ in 0..6 {
                    if (ma - mb).abs() <= f64::EPSILON * ma.abs() || fa == fb {
                        break;
                    }
                    let f = (fa - ma * (fa - fb) / (ma - mb)).clamp(0.0, 1.0);
                    let Some((mu, x, l)) = probe(self, f) else {
                        break;
                    };
                    best = Some((x, l));
                    let converged = (f - fa).abs() <= 1e-13;
                    (fb, mb, fa, ma) = (fa, ma, f, mu);
                    if converged {
                        break;
                    }
                }
            }
        }
        self.settings.newton.singular_threshold = strict;
        if let Some((xc, lc)) = best {
            // critical mode: inverse iteration on the KKT matrix there
            self.x = xc.clone();
            self.lambda = lc;
            self.system.set_tip_load(self.tip_load(lc));
            let mode = self.null_vector();
            // a fold makes dx/dλ blow up, a bifurcation leaves it bounded
            let t_near = self.compute_tangent();
            let kind = match (
                &t_near,
                &saved.3.clone().or_else(|| {
                    self.x = x0.to_vec();
                    self.lambda = l0;
                    self.system.set_tip_load(self.tip_load(l0));
                    self.compute_tangent()
                }),
            ) {
                (Some(a), Some(b)) => {
                    let na = (0..np).map(|i| a[i] * a[i]).sum::<f64>().sqrt();
                    let nb = (0..np).map(|i| b[i] * b[i]).sum::<f64>().sqrt();
                    if na > 1e3 * nb.max(1e-300) {
                        CriticalKind::LimitPoint
                    } else {
                        CriticalKind::Bifurcation
                    }
                }
                (None, _) => CriticalKind::LimitPoint,
                _ => CriticalKind::Bifurcation,
            };
            self.x = xc.clone();
            self.lambda = lc;
            self.system.set_tip_load(self.tip_load(lc));
            let lp = self.load_point(0);
            if let Some(mode) = mode {
                self.critical.push(CriticalPoint {
                    kind,
                    control: self.control,
                    parameter: lc,
                    eps: self.eps(),
                    load: lp.load,
                    unstable_before: before.unstable_directions,
                    unstable_after: after.unstable_directions,
                    state: xc,
                    mode,
                });
            }
        }
        // back to the accepted state
        self.x = saved.0;
        self.lambda = saved.1;
        self.previous = saved.2;
        self.tangent = None;
        self.last = saved.4;
        self.arclength = saved.5;
        self.system.set_tip_load(self.tip_load(self.lambda));
        self.ws.fresh = false;
    }

    /// Near-null vector of the KKT matrix at the current state by inverse iteration,
    /// scaled to unit norm over the primal unknowns.
    fn null_vector(&mut self) -> Option<Vec<f64>> {
        let np = self.model.n_primal;
        let n = self.system.n;
        self.ws
            .factorize_at(&self.model, &self.system, &self.x)
            .ok()?;
        self.stats.factorisations += 1;
        let mut v: Vec<f64> = (0..n)
            .map(|i| {
                if i < np {
                    1.0 + (i % 5) as f64 * 0.3
                } else {
                    0.0
                }
            })
            .collect();
        for _ in 0..30 {
            self.ws.lu.solve(&mut v);
            let norm = (0..np).map(|i| v[i] * v[i]).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return None;
            }
            v.iter_mut().for_each(|x| *x /= norm);
        }
        Some(v)
    }

    /// Leaves the path at bifurcation `index` (of [`Simulation::critical_points`]) along
    /// its critical mode, in the direction `sign` (±1), by an arclength step of `h`
    /// measured along the mode; continuation then goes on in arclength steps along the new
    /// branch.
    pub fn switch_branch(&mut self, index: usize, sign: f64, h: f64) -> Result<(), SolveError> {
        if self.full.is_some() {
            return Err(self.error(self.lambda, 0.0, StopReason::SymmetricPair));
        }
        let Some(cp) = self.critical.get(index).cloned() else {
            return Err(self.error(self.lambda, 0.0, StopReason::NoCriticalPoint { index }));
        };
        let np = self.model.n_primal;
        let tx: Vec<f64> = cp.mode[..np].iter().map(|v| v * sign).collect();
        let x: Vec<f64> = cp
            .state
            .iter()
            .zip(&cp.mode)
            .map(|(a, m)| a + sign * h * m)
            .collect();
        self.ws.fresh = false;
        match self.correct(
            x,
            cp.parameter,
            StepEquation {
                tx: &tx,
                tl: 0.0,
                x0: &cp.state,
                l0: cp.parameter,
                ds: h,
            },
        ) {
            Ok(t) => {
                self.x = cp.state.clone();
                self.lambda = cp.parameter;
                self.arclength = true;
                self.accept(t);
                self.step = h;
                self.update_stability(true);
                Ok(())
            }
            Err(cause) => Err(self.error(cp.parameter, h, StopReason::Newton { step: h, cause })),
        }
    }

    /// Changes the boundary conditions and re-solves at the current load from the current
    /// state; what the new conditions hold is held where it is now. On failure the old
    /// conditions and state are kept.
    pub fn set_boundary_conditions(&mut self, bc: BoundaryConditions) -> Result<(), SolveError> {
        let control = self.control;
        self.rebuild(bc, control)
    }

    /// Changes the control (displacement or load) at the current state: the load
    /// parameter becomes the current `ε`, or the current mean compressive tip force over
    /// `Pcrit`.
    pub fn set_control(&mut self, control: Control) -> Result<(), SolveError> {
        let bc = self.system.bc;
        self.rebuild(bc, control)
    }

    fn rebuild(&mut self, bc: BoundaryConditions, control: Control) -> Result<(), SolveError> {
        let lambda = match control {
            Control::Displacement => self.eps(),
            Control::Force => {
                let lp = self.load_point(0);
                -lp.load[2]
            }
        };
        let tip = tip_load(&self.model, control, lambda);
        let system = System::new(&self.model, bc, &self.x[..self.model.n_primal], tip);
        // inextensibility and unit-norm multipliers keep their rows; support and joint
        // multipliers enter the KKT matrix linearly and restart from zero
        let full = self.model.full_model().map(|m| {
            let x0 = m.natural_state();
            let system = System::new(&m, bc, &x0, tip);
            FullModel { model: m, system }
        });
        let keep = system.linear_row(0).min(self.x.len());
        let mut x = self.x[..keep].to_vec();
        x.resize(system.n, 0.0);
        let old = (
            std::mem::replace(&mut self.system, system),
            std::mem::replace(&mut self.ws, Workspace::new(&self.system)),
            std::mem::replace(&mut self.x, x),
            self.inertia.take(),
            self.control,
            self.lambda,
            self.arclength,
            std::mem::replace(&mut self.full, full),
        );
        self.control = control;
        self.lambda = lambda;
        self.arclength = false;
        self.ws = Workspace::new(&self.system);
        match self.correct_in_place() {
            Ok(()) => {
                self.step = self.settings.initial_step;
                self.update_stability(true);
                Ok(())
            }
            Err(e) => {
                self.system = old.0;
                self.ws = old.1;
                self.x = old.2;
                self.inertia = old.3;
                self.control = old.4;
                self.lambda = old.5;
                self.arclength = old.6;
                self.full = old.7;
                Err(e)
            }
        }
    }

    /// Number of rods of the whole assembly each modelled rod stands for.
    fn images(&self) -> f64 {
        self.model
            .assembly
            .symmetry
            .map_or(1.0, |s| s.full_rods() as f64 / self.model.rods.len() as f64)
    }

    /// Reactions, load, energy and stability at the current state.
    pub fn load_point(&self, step: usize) -> LoadPoint {
        let reactions = fields::reactions(&self.model, &self.system, &self.x);
        let load = fields::normalised_load(&self.model, &reactions);
        let eps = self.eps();
        LoadPoint {
            step,
            eps,
            parameter: self.lambda,
            height: self.height_at(eps),
            reactions,
            load,
            energy: self.last.energy * self.images(),
            iterations: self.last.iterations,
            residual: self.last.residual,
            stability: self.stability,
        }
    }

    /// Shapes and curvatures at the current state.
    pub fn snapshot(&self) -> Snapshot {
        fields::snapshot(&self.model, &self.system, &self.x, self.eps())
    }

    /// Shape of a critical mode: the state displaced by `amplitude` times the mode.
    pub fn mode_snapshot(&self, critical: &CriticalPoint, amplitude: f64) -> Snapshot {
        let x: Vec<f64> = critical
            .state
            .iter()
            .zip(&critical.mode)
            .map(|(a, m)| a + amplitude * m)
            .collect();
        fields::snapshot(&self.model, &self.system, &x, critical.eps)
    }
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

/// Mean tip height over the rods (m).
fn mean_tip_height(model: &DiscreteModel, x: &[f64]) -> f64 {
    let n = model.rods.len() as f64;
    model
        .rods
        .iter()
        .enumerate()
        .map(|(id, r)| model.vertex(x, id, r.end_vertex(End::Tip))[2])
        .sum::<f64>()
        / n
}

fn tip_load(model: &DiscreteModel, control: Control, lambda: f64) -> TipLoad {
    let pcrit = model.stiffness.euler_load(model.length());
    TipLoad::at(control, lambda, model.height0(), pcrit)
}
