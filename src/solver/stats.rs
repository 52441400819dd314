//! What a continuation has done: counters returned to the caller.

use std::time::Duration;

/// Counters of a continuation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Statistics {
    /// Accepted internal steps.
    pub steps: usize,
    /// Rejected trial steps.
    pub rejected: usize,
    /// Newton iterations of accepted solves.
    pub iterations: usize,
    /// Numeric factorisations of the Jacobian (LU).
    pub factorisations: usize,
    /// Arclength steps among `steps`.
    pub arclength_steps: usize,
    /// Wall time spent in correctors.
    pub time: Duration,
}
