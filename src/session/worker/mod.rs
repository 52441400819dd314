//! The solver thread of the explorer: it owns the
//! [`Simulation`](crate::simulation::Simulation), takes [`Request`]s over a channel and
//! answers with [`WorkerEvent`]s carrying cloned results, so the UI thread never waits for a
//! solve (gitui's async jobs, bottom's event enum).
//!
//! Scheduling: while a solve runs, requests pile up in a queue. Every step asked for is
//! solved in turn (each is a point of the path, however quickly the keys were pressed); a
//! change of the conditions or a branch switch directly followed by another of its kind is
//! dropped in favour of the later one, and a pending [`Job::Start`] drops everything queued
//! before it. A cancel answers the queued requests without solving them. The thread stops
//! when the request channel closes.
//!
//! Work-precision studies ([`Job::Precision`]) run on a second thread of their own, a
//! [`Latest`](crate::session::latest::Latest) job, so that a study of many meshes never
//! holds up the user's steps; there the last request wins too, and a newer request stops the
//! study in progress after its current mesh.
//!
//! Critical curves of the scene ([`Job::Curve`]) run on a third thread, a `Latest` job
//! as well, which a cancel (`Worker::cancel_curve`) or a newer request stops at its last
//! converged point.
//!
//! One file per job: the handle the explorer holds (`handle`), the requests and their
//! scheduling (`job`), the answers (`event`), the cancels shared with the thread
//! (`cancel`), the thread's loop (`serve`), the solves it runs (`solver`), the
//! failures in the user's terms (`failure`), the studies (`precision`) and the curves (`curve`).

mod cancel;
mod curve;
mod event;
mod failure;
mod handle;
mod job;
mod precision;
mod serve;
mod solver;

pub use event::{CriticalMode, CurveDone, Solved, WorkerEvent};
pub use handle::{Worker, CURVE_THREAD_NAME, PRECISION_THREAD_NAME, SOLVE_BUDGET, THREAD_NAME};
pub use job::{coalesce, CurveJob, Job, Part, Request};
pub use precision::PRECISION_REPEATS;
pub use solver::{run_jobs, Runner, PROGRESS_INTERVAL};
