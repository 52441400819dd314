//! Continuation in a load parameter `λ`: step-length control, the errors that stop a path,
//! and the statistics of its work.

use super::newton::{NewtonError, NewtonSettings};
use std::time::Duration;

/// Step-length control of the continuation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuationSettings {
    /// First internal step in `λ`.
    pub initial_step: f64,
    /// Smallest step before giving up (or changing strategy).
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Newton iterations aimed at: fewer grow the step, more shrink it.
    pub target_iterations: usize,
    /// Switch to pseudo-arclength steps when natural ones fail at the smallest step.
    pub arclength_fallback: bool,
    /// Count unstable directions at every converged step and locate critical points.
    pub track_stability: bool,
    /// Also compute the lowest eigenvalue at every output point (inverse iteration: the
    /// costliest part of the stability analysis).
    pub lowest_eigenvalue: bool,
    /// Critical points are located to this relative tolerance in the step.
    pub critical_tolerance: f64,
    pub newton: NewtonSettings,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings {
            initial_step: 0.01,
            min_step: 1e-6,
            max_step: 0.05,
            target_iterations: 6,
            arclength_fallback: true,
            track_stability: true,
            lowest_eigenvalue: true,
            critical_tolerance: 1e-9,
            newton: NewtonSettings::default(),
        }
    }
}

/// The continuation could not reach its target; the last converged state is kept.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("continuation stopped at eps = {eps:.6} ({control} parameter {reached:.6}, target {target:.6}): {reason}")]
pub struct SolveError {
    pub control: &'static str,
    /// Last converged load parameter.
    pub reached: f64,
    /// Compression ratio of the last converged state.
    pub eps: f64,
    pub target: f64,
    /// The last step tried.
    pub step: f64,
    pub reason: StopReason,
}

/// Why a continuation stopped.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum StopReason {
    #[error("a step of {step:.2e} failed: {cause}")]
    Newton { step: f64, cause: NewtonError },
    #[error("the path turned back (a limit point) and does not reach the target within {steps} arclength steps")]
    TurnedBack { steps: usize },
    #[error("switching branch needs the full model: a symmetric pair cannot follow a mode that breaks the symmetry")]
    SymmetricPair,
    #[error("there is no critical point {index} to switch branch at")]
    NoCriticalPoint { index: usize },
}

/// Counters of a continuation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Statistics {
    pub steps: usize,
    pub rejected: usize,
    pub iterations: usize,
    pub factorisations: usize,
    /// Arclength steps among `steps`.
    pub arclength_steps: usize,
    pub time: Duration,
}
