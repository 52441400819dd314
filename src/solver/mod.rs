//! Solvers: sparse linear algebra, Newton on the KKT system, continuation.

pub mod continuation;
pub mod inertia;
pub mod linear;
pub mod newton;
