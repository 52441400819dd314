//! Displacement-controlled continuation in the compression ratio `ε` (DESIGN.md §3, §5):
//! tangent predictor, Newton corrector, adaptive step length with cut-backs.

use super::newton::{self, NewtonError, NewtonReport, NewtonSettings, Workspace};
use crate::discretisation::system::{DiscreteModel, System};
use crate::model::boundary::BoundaryConditions;
use crate::results::{self, LoadPoint, Snapshot};
use std::time::{Duration, Instant};

/// Step-length control of the continuation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuationSettings {
    /// First internal step in `ε`.
    pub initial_step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Newton iterations aimed at: fewer grow the step, more shrink it.
    pub target_iterations: usize,
    pub newton: NewtonSettings,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings {
            initial_step: 0.01,
            min_step: 1e-6,
            max_step: 0.05,
            target_iterations: 6,
            newton: NewtonSettings::default(),
        }
    }
}

/// The continuation could not reach its target; the last converged state is kept.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("continuation stopped at eps = {reached:.6} (target {target:.6}): a step of {step:.2e} failed: {cause}")]
pub struct SolveError {
    /// Last converged compression ratio.
    pub reached: f64,
    pub target: f64,
    /// The last step tried.
    pub step: f64,
    pub cause: NewtonError,
}

/// Counters of a continuation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Statistics {
    pub steps: usize,
    pub rejected: usize,
    pub iterations: usize,
    pub factorisations: usize,
    pub time: Duration,
}

/// A discrete model under boundary conditions, at a converged state, that can be moved
/// along its load path.
pub struct Simulation {
    pub model: DiscreteModel,
    system: System,
    ws: Workspace,
    /// Converged state: primal unknowns then multipliers.
    x: Vec<f64>,
    eps: f64,
    /// `dx/dε` at the converged state, when known.
    tangent: Option<Vec<f64>>,
    step: f64,
    last: NewtonReport,
    pub settings: ContinuationSettings,
    pub stats: Statistics,
}

impl Simulation {
    /// Starts from the natural state at `ε = 0` and solves it.
    pub fn new(
        model: DiscreteModel,
        bc: BoundaryConditions,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        let x0 = model.natural_state();
        Simulation::from_state(model, bc, x0, settings)
    }

    /// Starts from a given primal state `x` (nodal quaternions and positions, e.g. of
    /// other helices than the natural ones) and solves it: the supports hold the ends
    /// where `x` puts them, and `ε` is that of `x`'s tip height.
    pub fn from_state(
        model: DiscreteModel,
        bc: BoundaryConditions,
        mut x: Vec<f64>,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        x.truncate(model.n_primal);
        let tip = model.rods[0].end_vertex(crate::discretisation::system::End::Tip);
        let height = model.vertex(&x, 0, tip)[2];
        let eps = 1.0 - height / model.height0();
        let system = System::new(&model, bc, &x, height);
        x.resize(system.n, 0.0);
        let ws = Workspace::new(&system);
        let mut sim = Simulation {
            model,
            system,
            ws,
            x,
            eps,
            tangent: None,
            step: settings.initial_step,
            last: NewtonReport {
                iterations: 0,
                residual: 0.0,
                energy: 0.0,
            },
            settings,
            stats: Statistics::default(),
        };
        sim.correct_in_place(eps)?;
        Ok(sim)
    }

    /// Current compression ratio.
    pub fn eps(&self) -> f64 {
        self.eps
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

    /// Newton report of the solve that produced the current state.
    pub fn last_solve(&self) -> NewtonReport {
        self.last
    }

    /// Newton at fixed `ε` from the current state; keeps the old state on failure.
    fn correct_in_place(&mut self, eps: f64) -> Result<(), SolveError> {
        let t0 = Instant::now();
        self.system.set_height(self.height_at(eps));
        let mut x = self.x.clone();
        let before = self.ws.lu.factorisations;
        let out = newton::solve(
            &self.model,
            &self.system,
            &mut x,
            &mut self.ws,
            &self.settings.newton,
        );
        self.stats.factorisations += self.ws.lu.factorisations - before;
        self.stats.time += t0.elapsed();
        match out {
            Ok(rep) => {
                self.stats.iterations += rep.iterations;
                self.x = x;
                self.eps = eps;
                self.last = rep;
                self.tangent = None;
                Ok(())
            }
            Err(cause) => {
                self.system.set_height(self.height_at(self.eps));
                Err(SolveError {
                    reached: self.eps,
                    target: eps,
                    step: 0.0,
                    cause,
                })
            }
        }
    }

    /// `dx/dε` at the current state from `K t = −∂R/∂ε` (`∂g/∂ε = h0` on the tip-height
    /// rows). The factorisation at the converged state is kept for the next corrector.
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
        let mut rhs = vec![0.0; self.system.n];
        let h0 = self.model.height0();
        for row in self.system.height_rows() {
            rhs[row] = -h0;
        }
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

    /// Continues to compression ratio `target` with as many internal steps as needed.
    /// On failure the last converged state is kept and the error says where and why.
    pub fn advance_to(&mut self, target: f64) -> Result<(), SolveError> {
        let t0 = Instant::now();
        let out = self.advance_inner(target);
        self.stats.time += t0.elapsed();
        out
    }

    fn advance_inner(&mut self, target: f64) -> Result<(), SolveError> {
        let s = &self.settings;
        let (min_step, max_step, target_it) = (s.min_step, s.max_step, s.target_iterations);
        let newton_settings = s.newton;
        while (target - self.eps).abs() > 1e-14 {
            if self.tangent.is_none() {
                self.tangent = self.compute_tangent();
            }
            let dir = (target - self.eps).signum();
            let mut step = self.step.min(max_step);
            loop {
                let d = dir * step.min((target - self.eps).abs());
                let eps = self.eps + d;
                let mut x = self.x.clone();
                if let Some(t) = &self.tangent {
                    for (xi, ti) in x.iter_mut().zip(t) {
                        *xi += ti * d;
                    }
                }
                self.system.set_height(self.height_at(eps));
                let before = self.ws.lu.factorisations;
                let out = newton::solve(
                    &self.model,
                    &self.system,
                    &mut x,
                    &mut self.ws,
                    &newton_settings,
                );
                self.stats.factorisations += self.ws.lu.factorisations - before;
                match out {
                    Ok(rep) => {
                        self.stats.steps += 1;
                        self.stats.iterations += rep.iterations;
                        self.x = x;
                        self.eps = eps;
                        self.last = rep;
                        self.tangent = None;
                        // adapt the step length to the Newton effort
                        if rep.iterations + 1 < target_it {
                            step = (step * 1.5).min(max_step);
                        } else if rep.iterations > target_it + 2 {
                            step *= 0.6;
                        }
                        self.step = step.max(min_step);
                        break;
                    }
                    Err(cause) => {
                        self.stats.rejected += 1;
                        self.system.set_height(self.height_at(self.eps));
                        self.ws.fresh = false;
                        if step <= min_step * 1.000001 {
                            self.step = min_step;
                            return Err(SolveError {
                                reached: self.eps,
                                target,
                                step,
                                cause,
                            });
                        }
                        step = (step * 0.5).max(min_step);
                    }
                }
            }
        }
        Ok(())
    }

    /// Changes the boundary conditions and re-solves at the current `ε` from the current
    /// state; what the new conditions hold is held where it is now. On failure the old
    /// conditions and state are kept.
    pub fn set_boundary_conditions(&mut self, bc: BoundaryConditions) -> Result<(), SolveError> {
        let h = self.height_at(self.eps);
        let system = System::new(&self.model, bc, &self.x[..self.model.n_primal], h);
        // inextensibility and unit-norm multipliers keep their rows; support and joint
        // multipliers enter the KKT matrix linearly and restart from zero
        let keep = system.linear_row(0).min(self.x.len());
        let mut x = self.x[..keep].to_vec();
        x.resize(system.n, 0.0);
        let old_system = std::mem::replace(&mut self.system, system);
        let old_ws = std::mem::replace(&mut self.ws, Workspace::new(&self.system));
        let old_x = std::mem::replace(&mut self.x, x);
        let eps = self.eps;
        match self.correct_in_place(eps) {
            Ok(()) => Ok(()),
            Err(e) => {
                self.system = old_system;
                self.ws = old_ws;
                self.x = old_x;
                Err(e)
            }
        }
    }

    /// Reactions, load and energy at the current state.
    pub fn load_point(&self, step: usize) -> LoadPoint {
        let reactions = results::reactions(&self.model, &self.system, &self.x);
        let load = results::normalised_load(&self.model, &reactions);
        LoadPoint {
            step,
            eps: self.eps,
            height: self.height_at(self.eps),
            reactions,
            load,
            energy: self.last.energy,
            iterations: self.last.iterations,
            residual: self.last.residual,
        }
    }

    /// Shapes and curvatures at the current state.
    pub fn snapshot(&self) -> Snapshot {
        results::snapshot(&self.model, &self.system, &self.x, self.eps)
    }
}
