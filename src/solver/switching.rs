//! Leaving a path: onto another branch at a critical point, along its mode (within the
//! problem, or onto another problem: the whole assembly behind a reduced model), and
//! restarting with another problem (other boundary conditions), where the path stands or
//! from the new problem's rest. The statistics and the critical points found go on.

use super::continuation::{Continuation, ContinuationError, StopReason};
use super::linear::least_squares_multipliers;
use super::newton::{Newton, NewtonSettings, StepEquation};
use super::path_state::PathState;
use super::problem::Problem;

/// A problem and its path's state, put aside by [`Continuation::start_over_with`] while a
/// new problem's path is followed, to be put back if that path falls short.
pub struct PutAside<P> {
    problem: P,
    newton: Newton,
    state: PathState,
    /// Critical points located before.
    critical: usize,
}

/// How many times the first step off a critical point is halved before the switch fails
/// (a step of 0.05 becomes 0.003125 at the last try).
pub const SWITCH_HALVINGS: usize = 4;

impl<P: Problem> Continuation<P> {
    /// Takes pseudo-arclength steps from now on (`true`), as after a failed natural step:
    /// for a path that bends sharply in its parameter, which a natural step's predictor
    /// could carry onto a nearby branch (an imperfect structure near the perfect one's
    /// bifurcation).
    /// Nothing changes when the steps are of that kind already.
    pub fn set_arclength(&mut self, on: bool) {
        if on == self.state.arclength {
            return;
        }
        if on {
            self.state.step = self.settings.initial_step.min(self.settings.max_step);
        }
        self.state.arclength = on;
        self.state.tangent = None;
    }

    /// Leaves the path at critical point `index` along its mode, in the direction `sign`
    /// (±1), by an arclength step of `h` measured along the mode; continuation then goes on
    /// in arclength steps along the new branch.
    pub fn switch_branch(
        &mut self,
        index: usize,
        sign: f64,
        h: f64,
    ) -> Result<(), ContinuationError> {
        let Some(cp) = self.critical.get(index).cloned() else {
            let lambda = self.state.lambda;
            return Err(self.error(lambda, 0.0, StopReason::NoCriticalPoint { index }));
        };
        self.switch_onto(&cp.state, cp.parameter, &cp.mode, sign, h)
    }

    /// Leaves the critical state `(state, λ)` along `mode` (its primal unknowns at least;
    /// unit norm over them), in the direction `sign` (±1), by an arclength step of `h`
    /// measured along the mode — halved up to [`SWITCH_HALVINGS`] times where Newton's
    /// method fails from the predicted state, as a step of the path would be; continuation
    /// then goes on in arclength steps along the new branch. On failure the current state
    /// is kept and the error quotes the first step tried.
    pub fn switch_onto(
        &mut self,
        state: &[f64],
        parameter: f64,
        mode: &[f64],
        sign: f64,
        h: f64,
    ) -> Result<(), ContinuationError> {
        let mut first = None;
        let mut step = h;
        for _ in 0..=SWITCH_HALVINGS {
            match self.switch_step(state, parameter, mode, sign, step) {
                Ok(()) => return Ok(()),
                Err(e) => {
                    self.stats.rejected += 1;
                    first.get_or_insert(e);
                }
            }
            step *= 0.5;
        }
        Err(first.expect("at least one step tried"))
    }

    /// One try of [`Continuation::switch_onto`] with the step `h`.
    fn switch_step(
        &mut self,
        state: &[f64],
        parameter: f64,
        mode: &[f64],
        sign: f64,
        h: f64,
    ) -> Result<(), ContinuationError> {
        let np = self.problem.primal_unknowns();
        let tx: Vec<f64> = mode[..np].iter().map(|v| v * sign).collect();
        let x: Vec<f64> = state
            .iter()
            .enumerate()
            .map(|(i, a)| a + sign * h * mode.get(i).copied().unwrap_or(0.0))
            .collect();
        self.newton.discard_factorisation();
        let step = StepEquation {
            tx: Some(&tx),
            tl: 0.0,
            x0: state,
            l0: parameter,
            ds: h,
        };
        let settings = self.settings.newton;
        match self.correct(x, parameter, &step, &settings) {
            Ok(t) => {
                self.state.x = state.to_vec();
                self.state.lambda = parameter;
                self.state.arclength = true;
                self.accept(t);
                self.state.step = h;
                self.update_stability(true);
                Ok(())
            }
            Err(cause) => Err(self.error(parameter, h, StopReason::Newton { step: h, cause })),
        }
    }

    /// Replaces the problem (e.g. other boundary conditions) and solves it from `(x, λ)`;
    /// the statistics and critical points go on. On failure the old problem and state are
    /// kept.
    pub fn restart_with(
        &mut self,
        problem: P,
        x: Vec<f64>,
        lambda: f64,
    ) -> Result<(), ContinuationError> {
        self.with_problem(problem, x, lambda, |this| {
            this.state.arclength = false;
            this.correct_in_place()?;
            this.state.step = this.settings.initial_step;
            this.update_stability(true);
            Ok(())
        })
    }

    /// Replaces the problem by `problem` and starts its path afresh at `(x, λ)` (solved
    /// there, its stability judged, no step taken yet), e.g. other boundary conditions
    /// from their rest when the path's state is too far from their equilibrium to be
    /// corrected where it stands. The old problem and state are handed back for
    /// [`Continuation::put_back`]; on failure they are put back at once.
    pub fn start_over_with(
        &mut self,
        problem: P,
        mut x: Vec<f64>,
        lambda: f64,
    ) -> Result<PutAside<P>, ContinuationError> {
        x.resize(problem.unknowns(), 0.0);
        let mut newton = Newton::new(&problem);
        newton.carry_count(self.newton.factorisations());
        let start = PathState::start(x, lambda, self.settings.initial_step);
        let aside = PutAside {
            problem: std::mem::replace(&mut self.problem, problem),
            newton: std::mem::replace(&mut self.newton, newton),
            state: std::mem::replace(&mut self.state, start),
            critical: self.critical.len(),
        };
        match self.correct_in_place() {
            Ok(()) => {
                self.update_stability(true);
                Ok(aside)
            }
            Err(e) => {
                self.put_back(aside);
                Err(e)
            }
        }
    }

    /// Puts back the problem and state put aside by [`Continuation::start_over_with`],
    /// forgetting the critical points located since.
    pub fn put_back(&mut self, aside: PutAside<P>) {
        let PutAside {
            problem,
            mut newton,
            state,
            critical,
        } = aside;
        newton.carry_count(self.newton.factorisations());
        self.problem = problem;
        self.newton = newton;
        self.state = state;
        self.critical.truncate(critical);
    }

    /// Replaces the problem by `problem`, the same one with the same unknowns (another
    /// sparsity pattern): the state is corrected where it is, and the branch goes on as it
    /// was. On failure the old problem and state are kept.
    pub fn reshape(&mut self, problem: P) -> Result<(), ContinuationError> {
        let (x, lambda) = (self.state.x.clone(), self.state.lambda);
        self.with_problem(problem, x, lambda, |this| this.correct_in_place())
    }

    /// Replaces the problem by `problem`: the same one with a constraint added that the
    /// current state satisfies (a phase condition), its multiplier zero at row `row` (the
    /// unknowns from there on move one row down). The state is checked where it is, and the
    /// branch goes on as it was (its step, its mode of stepping, the previous point and
    /// tangent its predictor uses). On failure the old problem and state are kept.
    pub fn constrain(&mut self, problem: P, row: usize) -> Result<(), ContinuationError> {
        let pad = |v: &mut Vec<f64>| v.insert(row.min(v.len()), 0.0);
        let mut x = self.state.x.clone();
        pad(&mut x);
        let lambda = self.state.lambda;
        self.with_problem(problem, x, lambda, |this| {
            let mut previous = this.state.previous.take();
            let mut tangent = this.state.tangent.take();
            this.correct_in_place()?;
            if let Some((x, _)) = previous.as_mut() {
                pad(x);
            }
            if let Some(t) = tangent.as_mut() {
                pad(t);
            }
            this.state.previous = previous;
            this.state.tangent = tangent;
            this.update_stability(true);
            Ok(())
        })
    }

    /// Replaces the problem (e.g. the full model behind a reduced one) and leaves the
    /// critical state `(x, λ)` of the new problem along `mode` as
    /// [`Continuation::switch_onto`] does; on failure the old problem and state are kept.
    /// `near` is another state of the new problem on the same path (the reduced model's
    /// last accepted state, expanded), from which the critical state is re-solved when the
    /// Jacobian at `x` itself is singular.
    // the new problem and `near` on top of `switch_onto`'s state, load, mode, sign and step
    #[allow(clippy::too_many_arguments)]
    pub fn switch_onto_problem(
        &mut self,
        problem: P,
        x: Vec<f64>,
        lambda: f64,
        mode: &[f64],
        sign: f64,
        h: f64,
        near: Option<Vec<f64>>,
    ) -> Result<(), ContinuationError> {
        self.with_problem(problem, x, lambda, |this| {
            this.state.tangent = None;
            // the new problem's multipliers (of supports and joints, which the reduced
            // state does not give) are fitted first by least squares at the known primal
            // state: Newton's method would otherwise have to find them through the
            // critical state's nearly singular Jacobian, and diverged there when the point
            // was placed to rounding (the n = 8 sliding tips' double point); the state is
            // then re-solved, and when its Jacobian is too singular to solve with, a
            // little before the critical load (relative offsets 1e-7, 1e-6 of the load
            // parameter, far below the accuracy of any branch followed from it), from the
            // critical state and then from `near`, where the first Jacobian is regular
            let mut x0 = this.state.x.clone();
            this.fit_multipliers(&mut x0, lambda);
            let settings = NewtonSettings {
                singular_threshold: this.settings.newton.singular_threshold.max(1e-2),
                ..this.settings.newton
            };
            const OFFSETS: [f64; 3] = [0.0, 1e-7, 1e-6];
            let mut starts = vec![x0.clone()];
            if let Some(mut near) = near {
                near.resize(x0.len(), 0.0);
                this.fit_multipliers(&mut near, lambda);
                starts.push(near);
            }
            let mut last = None;
            let mut solved = None;
            'starts: for start in &starts {
                for offset in OFFSETS {
                    let l0 = lambda - offset * lambda.abs().max(1e-3);
                    let step = StepEquation::natural(&x0, l0, 0.0);
                    match this.correct(start.clone(), l0, &step, &settings) {
                        Ok(t) => {
                            solved = Some((t, l0));
                            break 'starts;
                        }
                        Err(cause) => last = Some(cause),
                    }
                }
            }
            let Some((t, l0)) = solved else {
                let cause = last.expect("at least one start tried");
                return Err(this.error(lambda, 0.0, StopReason::Newton { step: 0.0, cause }));
            };
            this.state.x.clone_from(&t.x);
            this.state.lambda = l0;
            this.switch_onto(&t.x, l0, mode, sign, h)
        })
    }

    /// Replaces the multipliers of `x` by those that leave the least residual at its
    /// primal unknowns and load `lambda` ([`least_squares_multipliers`]), where they can be
    /// found.
    fn fit_multipliers(&mut self, x: &mut [f64], lambda: f64) {
        let n = self.problem.unknowns();
        let n_primal = self.problem.primal_unknowns();
        let mut residual = vec![0.0; n];
        let mut kkt = vec![0.0; self.problem.pattern().row_idx().len()];
        self.problem.jacobian(x, lambda, &mut residual, &mut kkt);
        let fitted = least_squares_multipliers(self.problem.pattern(), &kkt, &residual, n_primal);
        if let Some(delta) = fitted {
            for (v, d) in x[n_primal..].iter_mut().zip(&delta) {
                *v += d;
            }
        }
        self.problem.restore(&self.state.x, self.state.lambda);
    }

    /// Puts `problem` (with a Newton solver of its own) in place at `(x, λ)` and runs `f`;
    /// if `f` fails, the old problem, solver and state come back. The statistics go on.
    fn with_problem(
        &mut self,
        problem: P,
        mut x: Vec<f64>,
        lambda: f64,
        f: impl FnOnce(&mut Self) -> Result<(), ContinuationError>,
    ) -> Result<(), ContinuationError> {
        x.resize(problem.unknowns(), 0.0);
        let mut newton = Newton::new(&problem);
        newton.carry_count(self.newton.factorisations());
        let old_problem = std::mem::replace(&mut self.problem, problem);
        let mut old_newton = std::mem::replace(&mut self.newton, newton);
        let old_state = self.state.clone();
        self.state.x = x;
        self.state.lambda = lambda;
        f(self).inspect_err(|_| {
            old_newton.carry_count(self.newton.factorisations());
            self.problem = old_problem;
            self.newton = old_newton;
            self.state = old_state;
        })
    }
}
