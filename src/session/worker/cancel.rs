//! What cancelling shares between the UI and the solver thread.

use crate::solver::interrupt::Interrupt;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::Duration;

/// What cancelling shares between the UI and the solver thread: the interrupt of the job
/// running now (and its request's sequence number) and the last sequence number cancelled.
/// One lock, so a cancel can never fall between two jobs and be lost or hit the wrong one.
#[derive(Debug, Default)]
pub(super) struct Cancel {
    /// The time budget of the requests started from now on.
    pub(super) budget: Duration,
    pub(super) running: Option<(u64, Interrupt)>,
    /// Requests up to this sequence number are cancelled (the running one is interrupted,
    /// queued ones are answered without a solve).
    pub(super) through: u64,
}

impl Cancel {
    pub(super) fn lock(cancel: &Mutex<Cancel>) -> MutexGuard<'_, Cancel> {
        cancel.lock().unwrap_or_else(PoisonError::into_inner)
    }
}
