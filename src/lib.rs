//! spira: mechanics of tubular assemblies of helical Kirchhoff rods.
//!
//! An assembly is `n` helices of both chiralities, pin-jointed where they cross, each a
//! three-dimensional rod in large deformation (rotations by unit quaternions, quadratic or
//! linear finite elements), loaded along a path by displacement or load control. Along the
//! path spira reports the reactions, shapes, curvatures, energy and the stability of every
//! state, with its critical points located and bifurcated branches followed. The theory is
//! in `docs/theory.md`, the file formats in `docs/output-files.md`.
//!
//! # Entry points
//!
//! A computation goes case → path → outputs:
//!
//! 1. [`case::Case`] reads and checks a case file ([`Case::from_file`](case::Case::from_file))
//!    or text ([`Case::parse`](case::Case::parse)); every key has a default, listed in
//!    `docs/case-files.md` (generated from [`case::KEYS`]).
//! 2. [`run::run_path`] solves the case's load path through the given values of its load
//!    parameter ([`Case::output_parameters`](case::Case::output_parameters)) and returns a
//!    [`run::PathOutcome`]: the load points ([`results::LoadPoint`]), the last state, the
//!    critical points and the bulk of the rods. [`simulation::Simulation`] is the same path
//!    one step at a time, with branch switching and boundary conditions changed on the way
//!    (what the explorer uses).
//! 3. [`output::run_files`] turns an outcome into the CSV tables of `spira run`, and
//!    [`output::write_run`] writes them into a folder, all or nothing.
//!
//! ```
//! use spira::case::Case;
//! use spira::output::{run_files, RunFiles};
//! use spira::run::run_path;
//!
//! // two thesis helices on a coarse mesh, compressed to ε = 0.1 in two output steps
//! let text = "[geometry]\nhelices = 2\n[loading]\ntarget = 0.1\nsteps = 2\n[discretisation]\nelements = 6\n";
//! let case = Case::parse(text, "example.toml", "example")?;
//! let targets = case.output_parameters(case.loading.target, case.loading.steps);
//! let outcome = run_path(&case, &targets, |_point, _time| {})?;
//!
//! let last = outcome.points.last().expect("the natural state at least");
//! assert_eq!(outcome.points.len(), 3); // the natural state and two output steps
//! assert!((last.compression_ratio - 0.1).abs() < 1e-12);
//! assert!(last.load[2] < 0.0); // fz / (n Pcrit): compression
//! assert!(outcome.error.is_none());
//!
//! let files = run_files(&RunFiles::of(&case.name, None, &outcome))?;
//! let (_, load_csv) = files.iter().find(|(name, _)| name == "load.csv").expect("load.csv");
//! assert!(load_csv.contains("step,eps,h,fx,fy,fz"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Layers
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
