//! The solver thread of the explorer: it owns the [`Simulation`](crate::simulation::Simulation), takes [`Request`]s over a
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

//!
//! One file per job: the requests and their scheduling ([`job`]), the answers ([`event`]),
//! the thread's loop ([`serve`]), the solves it runs ([`solver`]), the failures in the
//! user's terms ([`failure`]) and the studies ([`precision`]).

mod event;
mod failure;
mod job;
mod precision;
mod serve;
mod solver;

pub use event::{Solved, WorkerEvent};
pub use job::{coalesce, Job, Part, Request};
pub use solver::run_jobs;

use super::latest::Latest;
use crate::solver::interrupt::Interrupt;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::{self, JoinHandle};
use std::time::Duration;

/// Name of the solver thread; the explorer's panic hook recognises it.
pub const THREAD_NAME: &str = "spira-solver";
/// Name of the thread of work-precision studies.
pub const PRECISION_THREAD_NAME: &str = "spira-precision";
/// Timed runs per mesh of the explorer's work-precision study (after a warm-up each): one,
/// to keep the study short; `spira precision` takes the best of several.
pub const PRECISION_REPEATS: usize = 1;
/// Time budget of one request on the solver thread: a solve still running after this long
/// stops by itself at its last converged state (reason [`Interruption::Deadline`](crate::solver::interrupt::Interruption::Deadline)), so a
/// path that makes no headway (a free motion, a step that keeps halving) never holds the
/// explorer. A minute is far above a normal step (milliseconds) and below a user's patience.
pub const SOLVE_BUDGET: Duration = Duration::from_secs(60);
/// Shortest interval between two [`WorkerEvent::Progress`] reports of one solve.
pub const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);

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
        let precision = Latest::spawn(PRECISION_THREAD_NAME, tx.clone(), precision::run_precision)?;
        let cancel = Arc::new(Mutex::new(Cancel {
            budget,
            ..Cancel::default()
        }));
        let shared = Arc::clone(&cancel);
        let thread = thread::Builder::new()
            .name(THREAD_NAME.to_string())
            .spawn(move || serve::serve(rx, tx, shared))?;
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
