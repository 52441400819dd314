//! The solver thread's loop: take the pending requests, keep those the later ones do not
//! replace, run the next one under its interrupt, send its answers.

use super::cancel::Cancel;
use super::event::WorkerEvent;
use super::job::{coalesce, Request};
use super::solver::Solver;
use crate::simulation::Simulation;
use crate::solver::interrupt::{Interrupt, Interruption};
use std::collections::VecDeque;
use std::panic::{self, AssertUnwindSafe};
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Serves requests from `rx` until the channel closes (or nobody listens on `tx`).
pub(super) fn serve(rx: Receiver<Request>, tx: Sender<WorkerEvent>, cancel: Arc<Mutex<Cancel>>) {
    let mut solver = Solver::new();
    let mut queue = VecDeque::new();
    loop {
        if !take_pending(&rx, &mut queue) {
            return;
        }
        coalesce(&mut queue);
        let Some(request) = queue.pop_front() else {
            continue;
        };
        let (generation, seq) = (request.generation, request.seq);
        let Some(interrupt) = begin(&cancel, seq) else {
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
            job: request.job.describe(solver.symbol()),
        };
        if tx.send(started).is_err() {
            return;
        }
        solver.watch(&interrupt, &tx, generation, seq);
        let events = run_guarded(&mut solver, request);
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

/// Waits for a request when `queue` is empty, then takes every request already sent;
/// false when the channel is closed.
fn take_pending(rx: &Receiver<Request>, queue: &mut VecDeque<Request>) -> bool {
    if queue.is_empty() {
        match rx.recv() {
            Ok(r) => queue.push_back(r),
            Err(_) => return false,
        }
    }
    loop {
        match rx.try_recv() {
            Ok(r) => queue.push_back(r),
            Err(TryRecvError::Empty) => return true,
            Err(TryRecvError::Disconnected) => return false,
        }
    }
}

/// The interrupt of request `seq`, with the time budget as its deadline, registered as the
/// running one; `None` when the request was cancelled before it started.
fn begin(cancel: &Mutex<Cancel>, seq: u64) -> Option<Interrupt> {
    let mut c = Cancel::lock(cancel);
    if seq <= c.through {
        c.running = None;
        None
    } else {
        let i = Interrupt::new().with_deadline(Some(Instant::now() + c.budget));
        c.running = Some((seq, i.clone()));
        Some(i)
    }
}

/// Runs `request` on `solver`. A panic in the core must not take the explorer down: it is
/// reported as a failure and the simulation, whose state can no longer be trusted, dropped.
fn run_guarded(solver: &mut Solver, request: Request) -> Vec<WorkerEvent> {
    let (generation, seq) = (request.generation, request.seq);
    match panic::catch_unwind(AssertUnwindSafe(|| solver.run(request))) {
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
    }
}
