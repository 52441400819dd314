//! The continuation engine, which knows nothing of rods: sparse linear algebra, Newton's
//! method bordered by the step equation, continuation in a load parameter, critical points
//! and branch switching, stability from the inertia of the KKT matrix. It follows any
//! [`problem::Problem`].

pub mod continuation;
pub mod critical;
pub mod extended;
mod fold;
pub mod interrupt;
pub mod ldl;
pub mod linear;
pub mod newton;
pub mod path_state;
pub mod problem;
pub mod stability;
pub mod stats;
mod step;
pub mod switching;
