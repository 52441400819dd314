//! The parts on their own: the crate's layers, the case reader and its fuzz, and the
//! continuation engine on canonical problems (`cargo test --release --test unit`).

#[path = "../common/mod.rs"]
mod common;

mod architecture;
mod case_settings;
mod cases;
mod continuation;
mod critical_curve;
mod docs;
mod fuzz_cases;
mod fuzz_sessions;
