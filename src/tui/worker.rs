//! The solver thread of the explorer: it owns the [`Simulation`], takes [`Request`]s over a
//! channel and answers with [`WorkerEvent`]s carrying cloned results, so the UI thread never
//! waits for a solve (gitui's async jobs, bottom's event enum).
//!
//! Scheduling is "last request wins": while a solve runs, requests pile up in a queue; before
//! the next one is taken, an earlier pending request of the same kind is dropped in favour of
//! the later one, and a pending [`Job::Start`] drops everything queued before it. The thread
//! stops when the request channel closes.

use crate::case::Case;
use crate::model::boundary::BoundaryConditions;
use crate::results::{LoadPoint, Snapshot};
use crate::solver::continuation::{Simulation, SolveError};
use std::collections::VecDeque;
use std::panic::{self, AssertUnwindSafe};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

/// Name of the solver thread; the explorer's panic hook recognises it.
pub const THREAD_NAME: &str = "spira-solver";

/// Work for the solver.
#[derive(Clone, Debug, PartialEq)]
pub enum Job {
    /// Build a new simulation from `case` (its `n` and boundary conditions) and solve the
    /// natural state at `ε = 0`.
    Start(Box<Case>),
    /// Continue the path to compression ratio `ε`.
    Advance(f64),
    /// Change the boundary conditions and re-solve at the current `ε` from the current state.
    SetBoundary(BoundaryConditions),
}

impl Job {
    fn same_kind(&self, other: &Job) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }

    /// What the solver is doing, for the status line.
    pub fn describe(&self) -> String {
        match self {
            Job::Start(case) => format!("natural state, n = {}", case.geometry.helices),
            Job::Advance(eps) => format!("ε → {eps:.5}"),
            Job::SetBoundary(_) => "new boundary conditions".to_string(),
        }
    }
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
    /// The conditions the state is under.
    pub boundary: BoundaryConditions,
    /// Internal continuation step length at this state.
    pub step_length: f64,
    /// Wall time of the job that produced it.
    pub time: Duration,
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
    /// The job failed; the last converged state (if any) stays, under `boundary`.
    Failed {
        generation: u64,
        seq: u64,
        reason: String,
        boundary: Option<BoundaryConditions>,
    },
}

impl WorkerEvent {
    pub fn generation(&self) -> u64 {
        match self {
            WorkerEvent::Started { generation, .. }
            | WorkerEvent::Solved { generation, .. }
            | WorkerEvent::Unchanged { generation, .. }
            | WorkerEvent::Failed { generation, .. } => *generation,
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

/// Handle of the solver thread: send requests, receive events. Dropping it closes the
/// request channel, and the thread ends after its current solve.
pub struct Worker {
    requests: Sender<Request>,
    pub events: Receiver<WorkerEvent>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    pub fn spawn() -> std::io::Result<Worker> {
        let (requests, rx) = mpsc::channel();
        let (tx, events) = mpsc::channel();
        let thread = thread::Builder::new()
            .name(THREAD_NAME.to_string())
            .spawn(move || serve(rx, tx))?;
        Ok(Worker {
            requests,
            events,
            thread: Some(thread),
        })
    }

    /// Queues a request; false if the solver thread has stopped.
    pub fn send(&self, request: Request) -> bool {
        self.requests.send(request).is_ok()
    }

    /// Whether the solver thread has ended (it only does when its channels close or it
    /// failed beyond recovery).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Closes the request channel and waits for the thread to finish its current solve.
    pub fn join(mut self) {
        let (closed, _) = mpsc::channel();
        drop(std::mem::replace(&mut self.requests, closed));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The solver thread's state: the simulation of the current generation and the number of
/// converged points it has produced (the next point's step number).
struct Solver {
    sim: Option<Simulation>,
    generation: u64,
    points: usize,
}

fn serve(rx: Receiver<Request>, tx: Sender<WorkerEvent>) {
    let mut solver = Solver {
        sim: None,
        generation: 0,
        points: 0,
    };
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
                }]
            }
        };
        for e in events {
            if tx.send(e).is_err() {
                return;
            }
        }
    }
}

impl Solver {
    fn solved(&mut self, seq: u64, done: bool, t0: Instant) -> Option<WorkerEvent> {
        let sim = self.sim.as_ref()?;
        let state = Solved {
            point: sim.load_point(self.points),
            snapshot: sim.snapshot(),
            boundary: sim.boundary_conditions(),
            step_length: sim.step_length(),
            time: t0.elapsed(),
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
                self.generation = generation;
                self.points = 0;
                self.sim = None;
                match case.simulation() {
                    Ok(sim) => {
                        self.sim = Some(sim);
                        self.solved(seq, true, t0).into_iter().collect()
                    }
                    Err(e) => vec![WorkerEvent::Failed {
                        generation,
                        seq,
                        reason: format!("no natural state: {e}"),
                        boundary: None,
                    }],
                }
            }
            Job::Advance(eps) => self.move_on(seq, t0, |sim| sim.advance_to(eps)),
            Job::SetBoundary(bc) => {
                if self
                    .sim
                    .as_ref()
                    .is_some_and(|s| s.boundary_conditions() == bc)
                {
                    return vec![WorkerEvent::Unchanged { generation, seq }];
                }
                self.move_on(seq, t0, |sim| sim.set_boundary_conditions(bc))
            }
        }
    }

    /// Moves the simulation on with `step`; on failure reports the converged part of the
    /// way (if any) and then the reason.
    fn move_on(
        &mut self,
        seq: u64,
        t0: Instant,
        step: impl FnOnce(&mut Simulation) -> Result<(), SolveError>,
    ) -> Vec<WorkerEvent> {
        let generation = self.generation;
        let Some(sim) = self.sim.as_mut() else {
            return vec![WorkerEvent::Failed {
                generation,
                seq,
                reason: "no converged state to continue from; press r to start over".into(),
                boundary: None,
            }];
        };
        let before = sim.eps();
        match step(sim) {
            Ok(()) => self.solved(seq, true, t0).into_iter().collect(),
            Err(e) => {
                let moved = sim.eps() != before;
                let boundary = Some(sim.boundary_conditions());
                let mut events = Vec::new();
                if moved {
                    events.extend(self.solved(seq, false, t0));
                }
                events.push(WorkerEvent::Failed {
                    generation,
                    seq,
                    reason: e.to_string(),
                    boundary,
                });
                events
            }
        }
    }
}
