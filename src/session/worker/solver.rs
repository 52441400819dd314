//! The solves the solver thread runs: it owns the [`Simulation`] of the current generation
//! and answers each job with the converged states it reached and how the job ended.

use super::event::{CriticalMode, Solved, WorkerEvent};
use super::failure::{describe_failure, interruption, Asked};
use super::job::{Job, Part, Request};
use crate::case::Case;
use crate::discretisation::bulk;
use crate::model::boundary::BoundaryConditions;
use crate::output;
use crate::results::CriticalPoint;
use crate::run::BRANCH_STEP;
use crate::simulation::{Simulation, SolveError};
use crate::solver::continuation::Observer;
use crate::solver::interrupt::Interrupt;
use crate::study::{resolve_accuracy_with, AccuracyError};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Shortest interval between two [`WorkerEvent::Progress`] reports of one solve.
pub const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);

/// Runs `jobs` in order on this thread with the solver thread's code (no time budget, no
/// cancellation, no coalescing) and returns its answers: a replay of a session.
pub fn run_jobs(jobs: Vec<Job>) -> Vec<WorkerEvent> {
    let mut runner = Runner::new();
    jobs.into_iter().flat_map(|job| runner.run(job)).collect()
}

/// Jobs run one at a time on this thread with the solver thread's code (no time budget, no
/// cancellation, no coalescing), so that a replay can look at the simulation between two.
pub struct Runner {
    solver: Solver,
    jobs: u64,
}

impl Default for Runner {
    fn default() -> Self {
        Runner::new()
    }
}

impl Runner {
    /// No simulation yet.
    pub fn new() -> Runner {
        Runner {
            solver: Solver::new(),
            jobs: 0,
        }
    }

    /// Runs `job` and returns its answers.
    pub fn run(&mut self, job: Job) -> Vec<WorkerEvent> {
        let generation = if matches!(job, Job::Start(_)) {
            self.solver.generation + 1
        } else {
            self.solver.generation
        };
        self.jobs += 1;
        self.solver.run(Request {
            generation,
            seq: self.jobs,
            job,
        })
    }

    /// The critical points the current simulation has found since its start (0 without
    /// one): the indices a [`Job::Switch`] may name.
    pub fn critical_points(&self) -> usize {
        self.solver
            .sim
            .as_ref()
            .map_or(0, |s| s.critical_points().len())
    }
}

/// The solver thread's state: the simulation of the current generation and the number of
/// converged points it has produced (the next point's step number).
pub(super) struct Solver {
    pub(super) sim: Option<Simulation>,
    /// The interrupt and progress channel of the job in hand.
    interrupt: Option<Interrupt>,
    progress: Option<(Sender<WorkerEvent>, u64, u64)>,
    /// Internal steps accepted by the job in hand (counted by its observer).
    accepted: Arc<AtomicUsize>,
    generation: u64,
    points: usize,
    /// Critical points of the simulation already reported.
    critical: usize,
}

impl Solver {
    /// No simulation yet.
    pub(super) fn new() -> Solver {
        Solver {
            sim: None,
            interrupt: None,
            progress: None,
            accepted: Arc::new(AtomicUsize::new(0)),
            generation: 0,
            points: 0,
            critical: 0,
        }
    }

    /// The symbol of the simulation's load parameter (`ε` before there is one).
    pub(super) fn symbol(&self) -> &'static str {
        self.sim
            .as_ref()
            .map_or("ε", |s| s.load_parameter().symbol())
    }

    /// Hands the simulation the interrupt of this job and an observer that reports the
    /// accepted internal steps as [`WorkerEvent::Progress`] (at most every
    /// [`PROGRESS_INTERVAL`]). A `Start` sets them on its new simulation in [`Solver::run`].
    pub(super) fn watch(
        &mut self,
        interrupt: &Interrupt,
        tx: &Sender<WorkerEvent>,
        generation: u64,
        seq: u64,
    ) {
        self.interrupt = Some(interrupt.clone());
        self.progress = Some((tx.clone(), generation, seq));
        let counted = self.observer();
        if let Some(sim) = self.sim.as_mut() {
            sim.set_interrupt(Some(interrupt.clone()));
            sim.set_observer(Some(counted));
        }
    }

    /// The observer of the job in hand: counts the accepted internal steps and reports
    /// progress when a channel is set.
    fn observer(&self) -> Observer {
        self.accepted.store(0, Ordering::Relaxed);
        let accepted = Arc::clone(&self.accepted);
        let mut progress = self
            .progress
            .as_ref()
            .map(|(tx, g, s)| observer(tx.clone(), *g, *s));
        Box::new(move |state| {
            accepted.fetch_add(1, Ordering::Relaxed);
            if let Some(p) = progress.as_mut() {
                p(state);
            }
        })
    }

    /// The job's interrupt (a new one when the job has none, as in a replay) raised once
    /// `steps` (≥ 1) internal steps are accepted, and the job's observer, set on the
    /// simulation; the interrupt is returned.
    fn stop_after(&mut self, steps: usize) -> Interrupt {
        let interrupt = self.interrupt.clone().unwrap_or_default();
        let raise = interrupt.clone();
        let mut inner = self.observer();
        let mut count = 0;
        let observer: Observer = Box::new(move |state| {
            inner(state);
            count += 1;
            if count >= steps {
                raise.raise();
            }
        });
        if let Some(sim) = self.sim.as_mut() {
            sim.set_interrupt(Some(interrupt.clone()));
            sim.set_observer(Some(observer));
        }
        interrupt
    }

    /// After a job stopped by [`Solver::stop_after`]: the job's own interrupt and observer.
    fn stop_after_done(&mut self) {
        let observer = self.observer();
        if let Some(sim) = self.sim.as_mut() {
            sim.set_interrupt(self.interrupt.clone());
            sim.set_observer(Some(observer));
        }
    }

    fn solved(&mut self, seq: u64, done: bool, t0: Instant) -> Option<WorkerEvent> {
        let sim = self.sim.as_ref()?;
        let all = sim.critical_points();
        let new = &all[self.critical.min(all.len())..];
        let modes = new
            .iter()
            .map(|c| CriticalMode {
                shape: sim.mode_shape(c),
                vertices: output::mode_vertices(sim.model(), c),
            })
            .collect();
        let critical = new
            .iter()
            .map(|c| CriticalPoint {
                state: Vec::new(),
                mode: Vec::new(),
                assembly_mode: None,
                second_mode: None,
                ..c.clone()
            })
            .collect();
        self.critical = all.len();
        let point = sim.load_point(self.points);
        let snapshot = sim.snapshot();
        let state = Solved {
            critical,
            modes,
            bulk: bulk::step_bulk(sim.model(), &snapshot, &point),
            point,
            snapshot,
            boundary: sim.boundary_conditions(),
            step_length: sim.step_length(),
            time: t0.elapsed(),
            pair: sim.solves_pair(),
        };
        self.points += 1;
        Some(WorkerEvent::Solved {
            generation: self.generation,
            seq,
            done,
            state: Box::new(state),
        })
    }

    /// Runs the job of `request` and returns its answers.
    pub(super) fn run(&mut self, request: Request) -> Vec<WorkerEvent> {
        let Request {
            generation,
            seq,
            job,
        } = request;
        let t0 = Instant::now();
        match job {
            Job::Start(case) => self.start(&case, generation, seq, t0),
            Job::Advance(parameter) => self.move_on(seq, t0, Asked::Parameter(parameter), |sim| {
                sim.advance_to(parameter)
            }),
            Job::AdvancePart { parameter, part } => self.advance_part(seq, t0, parameter, part),
            Job::Switch {
                index,
                sign,
                parameter,
                part,
            } => self.switch(seq, t0, (index, sign), parameter, part),
            Job::SetBoundary(bc) => self.set_boundary(generation, seq, t0, bc),
            Job::Precision(_) | Job::Curve(_) => vec![WorkerEvent::Failed {
                generation,
                seq,
                reason: "work-precision studies and critical curves run on their own threads"
                    .into(),
                boundary: None,
                interrupted: None,
            }],
        }
    }

    /// A new simulation of `case` (of generation `generation`) at its natural state.
    fn start(&mut self, case: &Case, generation: u64, seq: u64, t0: Instant) -> Vec<WorkerEvent> {
        // an accuracy target becomes a mesh here, before the natural state
        let (case, choice) = match resolve_accuracy_with(case, self.interrupt.as_ref()) {
            Ok(resolved) => resolved,
            // stopped from outside: the previous simulation stays, as it was
            Err(e @ AccuracyError::Interrupted { why, .. }) => {
                return vec![WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: format!("{e}; the previous simulation is kept"),
                    boundary: self.sim.as_ref().map(Simulation::boundary_conditions),
                    interrupted: Some(why),
                }]
            }
            Err(e) => {
                return vec![WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: format!("no mesh for the case's accuracy: {e}"),
                    boundary: None,
                    interrupted: None,
                }]
            }
        };
        let mut events: Vec<WorkerEvent> = choice
            .map(|c| WorkerEvent::MeshChosen {
                generation,
                seq,
                choice: Box::new(c),
            })
            .into_iter()
            .collect();
        let case = case.for_explorer();
        let observer = self.observer();
        match Simulation::from_case_with(&case, self.interrupt.clone(), Some(observer)) {
            Ok(sim) => {
                self.generation = generation;
                self.points = 0;
                self.critical = 0;
                self.sim = Some(sim);
                events.extend(self.solved(seq, true, t0));
            }
            // stopped from outside: the previous simulation stays, as it was
            Err(e) if interruption(&e).is_some() => events.push(WorkerEvent::Failed {
                generation,
                seq,
                reason: describe_failure(
                    &e,
                    Asked::Start(case.geometry.helices),
                    case.load_parameter().symbol(),
                    t0.elapsed(),
                ),
                boundary: self.sim.as_ref().map(Simulation::boundary_conditions),
                interrupted: interruption(&e),
            }),
            Err(e) => {
                self.generation = generation;
                self.points = 0;
                self.critical = 0;
                self.sim = None;
                events.push(WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: format!("no natural state: {e}"),
                    boundary: None,
                    interrupted: None,
                })
            }
        }
        events
    }

    /// The path towards load parameter `parameter`, stopped after `part.steps` internal
    /// steps with the next one `part.step_length` long.
    fn advance_part(
        &mut self,
        seq: u64,
        t0: Instant,
        parameter: f64,
        part: Part,
    ) -> Vec<WorkerEvent> {
        let interrupt = self.stop_after(part.steps);
        if part.steps == 0 {
            interrupt.raise();
        }
        let events = self.move_on(seq, t0, Asked::Parameter(parameter), |sim| {
            let outcome = sim.advance_to(parameter);
            sim.set_step_length(part.step_length);
            outcome
        });
        self.stop_after_done();
        events
    }

    /// Onto the branch of bifurcation `index` on the side `sign`, then along it to load
    /// parameter `parameter` (with `part`: only that part of the way).
    fn switch(
        &mut self,
        seq: u64,
        t0: Instant,
        (index, sign): (usize, f64),
        parameter: f64,
        part: Option<Part>,
    ) -> Vec<WorkerEvent> {
        let interrupt = part.map(|p| self.stop_after(p.steps));
        let events = self.move_on(seq, t0, Asked::Switch(index, parameter), |sim| {
            sim.switch_branch(index, sign, BRANCH_STEP)?;
            if let (Some(p), Some(i)) = (part, &interrupt) {
                if p.steps == 0 {
                    i.raise();
                }
            }
            let outcome = sim.advance_to(parameter);
            if let Some(p) = part {
                sim.set_step_length(p.step_length);
            }
            outcome
        });
        if part.is_some() {
            self.stop_after_done();
        }
        events
    }

    /// New boundary conditions `bc`, re-solved at the current load parameter (`generation`:
    /// the request's).
    fn set_boundary(
        &mut self,
        generation: u64,
        seq: u64,
        t0: Instant,
        bc: BoundaryConditions,
    ) -> Vec<WorkerEvent> {
        if self
            .sim
            .as_ref()
            .is_some_and(|s| s.boundary_conditions() == bc)
        {
            return vec![WorkerEvent::Unchanged { generation, seq }];
        }
        self.move_on(seq, t0, Asked::Boundary, |sim| {
            sim.set_boundary_conditions(bc)
        })
    }

    /// Moves the simulation on with `step`; on failure reports the converged part of the
    /// way (if any) and then the reason.
    fn move_on(
        &mut self,
        seq: u64,
        t0: Instant,
        asked: Asked,
        step: impl FnOnce(&mut Simulation) -> Result<(), SolveError>,
    ) -> Vec<WorkerEvent> {
        let generation = self.generation;
        let Some(sim) = self.sim.as_mut() else {
            return vec![WorkerEvent::Failed {
                generation,
                seq,
                reason: "no converged state to continue from; press r to start over".into(),
                boundary: None,
                interrupted: None,
            }];
        };
        let symbol = sim.load_parameter().symbol();
        let ratio_before = sim.compression_ratio();
        let (state_before, lambda_before) = (sim.state().to_vec(), sim.parameter());
        match step(sim) {
            Ok(()) => self.solved(seq, true, t0).into_iter().collect(),
            Err(e) => {
                let moved = sim.compression_ratio() != ratio_before;
                let boundary = Some(sim.boundary_conditions());
                // what a replay needs: the steps taken, or none when nothing changed
                let changed = sim.parameter() != lambda_before || sim.state() != state_before;
                let stopped = interruption(&e).map(|_| WorkerEvent::Stopped {
                    generation,
                    seq,
                    steps: (changed || !matches!(asked, Asked::Switch(..)))
                        .then(|| self.accepted.load(Ordering::Relaxed)),
                    step_length: sim.step_length(),
                });
                let mut events = Vec::new();
                if moved {
                    events.extend(self.solved(seq, false, t0));
                }
                events.extend(stopped);
                events.push(WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: describe_failure(&e, asked, symbol, t0.elapsed()),
                    boundary,
                    interrupted: interruption(&e),
                });
                events
            }
        }
    }
}

/// Reports accepted internal steps of request `seq` as [`WorkerEvent::Progress`], at most
/// every [`PROGRESS_INTERVAL`].
fn observer(tx: Sender<WorkerEvent>, generation: u64, seq: u64) -> Observer {
    let t0 = Instant::now();
    let mut last: Option<Instant> = None;
    let mut steps = 0;
    Box::new(move |state| {
        steps += 1;
        let now = Instant::now();
        if last.is_some_and(|l| now.duration_since(l) < PROGRESS_INTERVAL) {
            return;
        }
        last = Some(now);
        let _ = tx.send(WorkerEvent::Progress {
            generation,
            seq,
            parameter: state.lambda,
            steps,
            elapsed: now.duration_since(t0),
        });
    })
}
