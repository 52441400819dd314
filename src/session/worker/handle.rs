//! The explorer's handle of the solver thread (and of the thread of work-precision
//! studies): requests out, cancels, events in.

use super::cancel::Cancel;
use super::curve::{run_curve, Running};
use super::event::WorkerEvent;
use super::job::{Job, Request};
use super::precision::run_precision;
use super::serve::serve;
use crate::session::latest::Latest;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::{self, JoinHandle};
use std::time::Duration;

/// Name of the solver thread; the explorer's panic hook recognises it.
pub const THREAD_NAME: &str = "spira-solver";
/// Name of the thread of work-precision studies.
pub const PRECISION_THREAD_NAME: &str = "spira-precision";
/// Name of the thread of critical curves.
pub const CURVE_THREAD_NAME: &str = "spira-curve";
/// Time budget of one request on the solver thread: a solve still running after this long
/// stops by itself at its last converged state (reason
/// [`Interruption::Deadline`](crate::solver::interrupt::Interruption::Deadline)), so a path
/// that makes no headway (a free motion, a step that keeps halving) never holds the
/// explorer. A minute is far above a normal step (milliseconds) and below a user's patience.
pub const SOLVE_BUDGET: Duration = Duration::from_secs(60);

/// Handle of the solver thread (and of the thread of work-precision studies): send
/// requests, receive events. Dropping it closes the request channels, and the threads end
/// after their current solve (a study: after its current mesh).
pub struct Worker {
    requests: Sender<Request>,
    cancel: Arc<Mutex<Cancel>>,
    precision: Latest<Request>,
    curve: Latest<Request>,
    /// The interrupt of the curve running now.
    curve_running: Arc<Running>,
    pub events: Receiver<WorkerEvent>,
    thread: Option<JoinHandle<()>>,
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
        let curve_running = Arc::new(Running::default());
        let theirs = Arc::clone(&curve_running);
        let curve = Latest::spawn(CURVE_THREAD_NAME, tx.clone(), move |r, ctx| {
            run_curve(r, ctx, &theirs)
        })?;
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
            curve,
            curve_running,
            events,
            thread: Some(thread),
        })
    }

    /// Queues a request (a work-precision study on its own thread); false if the thread
    /// that takes it has stopped.
    pub fn send(&self, request: Request) -> bool {
        match request.job {
            Job::Precision(_) => self.precision.submit(request),
            Job::Curve(_) => {
                // the curve in progress is of no more use
                self.curve_running.cancel(request.seq.saturating_sub(1));
                self.curve.submit(request)
            }
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

    /// Cancels the critical curves of requests up to sequence number `through`: the one in
    /// progress stops at its last converged point (its rows so far are reported), one still
    /// to start reports at once that it was cancelled.
    pub fn cancel_curve(&self, through: u64) {
        self.curve_running.cancel(through);
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
        self.curve_running.cancel(u64::MAX);
        self.curve.close();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
