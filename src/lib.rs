//! spira: mechanics of tubular assemblies of helical Kirchhoff rods.
//!
//! Data flows one way: case file → [`model`] → [`discretisation`] → [`solver`] →
//! [`results`] → outputs and screens. The explorer's jobs ([`session`]) sit below its
//! screen ([`tui`]), which only sees their requests and events.

// Element and assembly loops index several arrays by the same node and component
// numbers, as the equations do; iterator chains would hide that.
#![allow(clippy::needless_range_loop)]

pub mod case;
pub mod chart;
pub mod discretisation;
pub mod model;
pub mod output;
pub mod precision;
pub mod results;
pub mod run;
pub mod session;
pub mod simulation;
pub mod solver;
pub mod tui;
