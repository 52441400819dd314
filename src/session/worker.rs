//! The solver thread of the explorer: it owns the [`Simulation`], takes [`Request`]s over a
//! channel and answers with [`WorkerEvent`]s carrying cloned results, so the UI thread never
//! waits for a solve (gitui's async jobs, bottom's event enum).
//!
//! Scheduling is "last request wins": while a solve runs, requests pile up in a queue; before
//! the next one is taken, an earlier pending request of the same kind is dropped in favour of
//! the later one, and a pending [`Job::Start`] drops everything queued before it. The thread
//! stops when the request channel closes.
//!
//! Work-precision studies ([`Job::Precision`]) run on a second thread of their own, a
//! [`Latest`] job, so that a study of many meshes never holds up the user's steps; there the
//! last request wins too, and a newer request stops the study in progress after its current
//! mesh.

use super::latest::{Context, Latest};
use crate::case::Case;
use crate::discretisation::bulk;
use crate::model::boundary::BoundaryConditions;
use crate::results::{CriticalPoint, LoadPoint, Snapshot, StepBulk};
use crate::run::BRANCH_STEP;
use crate::simulation::Simulation;
use crate::simulation::SolveError;
use crate::solver::continuation::{Observer, StopReason};
use crate::solver::interrupt::{Interrupt, Interruption};
use crate::study::{resolve_accuracy, run_study, Ladder, MeshChoice, Study, StudyError, Subject};
use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

/// Name of the solver thread; the explorer's panic hook recognises it.
pub const THREAD_NAME: &str = "spira-solver";
/// Name of the thread of work-precision studies.
pub const PRECISION_THREAD_NAME: &str = "spira-precision";
/// Timed runs per mesh of the explorer's work-precision study (after a warm-up each): one,
/// to keep the study short; `spira precision` takes the best of several.
pub const PRECISION_REPEATS: usize = 1;
/// Time budget of one request on the solver thread: a solve still running after this long
/// stops by itself at its last converged state (reason [`Interruption::Deadline`]), so a
/// path that makes no headway (a free motion, a step that keeps halving) never holds the
/// explorer. A minute is far above a normal step (milliseconds) and below a user's patience.
pub const SOLVE_BUDGET: Duration = Duration::from_secs(60);
/// Shortest interval between two [`WorkerEvent::Progress`] reports of one solve.
pub const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);

/// Work for the solver.
#[derive(Clone, Debug, PartialEq)]
pub enum Job {
    /// Build a new simulation from `case` (its `n` and boundary conditions) and solve the
    /// natural state at `ε = 0`.
    Start(Box<Case>),
    /// Continue the path to compression ratio `ε`.
    Advance(f64),
    /// Continue the path towards `ε = eps` and stop after `steps` accepted internal steps,
    /// leaving the next internal step `step_length` long: a step that was cancelled part
    /// of the way, replayed to the state it reached.
    AdvancePart { eps: f64, part: Part },
    /// Leave the path at bifurcation `index` (of the simulation's critical points) onto
    /// its branch, on the side `sign` (±1), and continue along it to `ε = eps` (with
    /// `part`: only that part of the way, as [`Job::AdvancePart`]).
    Switch {
        index: usize,
        sign: f64,
        eps: f64,
        part: Option<Part>,
    },
    /// Change the boundary conditions and re-solve at the current `ε` from the current state.
    SetBoundary(BoundaryConditions),
    /// A work-precision study of `case`'s path (on the precision thread).
    Precision(Box<Case>),
}

impl Job {
    fn same_kind(&self, other: &Job) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }

    /// What the solver is doing, for the status line.
    pub fn describe(&self) -> String {
        match self {
            Job::Start(case) => format!("natural state, n = {}", case.geometry.helices),
            Job::Advance(eps) | Job::AdvancePart { eps, .. } => format!("ε → {eps:.5}"),
            Job::Switch { index, eps, .. } => {
                format!("branch of critical point {index}, ε → {eps:.5}")
            }
            Job::SetBoundary(_) => "new boundary conditions".to_string(),
            Job::Precision(case) => {
                format!("work-precision study, n = {}", case.geometry.helices)
            }
        }
    }
}

/// The part of the way a stopped solve got: `steps` accepted internal steps, and the
/// length of the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    pub steps: usize,
    pub step_length: f64,
}

/// A job tagged with the app's generation (bumped by every [`Job::Start`]) and a sequence
/// number (increasing over all requests), which the answers carry back.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub generation: u64,
    pub seq: u64,
    pub job: Job,
}

/// A converged state as the screen needs it.
#[derive(Clone, Debug)]
pub struct Solved {
    pub point: LoadPoint,
    pub snapshot: Snapshot,
    /// The bulk of every rod of the state (`discretisation::bulk`).
    pub bulk: StepBulk,
    /// The conditions the state is under.
    pub boundary: BoundaryConditions,
    /// Internal continuation step length at this state.
    pub step_length: f64,
    /// Wall time of the job that produced it.
    pub time: Duration,
    /// Critical points crossed on the way to this state (without their state and mode).
    pub critical: Vec<CriticalPoint>,
    /// Whether the state is of the symmetric pair (else of the whole assembly).
    pub pair: bool,
}

/// What the solver thread reports.
#[derive(Clone, Debug)]
pub enum WorkerEvent {
    /// The job of request `seq` has started.
    Started {
        generation: u64,
        seq: u64,
        job: String,
    },
    /// A converged state; `done` is false when a failed job got part of the way and the
    /// failure follows.
    Solved {
        generation: u64,
        seq: u64,
        done: bool,
        state: Box<Solved>,
    },
    /// The job needed no solve (e.g. the conditions asked for are already in force).
    Unchanged { generation: u64, seq: u64 },
    /// The job of request `seq` is still solving: an internal step was accepted at load
    /// parameter `parameter` (`ε` under displacement control), `elapsed` after the job
    /// started.
    Progress {
        generation: u64,
        seq: u64,
        parameter: f64,
        steps: usize,
        elapsed: Duration,
    },
    /// The job of request `seq` was stopped from outside (cancelled, or out of time) after
    /// `steps` accepted internal steps of its continuation, with `step_length` the length
    /// of the next one: what a replay needs to reach the same state. `steps` is `None`
    /// when the job stopped before it changed anything (a branch switch that did not get
    /// onto the branch). Sent before the job's [`WorkerEvent::Failed`].
    Stopped {
        generation: u64,
        seq: u64,
        steps: Option<usize>,
        step_length: f64,
    },
    /// The job failed; the last converged state (if any) stays, under `boundary`.
    /// `interrupted` says when it was stopped from outside (cancelled, or out of time).
    Failed {
        generation: u64,
        seq: u64,
        reason: String,
        boundary: Option<BoundaryConditions>,
        interrupted: Option<Interruption>,
    },
    /// The case gives an accuracy: the mesh chosen for it (before the natural state).
    MeshChosen {
        generation: u64,
        seq: u64,
        choice: Box<MeshChoice>,
    },
    /// A work-precision study has solved `done` of its `total` meshes.
    PrecisionProgress {
        generation: u64,
        seq: u64,
        done: usize,
        total: usize,
    },
    /// A work-precision study is finished, or why it failed.
    Precision {
        generation: u64,
        seq: u64,
        study: Result<Box<Study>, String>,
    },
}

impl WorkerEvent {
    pub fn generation(&self) -> u64 {
        match self {
            WorkerEvent::Started { generation, .. }
            | WorkerEvent::Solved { generation, .. }
            | WorkerEvent::Unchanged { generation, .. }
            | WorkerEvent::Stopped { generation, .. }
            | WorkerEvent::Failed { generation, .. }
            | WorkerEvent::Progress { generation, .. }
            | WorkerEvent::MeshChosen { generation, .. }
            | WorkerEvent::PrecisionProgress { generation, .. }
            | WorkerEvent::Precision { generation, .. } => *generation,
        }
    }
}

/// Drops the requests a later one replaces: everything before the last `Start`, then every
/// request followed by a later one of the same kind. The survivors keep their order.
pub fn coalesce(queue: &mut VecDeque<Request>) {
    if let Some(last_start) = queue.iter().rposition(|r| matches!(r.job, Job::Start(_))) {
        queue.drain(..last_start);
    }
    let jobs: Vec<Job> = queue.iter().map(|r| r.job.clone()).collect();
    let mut k = 0;
    queue.retain(|_| {
        let keep = !jobs[k + 1..].iter().any(|later| later.same_kind(&jobs[k]));
        k += 1;
        keep
    });
}

/// Handle of the solver thread (and of the thread of work-precision studies): send
/// requests, receive events. Dropping it closes the request channels, and the threads end
/// after their current solve (a study: after its current mesh).
pub struct Worker {
    requests: Sender<Request>,
    cancel: Arc<Mutex<Cancel>>,
    precision: Latest<Request>,
    pub events: Receiver<WorkerEvent>,
    thread: Option<JoinHandle<()>>,
}

/// What cancelling shares between the UI and the solver thread: the interrupt of the job
/// running now (and its request's sequence number) and the last sequence number cancelled.
/// One lock, so a cancel can never fall between two jobs and be lost or hit the wrong one.
#[derive(Debug, Default)]
struct Cancel {
    /// The time budget of the requests started from now on.
    budget: Duration,
    running: Option<(u64, Interrupt)>,
    /// Requests up to this sequence number are cancelled (the running one is interrupted,
    /// queued ones are answered without a solve).
    through: u64,
}

impl Cancel {
    fn lock(cancel: &Mutex<Cancel>) -> std::sync::MutexGuard<'_, Cancel> {
        cancel.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl Worker {
    /// The solver thread with the time budget [`SOLVE_BUDGET`] per request.
    pub fn spawn() -> std::io::Result<Worker> {
        Worker::spawn_with_budget(SOLVE_BUDGET)
    }

    /// The solver thread with a time budget of `budget` per request.
    pub fn spawn_with_budget(budget: Duration) -> std::io::Result<Worker> {
        let (requests, rx) = mpsc::channel();
        let (tx, events) = mpsc::channel();
        let precision = Latest::spawn(PRECISION_THREAD_NAME, tx.clone(), run_precision)?;
        let cancel = Arc::new(Mutex::new(Cancel {
            budget,
            ..Cancel::default()
        }));
        let shared = Arc::clone(&cancel);
        let thread = thread::Builder::new()
            .name(THREAD_NAME.to_string())
            .spawn(move || serve(rx, tx, shared))?;
        Ok(Worker {
            requests,
            cancel,
            precision,
            events,
            thread: Some(thread),
        })
    }

    /// Queues a request (a work-precision study on its own thread); false if the thread
    /// that takes it has stopped.
    pub fn send(&self, request: Request) -> bool {
        match request.job {
            Job::Precision(_) => self.precision.submit(request),
            _ => self.requests.send(request).is_ok(),
        }
    }

    /// The time budget of the requests the solver starts from now on (the natural state
    /// of a new simulation has one too).
    pub fn set_budget(&self, budget: Duration) {
        Cancel::lock(&self.cancel).budget = budget;
    }

    /// Cancels every request up to sequence number `through`: the solve running now stops
    /// at its next check (between Newton iterations) keeping its last converged state, and
    /// queued ones are answered as cancelled without a solve.
    pub fn cancel(&self, through: u64) {
        let mut c = Cancel::lock(&self.cancel);
        c.through = c.through.max(through);
        if let Some((seq, interrupt)) = &c.running {
            if *seq <= c.through {
                interrupt.raise();
            }
        }
    }

    /// Whether the solver thread has ended (it only does when its channels close or it
    /// failed beyond recovery).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Closes the request channels and waits for the solver thread to finish its current
    /// solve (a study in progress stops by itself after its current mesh).
    pub fn join(mut self) {
        let (closed, _) = mpsc::channel();
        drop(std::mem::replace(&mut self.requests, closed));
        self.precision.close();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A work-precision study on the precision thread: progress after each mesh, then the
/// study; it stops after the current mesh when a newer request arrives (and then reports
/// nothing).
fn run_precision(request: Request, ctx: &Context<Request, WorkerEvent>) {
    let Request {
        generation,
        seq,
        job: Job::Precision(case),
    } = request
    else {
        return;
    };
    let problem = Subject::Path(case);
    let ladder = Ladder::standard(&problem);
    let study = panic::catch_unwind(AssertUnwindSafe(|| {
        run_study(&problem, &ladder, PRECISION_REPEATS, |p| {
            if ctx.is_cancelled() {
                return ControlFlow::Break(());
            }
            let progress = WorkerEvent::PrecisionProgress {
                generation,
                seq,
                done: p.done,
                total: p.total,
            };
            if !ctx.send(progress) {
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(())
        })
    }));
    let study = match study {
        Ok(Err(StudyError::Cancelled)) => return,
        Ok(Ok(s)) => Ok(Box::new(s)),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("the work-precision study panicked".to_string()),
    };
    ctx.send(WorkerEvent::Precision {
        generation,
        seq,
        study,
    });
}

/// Runs `jobs` in order on this thread with the solver thread's code (no time budget, no
/// cancellation, no coalescing) and returns its answers: a replay of a session.
pub fn run_jobs(jobs: Vec<Job>) -> Vec<WorkerEvent> {
    let mut solver = Solver::new();
    let mut events = Vec::new();
    for (k, job) in jobs.into_iter().enumerate() {
        let generation = if matches!(job, Job::Start(_)) {
            solver.generation + 1
        } else {
            solver.generation
        };
        events.extend(solver.run(Request {
            generation,
            seq: k as u64 + 1,
            job,
        }));
    }
    events
}

/// The solver thread's state: the simulation of the current generation and the number of
/// converged points it has produced (the next point's step number).
struct Solver {
    sim: Option<Simulation>,
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

fn serve(rx: Receiver<Request>, tx: Sender<WorkerEvent>, cancel: Arc<Mutex<Cancel>>) {
    let mut solver = Solver::new();
    let mut queue = VecDeque::new();
    loop {
        if queue.is_empty() {
            match rx.recv() {
                Ok(r) => queue.push_back(r),
                Err(_) => return,
            }
        }
        loop {
            match rx.try_recv() {
                Ok(r) => queue.push_back(r),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return,
            }
        }
        coalesce(&mut queue);
        let Some(request) = queue.pop_front() else {
            continue;
        };
        let (generation, seq) = (request.generation, request.seq);
        let interrupt = {
            let mut c = Cancel::lock(&cancel);
            if seq <= c.through {
                c.running = None;
                None
            } else {
                let i = Interrupt::new().with_deadline(Some(Instant::now() + c.budget));
                c.running = Some((seq, i.clone()));
                Some(i)
            }
        };
        let Some(interrupt) = interrupt else {
            let skipped = WorkerEvent::Failed {
                generation,
                seq,
                reason: "cancelled before it started".into(),
                boundary: solver.sim.as_ref().map(Simulation::boundary_conditions),
                interrupted: Some(Interruption::Cancelled),
            };
            if tx.send(skipped).is_err() {
                return;
            }
            continue;
        };
        let started = WorkerEvent::Started {
            generation,
            seq,
            job: request.job.describe(),
        };
        if tx.send(started).is_err() {
            return;
        }
        // A panic in the core must not take the explorer down: report it and drop the
        // simulation, whose state can no longer be trusted.
        solver.watch(&interrupt, &tx, generation, seq);
        let events = match panic::catch_unwind(AssertUnwindSafe(|| solver.run(request))) {
            Ok(events) => events,
            Err(payload) => {
                solver.sim = None;
                let what = payload
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| payload.downcast_ref::<&str>().copied())
                    .unwrap_or("unknown cause");
                vec![WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: format!("the solver panicked ({what}); press r to start over"),
                    boundary: None,
                    interrupted: None,
                }]
            }
        };
        Cancel::lock(&cancel).running = None;
        if let Some(sim) = solver.sim.as_mut() {
            sim.set_interrupt(None);
            sim.set_observer(None);
        }
        for e in events {
            if tx.send(e).is_err() {
                return;
            }
        }
    }
}

impl Solver {
    /// No simulation yet.
    fn new() -> Solver {
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

    /// Hands the simulation the interrupt of this job and an observer that reports the
    /// accepted internal steps as [`WorkerEvent::Progress`] (at most every
    /// [`PROGRESS_INTERVAL`]). A `Start` sets them on its new simulation in [`Solver::run`].
    fn watch(
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
        let critical = all[self.critical.min(all.len())..]
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

    fn run(&mut self, request: Request) -> Vec<WorkerEvent> {
        let Request {
            generation,
            seq,
            job,
        } = request;
        let t0 = Instant::now();
        match job {
            Job::Start(case) => {
                // an accuracy target becomes a mesh here, before the natural state
                let (case, choice) = match resolve_accuracy(&case) {
                    Ok(resolved) => resolved,
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
            Job::Advance(eps) => self.move_on(seq, t0, Asked::Eps(eps), |sim| sim.advance_to(eps)),
            Job::AdvancePart { eps, part } => {
                let interrupt = self.stop_after(part.steps);
                if part.steps == 0 {
                    interrupt.raise();
                }
                let events = self.move_on(seq, t0, Asked::Eps(eps), |sim| {
                    let outcome = sim.advance_to(eps);
                    sim.set_step_length(part.step_length);
                    outcome
                });
                self.stop_after_done();
                events
            }
            Job::Switch {
                index,
                sign,
                eps,
                part,
            } => {
                let interrupt = part.map(|p| self.stop_after(p.steps));
                let events = self.move_on(seq, t0, Asked::Switch(index, eps), |sim| {
                    sim.switch_branch(index, sign, BRANCH_STEP)?;
                    if let (Some(p), Some(i)) = (part, &interrupt) {
                        if p.steps == 0 {
                            i.raise();
                        }
                    }
                    let outcome = sim.advance_to(eps);
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
            Job::SetBoundary(bc) => {
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
            Job::Precision(_) => vec![WorkerEvent::Failed {
                generation,
                seq,
                reason: "work-precision studies run on their own thread".into(),
                boundary: None,
                interrupted: None,
            }],
        }
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
        let before = sim.eps();
        let (state_before, lambda_before) = (sim.state().to_vec(), sim.parameter());
        match step(sim) {
            Ok(()) => self.solved(seq, true, t0).into_iter().collect(),
            Err(e) => {
                let moved = sim.eps() != before;
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
                    reason: describe_failure(&e, asked, t0.elapsed()),
                    boundary,
                    interrupted: interruption(&e),
                });
                events
            }
        }
    }
}

/// What a failed job asked for, for its message.
#[derive(Clone, Copy, Debug)]
enum Asked {
    Eps(f64),
    Boundary,
    /// A new simulation of `n` helices.
    Start(usize),
    /// The branch of critical point `index`, followed to `ε`.
    Switch(usize, f64),
}

/// Why a solve stopped, if it was stopped from outside.
fn interruption(e: &SolveError) -> Option<Interruption> {
    match e.reason {
        StopReason::Interrupted(why) => Some(why),
        _ => None,
    }
}

/// A failure in the user's terms: what was asked for, where the path stopped, why.
fn describe_failure(e: &SolveError, asked: Asked, elapsed: Duration) -> String {
    let what = match asked {
        Asked::Eps(eps) => format!("ε → {eps:.5}"),
        Asked::Boundary => "the new boundary conditions".to_string(),
        Asked::Start(n) => format!("the natural state of n = {n}"),
        Asked::Switch(index, eps) => {
            format!("the switch onto the branch of critical point {index} (ε → {eps:.5})")
        }
    };
    let kept = match asked {
        Asked::Start(_) => "the previous simulation is kept".to_string(),
        _ => format!("the last converged state (ε = {:.5}) is kept", e.eps),
    };
    match (interruption(e), asked) {
        (Some(Interruption::Cancelled), _) => {
            format!(
                "{what} cancelled after {:.1} s; {kept}",
                elapsed.as_secs_f64()
            )
        }
        (Some(Interruption::Deadline), _) => format!(
            "{what} stopped: its time budget of {:.0} s ran out; {kept}",
            elapsed.as_secs_f64().round()
        ),
        (None, Asked::Boundary) => {
            format!(
                "the new boundary conditions were refused and undone ({}); {kept}",
                e.reason
            )
        }
        (None, _) => format!("{what} failed: {}; {kept}", e.reason),
    }
}

/// Reports accepted internal steps of request `seq` as [`WorkerEvent::Progress`], at most
/// every [`PROGRESS_INTERVAL`].
fn observer(
    tx: Sender<WorkerEvent>,
    generation: u64,
    seq: u64,
) -> crate::solver::continuation::Observer {
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
