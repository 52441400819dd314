//! spira: mechanics of tubular assemblies of helical Kirchhoff rods.
//!
//! Data flows one way, and a module imports only from the layers before it: [`model`] →
//! [`results`] (plain data) → [`discretisation`] → [`solver`] → [`case`] → [`simulation`] →
//! [`run`] → [`study`] → [`output`] → the explorer's jobs ([`session`], no terminal) → its
//! screen ([`tui`]) and the command line.

// Element and assembly loops index several arrays by the same node and component
// numbers, as the equations do; iterator chains would hide that.
#![allow(clippy::needless_range_loop)]

pub mod case;
pub mod discretisation;
pub mod model;
pub mod output;
pub mod results;
pub mod run;
pub mod session;
pub mod simulation;
pub mod solver;
pub mod study;
pub mod sweep;
pub mod tui;
