//! A discrete assembly moved along its load path: the continuation engine of
//! [`crate::solver`] on the loaded assembly ([`problem::LoadedAssembly`]), reporting what
//! it finds in the terms of [`crate::results`] — reactions, loads, shapes, stability and
//! critical points of the whole assembly, whichever reduction of it is solved
//! ([`reduction`]).

pub mod beam;
pub mod blocks;
pub mod cell;
pub mod curve;
pub mod flaw;
mod imperfection;
pub mod judge;
pub mod normal_form;
pub mod problem;
pub mod reduction;
mod switch;

use crate::case::Case;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::fields;
use crate::discretisation::system::System;
use crate::model::boundary::BoundaryConditions;
use crate::model::helix::Helix;
use crate::model::loading::{
    pressure_unit, AxisLoad, Component, Control, Driven, LoadParameter, Loads, SupportAxis,
};
use crate::results::{CriticalPoint, LoadPoint, ModeShape, Snapshot, Stability};
use crate::solver::continuation::Critical;
use crate::solver::continuation::{ContinuationError, ContinuationSettings, Observer, StopReason};
use crate::solver::interrupt::Interrupt;
use crate::solver::newton::NewtonReport;
use crate::solver::problem::Problem;
use crate::solver::stability::InertiaError;
use crate::solver::stats::Statistics;
use judge::all_cores;
use problem::{mean_tip_height, pcrit, LoadedAssembly};
use reduction::{CriticalModes, Reduction};

/// The continuation of a loaded assembly.
type Continuation = crate::solver::continuation::Continuation<LoadedAssembly>;

/// Passes of re-centring the sliding joints' windows after a solve (each moves a window by
/// up to its half-width).
const MAX_RECENTRING: usize = 20;

/// The continuation could not reach its target; the last converged state is kept.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error(
    "continuation stopped at eps = {compression_ratio:.6} ({} parameter {reached:.6}, target {target:.6}): {reason}",
    .control.name()
)]
pub struct SolveError {
    pub control: Control,
    /// Last converged load parameter.
    pub reached: f64,
    /// Compression ratio of the last converged state.
    pub compression_ratio: f64,
    pub target: f64,
    /// The last step tried.
    pub step: f64,
    pub reason: StopReason,
}

/// A discrete model under boundary conditions, at a converged state, that can be moved
/// along its load path.
pub struct Simulation {
    path: Continuation,
    /// The engine's critical points, reported with the loads and compression there.
    critical: Vec<CriticalPoint>,
    /// The reduced model and its system, once the path has left it for the whole assembly
    /// (its critical points' states are the reduced model's).
    reduced: Option<Box<(DiscreteModel, System)>>,
    /// Threads of the block work of every problem solved (at least one).
    threads: usize,
    /// The flaw of the natural state, for an imperfect case.
    flaw: Option<flaw::Flaw>,
}

impl Simulation {
    /// The case's simulation at its natural state (`ε = 0`, solved), under the case's
    /// boundary conditions, control and solver settings.
    pub fn from_case(case: &Case) -> Result<Simulation, SolveError> {
        Simulation::from_case_with(case, None, None)
    }

    /// As [`Simulation::from_case`], with the block work (a cyclic pair's Bloch blocks)
    /// shared out on `threads` threads (at least one; all the cores by default) from the
    /// natural state's solve on: one where other work runs in parallel (tests).
    pub fn from_case_on(case: &Case, threads: usize) -> Result<Simulation, SolveError> {
        let start = Start {
            threads,
            ..Start::plain(case.solver)
        };
        Simulation::start_case(case, start)
    }

    /// As [`Simulation::from_case`], with `interrupt` in force from the natural state's
    /// solve on (so that a long one can be cancelled, or stop at a deadline) and `observer`
    /// told of every accepted internal step from then on.
    pub fn from_case_with(
        case: &Case,
        interrupt: Option<Interrupt>,
        observer: Option<Observer>,
    ) -> Result<Simulation, SolveError> {
        let start = Start {
            interrupt,
            observer,
            ..Start::plain(case.solver)
        };
        Simulation::start_case(case, start)
    }

    /// The case's simulation at its natural state, solved.
    /// An imperfect case's model is flawed along its imperfection's shape (the perfect
    /// path is followed first, to the critical point whose mode it is).
    fn start_case(case: &Case, start: Start) -> Result<Simulation, SolveError> {
        let (model, flaw) = match case.imperfection {
            None => (case.model(), None),
            Some(imp) => {
                let (model, flaw) =
                    Simulation::flawed_model(case, imp, &start.interrupt, start.threads)?;
                (model, Some(flaw))
            }
        };
        let x0 = model.natural_state();
        let mut sim = Simulation::start(model, case.boundary, case.loads(), x0, start)?;
        sim.flaw = flaw;
        Ok(sim)
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
        x: Vec<f64>,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        Simulation::start(model, bc, Loads::axial(control), x, Start::plain(settings))
    }

    /// Starts from the primal state `x` under `loads` and solves it, as
    /// [`Simulation::from_state`] does under an axial control.
    pub fn with_loads(
        model: DiscreteModel,
        bc: BoundaryConditions,
        loads: Loads,
        x: Vec<f64>,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        Simulation::start(model, bc, loads, x, Start::plain(settings))
    }

    fn start(
        model: DiscreteModel,
        bc: BoundaryConditions,
        loads: Loads,
        mut x: Vec<f64>,
        start: Start,
    ) -> Result<Simulation, SolveError> {
        let Start {
            settings,
            interrupt,
            observer,
            threads,
        } = start;
        x.truncate(model.n_primal);
        if bc.joints.slides() && model.assembly.cell.as_ref().is_some_and(|c| c.bending) {
            return Err(SolveError {
                control: loads.control(),
                reached: 0.0,
                compression_ratio: 0.0,
                target: 0.0,
                step: 0.0,
                reason: StopReason::SlidingInBendingCell,
            });
        }
        // the contacts of sliding joints are unknowns of the model
        let (model, x) = if model.slides.is_empty() == bc.joints.slides() {
            let sliding = model.clone().with_sliding_joints(bc.joints.slides());
            let y = model.carry_state(&x, &sliding);
            (sliding, y)
        } else {
            (model, x)
        };
        let settings = settings.in_units(parameter_unit(&model, &loads));
        let (model, x) = match loads.preload() {
            Some(preload) => preloaded(model, bc, &preload, x, &settings, &interrupt, threads)?,
            None => (model, x),
        };
        let eps = 1.0 - mean_tip_height(&model, &x) / model.height0();
        let lambda = parameter_of_state(&loads, eps);
        let control = loads.control();
        let system = System::new(&model, bc, &x, &loads, lambda);
        let problem = LoadedAssembly::new(model, system).with_threads(threads);
        let path = Continuation::new_with(problem, x, lambda, settings, interrupt, observer)
            .map_err(|e| solve_error(e, control, eps))?;
        let mut sim = Simulation {
            path,
            critical: Vec::new(),
            reduced: None,
            threads,
            flaw: None,
        };
        // contacts that a start far from their crossings moves past their windows
        sim.recentre_slides()
            .map_err(|e| solve_error(e, control, eps))?;
        Ok(sim)
    }

    /// The perfect-helix equilibria of docs/theory.md §6 (Love): every rod held at both ends
    /// (clamped, no joints) on the helix of the given radius and pitch parameter (m) with
    /// its own arc length, chirality and base angle, and solved there.
    pub fn held_on_helices(
        model: DiscreteModel,
        radius: f64,
        pitch: f64,
        settings: ContinuationSettings,
    ) -> Result<Simulation, SolveError> {
        let targets: Vec<Helix> = model
            .rods
            .iter()
            .map(|r| Helix {
                radius,
                pitch,
                ..r.helix
            })
            .collect();
        let x = model.helix_state(&targets);
        let bc = BoundaryConditions {
            joints: crate::model::boundary::Joints::None,
            ..Default::default()
        };
        Simulation::from_state(model, bc, Control::Displacement, x, settings)
    }

    /// Solves from now on stop (keeping the last converged state) when `interrupt` is
    /// raised or its deadline passes.
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.path.set_interrupt(interrupt);
    }

    /// `observer` is told of every accepted internal step from now on (its load parameter
    /// is `ε` under displacement control).
    pub fn set_observer(&mut self, observer: Option<Observer>) {
        self.path.set_observer(observer);
    }

    /// Sets the length of the next internal step (see
    /// [`Continuation::set_step_length`]).
    pub fn set_step_length(&mut self, step: f64) {
        self.path.set_step_length(step);
    }

    /// Shares the block work (a cyclic pair's Bloch blocks) out on `threads` threads (at
    /// least one) from now on.
    pub fn set_threads(&mut self, threads: usize) {
        self.threads = threads.max(1);
        self.path.problem_mut().set_threads(self.threads);
    }

    /// Whether the model solved is reduced, standing for the whole assembly (false for the
    /// full model, and after a switch has moved a reduced model's path onto it).
    pub fn solves_pair(&self) -> bool {
        self.reduction().is_reduced()
    }

    /// How the model solved stands for the whole assembly.
    pub fn reduction(&self) -> &dyn Reduction {
        self.rods().reduction()
    }

    fn rods(&self) -> &LoadedAssembly {
        self.path.problem()
    }

    /// The discrete model solved (a reduction of the whole assembly, or all of it).
    pub fn model(&self) -> &DiscreteModel {
        &self.rods().model
    }

    /// Euler load of a clamped–clamped rod, `Pcrit = B1 (2π/L)²` (N): the unit of `λ`
    /// under load control.
    pub fn pcrit(&self) -> f64 {
        pcrit(self.model())
    }

    pub fn control(&self) -> Control {
        self.loads().control()
    }

    /// What is applied to the assembly, as functions of the load parameter.
    pub fn loads(&self) -> &Loads {
        self.system().loads()
    }

    /// What the load parameter `λ` is (its symbol, unit and label for the faces).
    pub fn load_parameter(&self) -> LoadParameter {
        self.loads().parameter()
    }

    /// Current load parameter `λ`.
    pub fn parameter(&self) -> f64 {
        self.path.state().lambda
    }

    /// Compression ratio of the current state, from the mean tip height.
    pub fn compression_ratio(&self) -> f64 {
        eps_of(self.model(), &self.path.state().x)
    }

    /// Tip height `h = h0 (1 − ε)` (m) at compression ratio `eps`.
    pub fn height_at(&self, eps: f64) -> f64 {
        self.model().height0() * (1.0 - eps)
    }

    pub fn boundary_conditions(&self) -> BoundaryConditions {
        self.rods().system.bc
    }

    pub fn system(&self) -> &System {
        &self.rods().system
    }

    /// The converged state vector.
    pub fn state(&self) -> &[f64] {
        &self.path.state().x
    }

    /// The current internal step length.
    pub fn step_length(&self) -> f64 {
        self.path.state().step
    }

    /// Whether steps are pseudo-arclength ones.
    pub fn is_arclength(&self) -> bool {
        self.path.state().arclength
    }

    /// Newton report of the solve that produced the current state.
    pub fn last_solve(&self) -> NewtonReport {
        self.path.state().solve
    }

    /// Stability of the current state, when tracked and computable.
    pub fn stability(&self) -> Option<Stability> {
        self.path.state().stability
    }

    /// Critical points located so far.
    pub fn critical_points(&self) -> &[CriticalPoint] {
        &self.critical
    }

    /// Counters of the work done so far.
    pub fn statistics(&self) -> Statistics {
        self.path.statistics()
    }

    /// The continuation settings in force.
    pub fn settings(&self) -> &ContinuationSettings {
        self.path.settings()
    }

    fn error(&self, e: ContinuationError) -> SolveError {
        solve_error(e, self.control(), self.compression_ratio())
    }

    /// Reports the critical points the engine found since the last call, with the load
    /// and compression at each.
    fn record_critical(&mut self) {
        let found: Vec<Critical> = self.path.critical_points()[self.critical.len()..].to_vec();
        for c in found {
            let control = self.control();
            let rods = self.path.problem_mut();
            rods.restore(&c.state, c.parameter);
            let reactions = fields::reactions(&rods.model, &rods.system, &c.state);
            let load = fields::normalised_load(&rods.model, &reactions);
            let eps = eps_of(&rods.model, &c.state);
            let CriticalModes {
                wavenumber,
                bloch_phase,
                multiplicity,
                assembly_mode,
                second_mode,
            } = rods.critical_modes(&c);
            self.critical.push(CriticalPoint {
                kind: c.kind,
                control,
                parameter: c.parameter,
                compression_ratio: eps,
                load,
                unstable_before: c.unstable_before,
                unstable_after: c.unstable_after,
                wavenumber,
                bloch_phase,
                multiplicity,
                state: c.state,
                mode: c.mode,
                assembly_mode,
                second_mode,
            });
        }
        let (x, lambda) = (self.path.state().x.clone(), self.path.state().lambda);
        self.path.problem_mut().restore(&x, lambda);
    }

    /// Forgets the critical points after the first `len`: those located past a switch
    /// point on the path it left (a run that switches at its first bifurcation lists only
    /// the points of the path it followed).
    pub fn keep_critical_points(&mut self, len: usize) {
        self.critical.truncate(len);
        self.path.keep_critical_points(len);
    }

    /// Continues to load parameter `target` with as many internal steps as needed.
    /// On failure the last converged state is kept and the error says where and why.
    /// A path whose parameter prescribes the axial motion of the tip ends at the first
    /// limit point it meets: past it the path would carry the tip back, beyond where it
    /// started.
    pub fn advance_to(&mut self, target: f64) -> Result<(), SolveError> {
        let prescribed = prescribes_axial_motion(self.loads());
        self.path.set_stop_at_folds(prescribed);
        // a flawed path bends sharply near the perfect bifurcation: followed by arclength
        self.path
            .set_arclength(self.flaw.is_some() || self.path.state().arclength);
        let mut outcome = self.path.advance_to(target);
        if outcome.is_ok() {
            outcome = self.recentre_slides();
        }
        self.record_critical();
        outcome.map_err(|e| self.error(e))
    }

    /// Re-centres the pattern's windows of the sliding joints whose contacts have come near
    /// their edges, and re-solves the state there (the same unknowns: the branch goes on).
    fn recentre_slides(&mut self) -> Result<(), ContinuationError> {
        // each pass moves a window by up to its half-width: a contact far from its
        // window's element comes home in a few
        for _ in 0..MAX_RECENTRING {
            let (model, system) = (self.model(), self.system());
            let x = &self.path.state().x;
            if !system.slides_stale(model, x) {
                break;
            }
            let system = system.recentred(model, x);
            let problem = LoadedAssembly::new(model.clone(), system).with_threads(self.threads);
            self.path.reshape(problem)?;
        }
        Ok(())
    }

    /// Number of unstable directions of the current state: negative eigenvalues of the
    /// Hessian of the Lagrangian on the tangent space of the constraints (of the full
    /// model for a symmetric pair).
    pub fn unstable_directions(&mut self) -> Result<usize, InertiaError> {
        let (x, lambda) = (self.path.state().x.clone(), self.path.state().lambda);
        self.path.problem_mut().unstable_directions(&x, lambda)
    }

    /// Changes the boundary conditions and re-solves at the current load from the current
    /// state; what the new conditions hold is held where it is now. On failure the old
    /// conditions and state are kept.
    pub fn set_boundary_conditions(&mut self, bc: BoundaryConditions) -> Result<(), SolveError> {
        let loads = self.loads().clone();
        self.rebuild(bc, loads)
    }

    /// Changes the control (displacement or load) of the axial load parameter at the
    /// current state: the load parameter becomes the current `ε`, or the current mean
    /// compressive tip force over `Pcrit` (a path driven otherwise keeps its loads).
    pub fn set_control(&mut self, control: Control) -> Result<(), SolveError> {
        let bc = self.boundary_conditions();
        let loads = self.loads().with_axial_control(control);
        self.rebuild(bc, loads)
    }

    fn rebuild(&mut self, bc: BoundaryConditions, loads: Loads) -> Result<(), SolveError> {
        let control = loads.control();
        let lambda = match (loads.parameter().driven, control) {
            (Driven::Tip(SupportAxis::Z), Control::Displacement) => self.compression_ratio(),
            (Driven::Tip(SupportAxis::Z), Control::Force) => -self.load_point(0).load[2],
            _ => self.parameter(),
        };
        let old = self.model();
        if bc.joints.slides() && old.assembly.cell.as_ref().is_some_and(|c| c.bending) {
            let state = self.path.state();
            return Err(SolveError {
                control,
                reached: state.lambda,
                compression_ratio: self.compression_ratio(),
                target: state.lambda,
                step: 0.0,
                reason: StopReason::SlidingInBendingCell,
            });
        }
        let model = old.clone().with_sliding_joints(bc.joints.slides());
        let carried;
        let x = if model.n_primal == old.n_primal {
            self.state()
        } else {
            // joints that start or stop sliding: the contacts' arc lengths come or go, the
            // multipliers restart from zero
            carried = old.carry_state(self.state(), &model);
            &carried[..]
        };
        let mut system = System::new(&model, bc, &x[..model.n_primal], &loads, lambda);
        // a branch held by a phase condition stays held: every support condition and axial
        // control keeps the symmetry the condition stands on (the rotation about the axis
        // of a straight isotropic rod, the tube's mirror)
        if let Some(phase) = self.system().phase() {
            system = system.with_phase(&model, x, phase.clone());
        }
        // inextensibility and unit-norm multipliers keep their rows; support and joint
        // multipliers enter the KKT matrix linearly and restart from zero
        let keep = system.linear_row(0).min(x.len());
        let x = x[..keep].to_vec();
        let eps = self.compression_ratio();
        // a path that cannot start from its rest as it stands: a branch held by a phase
        // condition, the whole assembly the path has switched onto, a flawed or preloaded
        // start
        let from_rest = self.system().phase().is_none()
            && self.reduced.is_none()
            && self.flaw.is_none()
            && loads.preload().is_none();
        let problem = LoadedAssembly::new(model.clone(), system).with_threads(self.threads);
        match self.path.restart_with(problem, x, lambda) {
            Ok(()) => Ok(()),
            Err(e) if matches!(e.reason, StopReason::Interrupted(_)) || !from_rest => {
                Err(solve_error(e, control, eps))
            }
            Err(_) => self.retrace(model, bc, &loads, lambda),
        }
    }

    /// Follows the path of `model` under `bc` and `loads` from its rest to the load
    /// parameter `lambda`, in place of the path so far: the state of the new conditions'
    /// own path, where the old state is too far from their equilibrium for Newton's method
    /// to correct it in place (welded crossings loosened to springs at large compression).
    /// Taken in steps of the largest internal step, the sliding contacts' windows
    /// re-centred between; if it falls short, the old path is kept and the error says
    /// where the new one stopped (`reached`) and why.
    fn retrace(
        &mut self,
        model: DiscreteModel,
        bc: BoundaryConditions,
        loads: &Loads,
        lambda: f64,
    ) -> Result<(), SolveError> {
        let control = loads.control();
        let eps = self.compression_ratio();
        let plain = model.clone().with_sliding_joints(false);
        let rest = plain.carry_state(&plain.natural_state(), &model);
        let start = parameter_of_state(
            loads,
            1.0 - mean_tip_height(&model, &rest) / model.height0(),
        );
        let system = System::new(&model, bc, &rest, loads, start);
        let problem = LoadedAssembly::new(model, system).with_threads(self.threads);
        let known = self.critical.len();
        let aside = self
            .path
            .start_over_with(problem, rest, start)
            .map_err(|e| solve_error(e, control, eps))?;
        let mut outcome = self
            .recentre_slides()
            .map_err(|e| solve_error(e, control, eps));
        let steps = ((lambda - start).abs() / self.path.settings().max_step)
            .ceil()
            .max(1.0);
        for k in 1..=steps as usize {
            if outcome.is_err() {
                break;
            }
            outcome = self.advance_to(start + (lambda - start) * k as f64 / steps);
        }
        outcome
            .inspect_err(|_| {
                self.path.put_back(aside);
                self.critical.truncate(known);
            })
            .map_err(|e| SolveError {
                compression_ratio: eps,
                target: lambda,
                ..e
            })
    }

    /// Number of rods of the whole assembly each modelled rod stands for.
    fn images(&self) -> f64 {
        self.reduction().images(self.model())
    }

    /// Reactions, load, energy and stability at the current state.
    pub fn load_point(&self, step: usize) -> LoadPoint {
        let (model, system) = (self.model(), self.system());
        let state = self.path.state();
        let reactions = fields::reactions(model, system, &state.x);
        let load = fields::normalised_load(model, &reactions);
        let eps = self.compression_ratio();
        let height = self.height_at(eps);
        let support = fields::support_response(model, system, &state.x, &reactions, height);
        LoadPoint {
            step,
            compression_ratio: eps,
            parameter: state.lambda,
            height,
            support,
            reactions,
            load,
            energy: state.solve.energy * self.images(),
            iterations: state.solve.iterations,
            residual: state.solve.residual,
            stability: state.stability,
        }
    }

    /// Shapes and curvatures at the current state.
    pub fn snapshot(&self) -> Snapshot {
        fields::snapshot(
            self.model(),
            self.system(),
            self.state(),
            self.compression_ratio(),
        )
    }

    /// For a critical point of a reduced model whose mode was rebuilt on the whole
    /// assembly: the full model, its system and the critical state expanded onto it.
    fn on_whole_assembly(
        &self,
        critical: &CriticalPoint,
    ) -> Option<(DiscreteModel, System, Vec<f64>)> {
        critical.assembly_mode.as_ref()?;
        let (reduced, system) = match &self.reduced {
            Some(p) => (&p.0, &p.1),
            None => (self.model(), self.system()),
        };
        if critical.state.len() != system.n {
            return None;
        }
        let reduction = reduction::of(reduced);
        let full = reduction.whole(reduced)?;
        let full_system = System::new(
            &full,
            system.bc,
            &full.natural_state(),
            &Loads::axial(Control::Displacement),
            0.0,
        );
        let mut x = vec![0.0; full_system.n];
        reduction.expand_state(
            reduced,
            system,
            &critical.state,
            &full,
            &full_system,
            &mut x,
        );
        Some((full, full_system, x))
    }

    /// A critical mode on the geometry of its state (for a reduced model, on the whole
    /// assembly, where its mode was rebuilt): for ParaView series.
    pub fn mode_shape(&self, critical: &CriticalPoint) -> ModeShape {
        match (self.on_whole_assembly(critical), &critical.assembly_mode) {
            (Some((full, system, x)), Some(mode)) => {
                fields::mode_shape(&full, &system, &x, critical.compression_ratio, mode)
            }
            _ if critical.state.len() == self.system().n => fields::mode_shape(
                self.model(),
                self.system(),
                &critical.state,
                critical.compression_ratio,
                &critical.mode,
            ),
            // a critical point of the reduced model, which the path has left: drawn on it
            _ => match &self.reduced {
                Some(p) => fields::mode_shape(
                    &p.0,
                    &p.1,
                    &critical.state,
                    critical.compression_ratio,
                    &critical.mode,
                ),
                None => fields::mode_shape(
                    self.model(),
                    self.system(),
                    &critical.state,
                    critical.compression_ratio,
                    &critical.mode,
                ),
            },
        }
    }

    /// Shape of a critical mode: the state displaced by `amplitude` times the mode (for a
    /// reduced model, the whole assembly displaced by the mode rebuilt on it).
    pub fn mode_snapshot(&self, critical: &CriticalPoint, amplitude: f64) -> Snapshot {
        if let (Some((full, system, mut x)), Some(mode)) =
            (self.on_whole_assembly(critical), &critical.assembly_mode)
        {
            for (xi, mi) in x.iter_mut().zip(mode) {
                *xi += amplitude * mi;
            }
            return fields::snapshot(&full, &system, &x, critical.compression_ratio);
        }
        let x: Vec<f64> = critical
            .state
            .iter()
            .zip(&critical.mode)
            .map(|(a, m)| a + amplitude * m)
            .collect();
        match &self.reduced {
            // a critical point of the reduced model, which the path has left
            Some(p) if x.len() != self.system().n => {
                fields::snapshot(&p.0, &p.1, &x, critical.compression_ratio)
            }
            _ => fields::snapshot(self.model(), self.system(), &x, critical.compression_ratio),
        }
    }
}

/// Compression ratio `ε = 1 − h/h0` of state `x`, from the mean tip height.
fn eps_of(model: &DiscreteModel, x: &[f64]) -> f64 {
    1.0 - mean_tip_height(model, x) / model.height0()
}

/// How a simulation starts: its continuation settings, what may stop it and be told of its
/// steps, and the threads of its block work.
struct Start {
    settings: ContinuationSettings,
    interrupt: Option<Interrupt>,
    observer: Option<Observer>,
    threads: usize,
}

impl Start {
    /// Under `settings`, without interrupt or observer, the block work on all the cores.
    fn plain(settings: ContinuationSettings) -> Start {
        Start {
            settings,
            interrupt: None,
            observer: None,
            threads: all_cores(),
        }
    }
}

/// The natural scale of the load parameter of `loads` on `model`, in its own measure: the
/// continuation's step lengths are given per unit of it. 1 for the compression ratio, the
/// axial load over `Pcrit` and the angles (rad); for the radial pressure `B1 a/c⁴` (N/m),
/// the line pressure that changes the rods' curvature `a/c²` by its own size.
pub fn parameter_unit(model: &DiscreteModel, loads: &Loads) -> f64 {
    match loads.stepped() {
        Some(Component::Pressure) => {
            let helix = &model.rods[0].helix;
            pressure_unit(model.stiffness.b1, helix.radius, helix.pitch)
        }
        _ => 1.0,
    }
}

/// The state `x` (at the natural pose of the supports, unloaded) brought to where the held
/// loads hold it, by a path of `preload` from 0 to 1 (`Driven::Held`): its model and primal
/// state. A failure is reported in the terms of that path.
fn preloaded(
    model: DiscreteModel,
    bc: BoundaryConditions,
    preload: &Loads,
    x: Vec<f64>,
    settings: &ContinuationSettings,
    interrupt: &Option<Interrupt>,
    threads: usize,
) -> Result<(DiscreteModel, Vec<f64>), SolveError> {
    let eps = 1.0 - mean_tip_height(&model, &x) / model.height0();
    let control = preload.control();
    let system = System::new(&model, bc, &x, preload, 0.0);
    let problem = LoadedAssembly::new(model, system).with_threads(threads);
    let mut path = Continuation::new_with(problem, x, 0.0, *settings, interrupt.clone(), None)
        .map_err(|e| solve_error(e, control, eps))?;
    path.advance_to(1.0).map_err(|e| {
        let eps = eps_of(&path.problem().model, &path.state().x);
        solve_error(e, control, eps)
    })?;
    let model = path.problem().model.clone();
    let x = path.state().x[..model.n_primal].to_vec();
    Ok((model, x))
}

/// The load parameter at which a state of compression ratio `eps` starts a path under
/// `loads`: `ε` itself when the parameter prescribes the axial motion (the supports then
/// hold the tips where the state has them), zero otherwise.
fn parameter_of_state(loads: &Loads, eps: f64) -> f64 {
    if !prescribes_axial_motion(loads) {
        return 0.0;
    }
    match loads.tip().axis(SupportAxis::Z) {
        AxisLoad::Motion(r) => (eps - r.at_zero) / r.per_unit,
        AxisLoad::Force(_) => 0.0,
    }
}

/// Whether the load parameter of `loads` prescribes the axial motion of the tip (`ε`).
fn prescribes_axial_motion(loads: &Loads) -> bool {
    matches!(
        (loads.parameter().driven, loads.tip().axis(SupportAxis::Z)),
        (Driven::Tip(SupportAxis::Z), AxisLoad::Motion(_))
    )
}

fn solve_error(e: ContinuationError, control: Control, eps: f64) -> SolveError {
    SolveError {
        control,
        reached: e.reached,
        compression_ratio: eps,
        target: e.target,
        step: e.step,
        reason: e.reason,
    }
}

impl Simulation {
    /// The dispersion of the current state of a cell on `phases` axial phases in `[0, π]`
    /// (`None` for a model that is not a cell).
    pub fn dispersion(&self, phases: usize) -> Option<cell::Dispersion> {
        let mut judge = cell::CellJudge::new(self.model(), self.system(), phases)?;
        Some(judge.dispersion(self.model(), self.system(), self.state()))
    }
}
