//! Stopping a long solve from outside: a flag another thread raises (the user cancels) and
//! an optional deadline (a time budget), checked by Newton between iterations and by the
//! continuation between steps. The path stops at its last converged state.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Why a solve was interrupted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Interruption {
    #[error("cancelled")]
    Cancelled,
    #[error("its time budget ran out")]
    Deadline,
}

/// A cancellation flag shared between threads, with an optional deadline.
#[derive(Clone, Debug, Default)]
pub struct Interrupt {
    flag: Arc<AtomicBool>,
    deadline: Option<Instant>,
}

impl Interrupt {
    pub fn new() -> Interrupt {
        Interrupt::default()
    }

    /// The same flag, stopping also at `deadline`.
    pub fn with_deadline(&self, deadline: Option<Instant>) -> Interrupt {
        Interrupt {
            flag: Arc::clone(&self.flag),
            deadline,
        }
    }

    /// Asks the solve to stop (from any thread).
    pub fn raise(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }

    /// Lowers the flag for the next solve.
    pub fn clear(&self) {
        self.flag.store(false, Ordering::Relaxed);
    }

    /// Why the solve must stop now, if it must.
    pub fn check(&self) -> Option<Interruption> {
        if self.flag.load(Ordering::Relaxed) {
            Some(Interruption::Cancelled)
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Some(Interruption::Deadline)
        } else {
            None
        }
    }
}
