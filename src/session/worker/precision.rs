//! Work-precision studies on their own thread, a [`Latest`](crate::session::latest::Latest)
//! job: a newer request stops the study in progress after its current mesh.

use super::event::WorkerEvent;
use super::job::{Job, Request};
use crate::session::latest::Context;
use crate::study::{run_study, Ladder, StudyError, Subject};
use std::ops::ControlFlow;
use std::panic::{self, AssertUnwindSafe};

/// Timed runs per mesh of the explorer's work-precision study (after a warm-up each): one,
/// to keep the study short; `spira precision` takes the best of several.
pub const PRECISION_REPEATS: usize = 1;

/// A work-precision study on the precision thread: progress after each mesh, then the
/// study; it stops after the current mesh when a newer request arrives (and then reports
/// nothing).
pub(super) fn run_precision(request: Request, ctx: &Context<Request, WorkerEvent>) {
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
