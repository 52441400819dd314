//! The mechanics against numbers that do not come from spira: closed forms, finite
//! differences, convergence orders, the symmetric pair against the full model
//! (`cargo test --release --test physics`).

mod beam;
mod bulk;
mod cell;
mod critical_curves;
mod free_motion;
mod imperfection;
mod joints;
mod loads;
mod mirror;
mod precision;
mod robustness;
mod rods;
mod sliding;
mod stability;
mod symmetry;
