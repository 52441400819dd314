//! The mesh of a case that gives an accuracy target instead of one: chosen from coarse
//! pilot solves, said on the way.

use anyhow::{anyhow, Result};
use spira::case::Case;
use spira::model::loading::Control;
use spira::output::precision::ChoiceReport as _;
use spira::results::LoadPoint;
use spira::solver::interrupt::Interrupt;
use spira::study::{resolve_accuracy_with, AccuracyError, MeshChoice, Subject};

/// The case with its mesh: when it gives an accuracy instead, the mesh chosen for it, said
/// on the way; `interrupt` stops the choice (nothing chosen, the error says so).
pub fn resolve(case: Case, interrupt: &Interrupt) -> Result<(Case, Option<MeshChoice>)> {
    let Some(acc) = case.discretisation.accuracy else {
        return Ok((case, None));
    };
    println!(
        "choosing the mesh for accuracy {:e} on the response ({}) and the first critical point from two coarse solves per element order:",
        acc.target,
        Subject::Path(Box::new(case.clone())).response_label()
    );
    let (resolved, choice) =
        resolve_accuracy_with(&case, Some(interrupt)).map_err(|e| match e {
            AccuracyError::Interrupted { .. } => anyhow!("{e}; nothing was solved or written"),
            e => e.into(),
        })?;
    if let Some(c) = &choice {
        for line in c.pilot_lines() {
            println!("  {line}");
        }
        println!(
            "  chosen: {} elements, {} per rod, predicted error {:.1e} ({:.0} ms of pilot solves)",
            c.order.name(),
            c.elements,
            c.estimated_error,
            c.cost.as_secs_f64() * 1e3
        );
    }
    Ok((resolved, choice))
}

/// The response an accuracy refers to: `Fz/(n Pcrit)` under displacement control, the
/// compression ratio `ε` under load control.
pub fn response(case: &Case, point: &LoadPoint) -> f64 {
    match case.loading.control {
        Control::Displacement => point.load[2],
        Control::Force => point.compression_ratio,
    }
}
