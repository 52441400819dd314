//! Continuation of the solutions of `R(x, λ) = 0` in the load parameter `λ` (docs/theory.md §5):
//! tangent predictor, modified-Newton corrector, adaptive step length with cut-backs,
//! pseudo-arclength steps where natural ones fail (folds), the stability of every converged
//! state, critical points where the count of unstable directions changes
//! ([`super::critical`]), and branch switching at bifurcations ([`super::switching`]).
//!
//! The engine knows nothing of rods: it follows any [`Problem`].

use super::interrupt::{Interrupt, Interruption};
use super::newton::{Newton, NewtonError, NewtonReport, NewtonSettings, StepEquation};
use super::path_state::PathState;
use super::problem::Problem;
use super::stats::Statistics;
use crate::results::{CriticalKind, Stability};
use std::time::Instant;

/// Step-length control of the continuation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuationSettings {
    /// First internal step in `λ`.
    pub initial_step: f64,
    /// Smallest step before giving up (or changing strategy).
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Newton iterations aimed at: fewer grow the step, more shrink it.
    pub target_iterations: usize,
    /// Switch to pseudo-arclength steps when natural ones fail at the smallest step.
    pub arclength_fallback: bool,
    /// Count unstable directions at every converged step and locate critical points.
    pub track_stability: bool,
    /// Also compute the lowest eigenvalue at every output point (inverse iteration: the
    /// costliest part of the stability analysis).
    pub lowest_eigenvalue: bool,
    /// Critical points are located to this relative tolerance in the step.
    pub critical_tolerance: f64,
    pub newton: NewtonSettings,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings {
            initial_step: 0.01,
            min_step: 1e-6,
            max_step: 0.05,
            target_iterations: 6,
            arclength_fallback: true,
            track_stability: true,
            lowest_eigenvalue: true,
            critical_tolerance: 1e-9,
            newton: NewtonSettings::default(),
        }
    }
}

impl ContinuationSettings {
    /// The same settings for a load parameter whose natural scale is `unit` (in its own
    /// measure): the step lengths, given per unit of that scale, multiplied by it.
    pub fn in_units(self, unit: f64) -> ContinuationSettings {
        ContinuationSettings {
            initial_step: self.initial_step * unit,
            min_step: self.min_step * unit,
            max_step: self.max_step * unit,
            ..self
        }
    }
}

/// Why a continuation stopped.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StopReason {
    #[error("a step of {step:.2e} failed: {cause}")]
    Newton { step: f64, cause: NewtonError },
    #[error("the path turned back (a limit point) and does not reach the target within {steps} arclength steps")]
    TurnedBack { steps: usize },
    /// A path that must not turn back in its parameter (the axial motion prescribed) met a
    /// limit point: it ends there (see [`Continuation::set_stop_at_folds`]).
    #[error("the path meets a limit point (fold) at parameter {parameter:.6} and turns back there, short of the target: a path of prescribed motion ends at its fold")]
    Fold { parameter: f64 },
    #[error("the next step leaves the physical domain ({why})")]
    LeftDomain { why: &'static str },
    #[error("switching branch needs the full model: a symmetric pair cannot follow a mode that breaks the symmetry")]
    SymmetricPair,
    /// Sliding joints asked of a bending cell (all the rods over an axial period, tilted),
    /// whose gauge holds only the straight cell's neutral motions of sliding crossings.
    #[error("sliding joints are carried by the straight cell of the infinite tube, not by its bending cell (a tilt): start over without the tilt, or with discretisation.model = \"full\"")]
    SlidingInBendingCell,
    #[error("there is no critical point {index} to switch branch at")]
    NoCriticalPoint { index: usize },
    /// The critical point's state is of another problem than the path's now (a symmetric
    /// pair the path has left for the full model).
    #[error("critical point {index} is of the symmetric pair, which the path has left for the whole assembly: start over to switch there")]
    LeftProblem { index: usize },
    /// A path asked to switch branch at its first bifurcation met none on the way.
    #[error("the case asks to switch branch at the first bifurcation (loading.branch), but the path met none on its way to the target")]
    NoBifurcation,
    /// A flaw along the mode of critical point `index` of the perfect path, which located
    /// only `found` on its way to the target.
    #[error("the imperfection follows the mode of critical point {index} of the perfect path, but that path locates {found} critical point(s) on its way to the target (imperfection.mode counts from 0)")]
    NoImperfectionMode { index: usize, found: usize },
    /// A flaw along a mode that moves no point of the centreline (a pure twist).
    #[error("the mode of critical point {index} moves no point of the centreline: it cannot be scaled to an amplitude in rod lengths")]
    FlatImperfectionMode { index: usize },
    #[error("the solve was interrupted: {0}")]
    Interrupted(Interruption),
    /// The count of unstable directions changed more often than a path has critical
    /// points: a neutral mode flipping it (see [`MAX_CRITICAL_POINTS`]).
    #[error("the count of unstable directions changed at more than {max} points: a neutral mode (a zero-energy motion the supports leave free, or a buckled isotropic rod turning about its axis) flips it at every step")]
    TooManyCritical { max: usize },
}

/// Critical points located on one path before it stops (bounds the critical-point search).
pub const MAX_CRITICAL_POINTS: usize = 16;

/// A count of unstable directions that changes across a step while the eigenvalue nearest
/// zero stays below this fraction of [`Problem::eigenvalue_scale`] at both its ends is a
/// neutral direction flipping the count by rounding, not a crossing: a real crossing in a
/// step moves the eigenvalue by its slope times the step (for Euler's column, about
/// `Pcrit Δλ`, 1e-2 to 1 of the scale), a neutral one stays at rounding level. Tested on
/// the buckled pinned column (one neutral entry) and on the thesis paths (their
/// bifurcations unchanged).
pub const NEUTRAL_FRACTION: f64 = 1e-6;

/// The continuation could not go on; the last converged state is kept.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("continuation stopped at parameter {reached:.6} (target {target:.6}): {reason}")]
pub struct ContinuationError {
    /// Last converged load parameter.
    pub reached: f64,
    pub target: f64,
    /// The last step tried.
    pub step: f64,
    pub reason: StopReason,
}

/// A critical point of the path as the engine finds it.
#[derive(Clone, Debug, PartialEq)]
pub struct Critical {
    /// The block of the problem's stability whose count changed (see
    /// [`Problem::focus_on_crossing`]; 0 for a problem of one block).
    pub block: usize,
    pub kind: CriticalKind,
    /// Load parameter at the critical point.
    pub parameter: f64,
    pub unstable_before: usize,
    pub unstable_after: usize,
    /// State at the critical point (all unknowns).
    pub state: Vec<f64>,
    /// Critical mode: the near-null vector of the Jacobian there (all unknowns), scaled to
    /// unit norm over the primal unknowns.
    pub mode: Vec<f64>,
}

/// The converged state an accepted step started from, and how many critical points had
/// been located then.
pub(super) struct Before {
    pub x: Vec<f64>,
    pub lambda: f64,
    pub stability: Option<Stability>,
    pub located: usize,
}

/// Arclength steps after which a path that has turned back is given up.
const MAX_ARCLENGTH_STEPS: usize = 2000;

/// A trial step's outcome (not yet accepted).
pub(super) struct Trial {
    pub x: Vec<f64>,
    pub lambda: f64,
    pub report: NewtonReport,
    /// How far the corrector moved the primal unknowns from the predicted state, relative
    /// to the predictor's length (0 where there was no predictor).
    pub correction: f64,
}

/// A problem at a converged point of its path, that can be moved along it.
pub struct Continuation<P: Problem> {
    pub(super) problem: P,
    pub(super) state: PathState,
    pub(super) newton: Newton,
    pub(super) settings: ContinuationSettings,
    pub(super) stats: Statistics,
    pub(super) critical: Vec<Critical>,
    /// Whether a neutral direction has been recorded (once) on this path.
    neutral_found: bool,
    /// Whether the path ends at a limit point instead of following it back.
    pub(super) stop_at_folds: bool,
    /// Checked between Newton iterations and between steps.
    interrupt: Option<Interrupt>,
    /// Told of every accepted step.
    observer: Option<Observer>,
}

/// Called with every accepted state of a path (e.g. to show progress).
pub type Observer = Box<dyn FnMut(&PathState) + Send>;

impl<P: Problem> Continuation<P> {
    /// Starts at `(x, λ)` (`x` padded with zero multipliers to the problem's size) and
    /// solves there at fixed `λ`, then judges the stability of the solution.
    pub fn new(
        problem: P,
        x: Vec<f64>,
        lambda: f64,
        settings: ContinuationSettings,
    ) -> Result<Continuation<P>, ContinuationError> {
        Continuation::new_with(problem, x, lambda, settings, None, None)
    }

    /// As [`Continuation::new`], with `interrupt` checked from the first solve on (so that
    /// the solve at the start can be stopped too) and `observer` told of every accepted
    /// step from then on.
    pub fn new_with(
        problem: P,
        mut x: Vec<f64>,
        lambda: f64,
        settings: ContinuationSettings,
        interrupt: Option<Interrupt>,
        observer: Option<Observer>,
    ) -> Result<Continuation<P>, ContinuationError> {
        x.resize(problem.unknowns(), 0.0);
        let newton = Newton::new(&problem);
        let mut path = Continuation {
            problem,
            state: PathState::start(x, lambda, settings.initial_step),
            newton,
            settings,
            stats: Statistics::default(),
            critical: Vec::new(),
            neutral_found: false,
            stop_at_folds: false,
            interrupt,
            observer,
        };
        path.correct_in_place()?;
        path.update_stability(true);
        // the stability count cannot be stopped part of the way: a stop asked for while it
        // ran is honoured when it ends (the start is then not made)
        if let Some(why) = path.interrupt.as_ref().and_then(Interrupt::check) {
            return Err(path.error(lambda, 0.0, StopReason::Interrupted(why)));
        }
        Ok(path)
    }

    /// The settings from the next step on (the current step kept within their bounds).
    pub fn set_settings(&mut self, settings: ContinuationSettings) {
        self.settings = settings;
        self.state.step = self.state.step.clamp(settings.min_step, settings.max_step);
    }

    /// Solves from now on stop when `interrupt` says so.
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.interrupt = interrupt;
    }

    /// Whether the path ends at a limit point it meets (the parameter prescribes a motion
    /// that may not turn back) instead of following the returning branch: false by default.
    pub fn set_stop_at_folds(&mut self, stop: bool) {
        self.stop_at_folds = stop;
    }

    /// `observer` is told of every accepted step from now on.
    pub fn set_observer(&mut self, observer: Option<Observer>) {
        self.observer = observer;
    }

    /// Sets the length of the next internal step (within the settings' bounds), e.g. to
    /// resume a path exactly as a stopped solve left it.
    pub fn set_step_length(&mut self, step: f64) {
        if step.is_finite() && step > 0.0 {
            self.state.step = step.clamp(self.settings.min_step, self.settings.max_step);
        }
    }

    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// The problem, to evaluate things at the converged state; the engine calls
    /// [`Problem::restore`] before it evaluates anything itself.
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.problem
    }

    /// The converged state.
    pub fn state(&self) -> &PathState {
        &self.state
    }

    pub fn settings(&self) -> &ContinuationSettings {
        &self.settings
    }

    /// Counters of the work done so far.
    pub fn statistics(&self) -> Statistics {
        Statistics {
            factorisations: self.newton.factorisations(),
            ..self.stats
        }
    }

    /// Critical points located so far.
    pub fn critical_points(&self) -> &[Critical] {
        &self.critical
    }

    /// Forgets the critical points after the first `len` (those of a path left behind).
    pub fn keep_critical_points(&mut self, len: usize) {
        self.critical.truncate(len);
    }

    pub(super) fn error(&self, target: f64, step: f64, reason: StopReason) -> ContinuationError {
        ContinuationError {
            reached: self.state.lambda,
            target,
            step,
            reason,
        }
    }

    /// Runs the bordered Newton corrector from `(x, λ)` with `settings`; counts its work.
    /// The problem is restored to the converged point afterwards.
    pub(super) fn correct(
        &mut self,
        mut x: Vec<f64>,
        mut lambda: f64,
        step: &StepEquation,
        settings: &NewtonSettings,
    ) -> Result<Trial, NewtonError> {
        let t0 = Instant::now();
        let out = self.newton.solve(
            &mut self.problem,
            &mut x,
            &mut lambda,
            step,
            settings,
            self.interrupt.as_ref(),
        );
        self.stats.time += t0.elapsed();
        self.problem.restore(&self.state.x, self.state.lambda);
        out.map(|report| {
            self.stats.iterations += report.iterations;
            Trial {
                x,
                lambda,
                report,
                correction: 0.0,
            }
        })
    }

    /// Newton at fixed `λ` from the current state; keeps the old state on failure.
    pub(super) fn correct_in_place(&mut self) -> Result<(), ContinuationError> {
        let x0 = self.state.x.clone();
        let l0 = self.state.lambda;
        let step = StepEquation::natural(&x0, l0, 0.0);
        let settings = self.settings.newton;
        match self.correct(x0.clone(), l0, &step, &settings) {
            Ok(t) => {
                self.state.x = t.x;
                self.state.solve = t.report;
                self.state.tangent = None;
                self.state.previous = None;
                Ok(())
            }
            // stopped from outside: said as such, as for a step
            Err(NewtonError::Interrupted { why, .. }) => {
                self.newton.discard_factorisation();
                Err(self.error(l0, 0.0, StopReason::Interrupted(why)))
            }
            Err(cause) => Err(self.error(l0, 0.0, StopReason::Newton { step: 0.0, cause })),
        }
    }

    pub(super) fn accept(&mut self, trial: Trial) {
        let old = std::mem::replace(&mut self.state.x, trial.x);
        self.state.previous = Some((old, self.state.lambda));
        self.state.lambda = trial.lambda;
        self.problem.restore(&self.state.x, self.state.lambda);
        self.state.solve = trial.report;
        self.state.tangent = None;
        self.stats.steps += 1;
        if self.state.arclength {
            self.stats.arclength_steps += 1;
        }
    }

    /// Continues to load parameter `target` with as many internal steps as needed.
    /// On failure the last converged state is kept and the error says where and why.
    pub fn advance_to(&mut self, target: f64) -> Result<(), ContinuationError> {
        let s = self.settings;
        let mut arclength_steps = 0;
        // whether the stability of the state on the target has its lowest eigenvalue
        let mut lowest_done = false;
        // a step left the problem's domain: the edge lies within the steps tried since,
        // which are halved until they are the smallest (the path stops on the edge)
        let mut edge_within: Option<&'static str> = None;
        while (target - self.state.lambda).abs() > 1e-14 * (1.0 + target.abs()) {
            if let Some(why) = self.interrupt.as_ref().and_then(Interrupt::check) {
                // as when a Newton iteration is interrupted, so that a path stopped here
                // and one stopped inside the next step go on alike
                self.newton.discard_factorisation();
                return Err(self.error(target, 0.0, StopReason::Interrupted(why)));
            }
            let dir = (target - self.state.lambda).signum();
            let remaining = (target - self.state.lambda).abs();
            // `nominal` is the adaptive step; the last natural step is shortened to land
            // on the target without shrinking the step for what follows
            let nominal = self.state.step.min(s.max_step);
            let h = if self.state.arclength {
                nominal
            } else {
                nominal.min(remaining)
            };
            match self.try_step_on_path(h, dir) {
                Ok(t) => {
                    // an arclength step that overshoots the target: land on it exactly
                    let overshoot = self.state.arclength && (t.lambda - target) * dir > 0.0;
                    if overshoot {
                        self.state.arclength = false;
                        self.state.step = remaining.max(s.min_step);
                        self.newton.discard_factorisation();
                        continue;
                    }
                    if let Some(why) = self.problem.out_of_domain(&t.x) {
                        self.newton.discard_factorisation();
                        if h > s.min_step * 1.000001 {
                            self.stats.rejected += 1;
                            edge_within = Some(why);
                            self.state.step = (h * 0.5).max(s.min_step);
                            continue;
                        }
                        return Err(self.error(target, h, StopReason::LeftDomain { why }));
                    }
                    let iterations = t.report.iterations;
                    let located_before = self.critical.len();
                    let (x_before, l_before) = (self.state.x.clone(), self.state.lambda);
                    let (stability_before, was_arclength) =
                        (self.state.stability, self.state.arclength);
                    self.accept(t);
                    if self.state.arclength {
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
                    // on the target, one evaluation gives the count and the lowest
                    // eigenvalue (the count alone would factorise the blocks twice)
                    let on_target =
                        (target - self.state.lambda).abs() <= 1e-14 * (1.0 + target.abs());
                    lowest_done = on_target && s.track_stability && s.lowest_eigenvalue;
                    self.update_stability(lowest_done);
                    if let Some(observe) = self.observer.as_mut() {
                        observe(&self.state);
                    }
                    self.judge_crossing(stability_before, &x_before, l_before, was_arclength)
                        .map_err(|reason| self.error(target, h, reason))?;
                    let step_from = Before {
                        x: x_before,
                        lambda: l_before,
                        stability: stability_before,
                        located: located_before,
                    };
                    if let Some(reason) = self.stop_at_fold(step_from, dir) {
                        return Err(self.error(target, h, reason));
                    }
                    if edge_within.is_some() {
                        // the edge lies within a step of length h from here
                        self.state.step = h;
                    } else {
                        self.adapt_step(nominal, h, iterations);
                    }
                }
                Err(NewtonError::Interrupted { why, .. }) => {
                    self.newton.discard_factorisation();
                    return Err(self.error(target, h, StopReason::Interrupted(why)));
                }
                Err(cause) => {
                    self.stats.rejected += 1;
                    self.newton.discard_factorisation();
                    if h <= s.min_step * 1.000001 {
                        if let Some(why) = edge_within {
                            // no smaller step to close in on the edge with
                            self.state.step = s.min_step;
                            return Err(self.error(target, h, StopReason::LeftDomain { why }));
                        }
                        if !self.state.arclength && s.arclength_fallback {
                            // change strategy: pseudo-arclength from here
                            self.state.arclength = true;
                            self.state.step = s.initial_step.min(s.max_step);
                            continue;
                        }
                        self.state.step = s.min_step;
                        return Err(self.error(target, h, StopReason::Newton { step: h, cause }));
                    }
                    self.state.step = (h * 0.5).max(s.min_step);
                }
            }
        }
        self.settle_on_target(target, lowest_done);
        Ok(())
    }

    /// After an accepted step from `(x_before, λ_before)` whose state had the stability
    /// `before`: a change of the count of unstable directions is settled as a neutral
    /// direction's flip or located as a critical point. Fails when the path has more
    /// critical points than [`MAX_CRITICAL_POINTS`].
    fn judge_crossing(
        &mut self,
        before: Option<Stability>,
        x_before: &[f64],
        l_before: f64,
        was_arclength: bool,
    ) -> Result<(), StopReason> {
        if let (Some(b), Some(a)) = (before, self.state.stability) {
            if a.unstable_directions != b.unstable_directions
                && self.is_neutral_flip(x_before, l_before)
            {
                self.settle_neutral(b, a);
            } else if a.unstable_directions != b.unstable_directions {
                if self.critical.len() >= MAX_CRITICAL_POINTS {
                    return Err(StopReason::TooManyCritical {
                        max: MAX_CRITICAL_POINTS,
                    });
                }
                self.locate_critical(x_before, l_before, was_arclength, b, a);
            }
        }
        Ok(())
    }

    /// Adapts the step length to the Newton effort (`iterations`) of the accepted step of
    /// length `h`, the adaptive step having been `nominal`.
    fn adapt_step(&mut self, nominal: f64, h: f64, iterations: usize) {
        let s = self.settings;
        let mut nominal = nominal;
        if iterations + 1 < s.target_iterations {
            nominal = (nominal * 1.5).min(s.max_step);
        } else if iterations > s.target_iterations + 2 {
            nominal = h * 0.6;
        }
        self.state.step = nominal.max(s.min_step);
    }

    /// Puts the path on the load parameter `target` it has reached (to rounding) and, unless
    /// `lowest_done`, adds the lowest eigenvalue to the state's stability when the settings
    /// ask for it.
    fn settle_on_target(&mut self, target: f64, lowest_done: bool) {
        let s = self.settings;
        self.state.lambda = target;
        self.problem.restore(&self.state.x, self.state.lambda);
        // the count is that of the last accepted step; the lowest eigenvalue is added at
        // output points only
        if s.track_stability && s.lowest_eigenvalue && !lowest_done {
            let before = self.state.stability;
            self.update_stability(true);
            // the same state counted again: a neutral direction may flip it by rounding
            if let (Some(b), Some(a)) = (before, self.state.stability) {
                if a.unstable_directions != b.unstable_directions && self.neutral_found {
                    let (x, l) = (self.state.x.clone(), self.state.lambda);
                    if self.is_neutral_at(&x, l) {
                        self.state.stability = Some(Stability {
                            unstable_directions: b.unstable_directions,
                            ..a
                        });
                    }
                }
            }
        }
    }

    /// Whether the eigenvalue nearest zero at `(x, λ)` is zero to rounding
    /// ([`NEUTRAL_FRACTION`] of the problem's eigenvalue scale). Leaves the problem at the
    /// current state.
    fn is_neutral_at(&mut self, x: &[f64], lambda: f64) -> bool {
        let scale = self.problem.eigenvalue_scale();
        let mu = self.problem.eigenvalue_nearest_zero(x, lambda);
        self.problem.restore(&self.state.x, self.state.lambda);
        mu.is_some_and(|m| m.abs() <= NEUTRAL_FRACTION * scale)
    }

    /// Whether the change of the count across the accepted step from `(x0, λ0)` to the
    /// current state is a neutral direction's: zero to rounding at both ends, so that no
    /// eigenvalue crossed.
    fn is_neutral_flip(&mut self, x0: &[f64], l0: f64) -> bool {
        let (x, l) = (self.state.x.clone(), self.state.lambda);
        self.is_neutral_at(&x, l) && self.is_neutral_at(x0, l0)
    }

    /// A neutral direction flipped the count from `before` to `after`: it counts as stable
    /// (the lower count is kept), and the first time it is recorded as a critical point of
    /// kind [`CriticalKind::Neutral`] with its mode, at the current state.
    fn settle_neutral(&mut self, before: Stability, after: Stability) {
        let kept = before.unstable_directions.min(after.unstable_directions);
        self.state.stability = Some(Stability {
            unstable_directions: kept,
            ..after
        });
        if self.neutral_found {
            return;
        }
        self.neutral_found = true;
        let (x, l) = (self.state.x.clone(), self.state.lambda);
        let n = x.len();
        let mode = self
            .newton
            .null_vector(&mut self.problem, &x, l)
            .unwrap_or_else(|| vec![0.0; n]);
        self.problem.restore(&x, l);
        self.critical.push(Critical {
            block: 0,
            kind: CriticalKind::Neutral,
            parameter: l,
            unstable_before: before.unstable_directions,
            unstable_after: after.unstable_directions,
            state: x,
            mode,
        });
    }

    /// Counts unstable directions at the current state (and the lowest eigenvalue when
    /// `eigenvalue` is set and the settings ask for it).
    pub(super) fn update_stability(&mut self, eigenvalue: bool) {
        if !self.settings.track_stability {
            self.state.stability = None;
            return;
        }
        let (x, lambda) = (&self.state.x, self.state.lambda);
        let lowest = eigenvalue && self.settings.lowest_eigenvalue;
        self.state.stability = self.problem.stability(x, lambda, lowest).ok();
    }
}
