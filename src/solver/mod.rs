//! Solvers: sparse linear algebra, Newton on the KKT system, continuation.

pub mod continuation;
pub mod linear;
pub mod newton;
