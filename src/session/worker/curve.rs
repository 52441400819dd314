//! Critical curves of the explorer's scene on their own thread, a
//! [`Latest`](crate::session::latest::Latest) job: the scene's first critical point
//! continued in a design key on both sides of its value, each row reported as it is found.
//! A newer request, or a cancel, stops the curve at its last converged point.

use super::event::{CurveDone, WorkerEvent};
use super::job::{CurveJob, Job, Request};
use crate::session::latest::Context;
use crate::simulation::curve::{design_curve, CurveError, CurveProgress, CurveRow, Watch};
use crate::solver::interrupt::Interrupt;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

/// The curve running now: its request's sequence number and the interrupt of the side in
/// progress, and the last sequence number cancelled (a curve also raises its interrupt
/// itself where the case refuses a value, so the interrupt alone does not say).
#[derive(Debug, Default)]
pub(super) struct Running {
    side: Mutex<Option<Interrupt>>,
    seq: AtomicU64,
    through: AtomicU64,
}

impl Running {
    /// Cancels the curves of requests up to `through`: the one running stops at its last
    /// converged point, one still to start reports at once.
    pub(super) fn cancel(&self, through: u64) {
        self.through.fetch_max(through, Ordering::SeqCst);
        if self.is_cancelled() {
            if let Some(i) = self.lock().as_ref() {
                i.raise();
            }
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Interrupt>> {
        self.side.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// A fresh interrupt for the next side, raised at once if the curve is cancelled.
    fn next_side(&self) -> Interrupt {
        let i = Interrupt::new();
        *self.lock() = Some(i.clone());
        if self.is_cancelled() {
            i.raise();
        }
        i
    }

    fn is_cancelled(&self) -> bool {
        self.seq.load(Ordering::SeqCst) <= self.through.load(Ordering::SeqCst)
    }
}

/// A critical curve on the curve thread: the side below the key's value, then the side
/// above, each row sent as it comes, then the whole curve (or why there is none).
pub(super) fn run_curve(request: Request, ctx: &Context<Request, WorkerEvent>, running: &Running) {
    let Request {
        generation,
        seq,
        job: Job::Curve(job),
    } = request
    else {
        return;
    };
    running.seq.store(seq, Ordering::SeqCst);
    let done = panic::catch_unwind(AssertUnwindSafe(|| {
        both_sides(&job, running, &mut |progress| {
            if ctx.is_cancelled() {
                running.cancel(seq);
            }
            ctx.send(WorkerEvent::CurveProgress {
                generation,
                seq,
                progress,
            });
        })
    }));
    *running.lock() = None;
    let cancelled = running.is_cancelled() || ctx.is_cancelled();
    let outcome = match done {
        Ok(Ok(mut d)) => {
            d.cancelled = cancelled;
            Ok(d)
        }
        Ok(Err(e)) if cancelled => Err(format!("cancelled ({e})")),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("the critical curve panicked".to_string()),
    };
    ctx.send(WorkerEvent::Curve {
        generation,
        seq,
        outcome,
    });
}

/// The curve of `job` from the key's value down to `value (1 − width)`, then up to
/// `value (1 + width)`, its rows in increasing order of the key; progress counts the rows
/// of both sides.
fn both_sides(
    job: &CurveJob,
    running: &Running,
    progress: &mut dyn FnMut(CurveProgress),
) -> Result<CurveDone, CurveError> {
    let value = job.case.design_value(job.key);
    let total = 2 * job.rows_each - 1;
    let mut rows: Vec<CurveRow> = Vec::new();
    let mut stopped = Vec::new();
    let mut label = String::new();
    for (side, end) in [
        (0, value * (1.0 - job.width)),
        (1, value * (1.0 + job.width)),
    ] {
        if running.is_cancelled() {
            break;
        }
        let before = rows.len();
        let mut relay = |p: CurveProgress| match p {
            // the start is the same point on both sides: counted once
            CurveProgress::Row { done, .. } if side == 1 && done == 1 => {}
            CurveProgress::Row { row, done, .. } => progress(CurveProgress::Row {
                row,
                done: side * (job.rows_each - 1) + done,
                total,
            }),
            locating => progress(locating),
        };
        let mut watch = Watch {
            interrupt: running.next_side(),
            progress: &mut relay,
        };
        let curve = match design_curve(&job.case, job.key, value, end, job.rows_each, &mut watch) {
            Ok(c) => c,
            // the other side's rows stand
            Err(e) if !rows.is_empty() => {
                stopped.push(e.to_string());
                continue;
            }
            Err(e) => return Err(e),
        };
        let skip = usize::from(side == 1 && before > 0);
        rows.extend(curve.rows.into_iter().skip(skip));
        stopped.extend(curve.stopped.map(|e| e.to_string()));
        label = curve.parameter_label;
    }
    rows.sort_by(|a, b| a.value.total_cmp(&b.value));
    Ok(CurveDone {
        key: job.key,
        rows,
        parameter_label: label,
        stopped,
        cancelled: false,
    })
}
