//! What a user meets: the `spira` commands run as processes, the explorer (in memory and in
//! a pseudo-terminal), figures, ParaView files, sweeps and the command-line fuzz
//! (`cargo test --release --test faces`), and the tour of the README.

#[path = "../common/mod.rs"]
mod common;

mod cell;
mod cli;
mod critical;
mod figures;
mod fuzz_cli;
mod interrupts;
mod paper_figures;
mod replay;
mod sweep;
mod sweep_input;
mod tour;
mod tui;
mod tui_e2e;
mod vtk;
mod what_if;
