//! The explorer's job layer, without a terminal: the solver thread that owns the
//! [`Simulation`](crate::simulation::Simulation) and answers requests with events
//! ([`worker`]), and the generic "latest request wins" background job it runs its
//! work-precision studies on ([`latest`]). The terminal UI ([`crate::tui`]) sits on top.

mod check;
mod error;
pub mod export;
pub mod latest;
pub mod replay;
pub mod script;
pub mod worker;
