//! `beam.csv`: the infinite tube as a beam at every output step of a cell's run
//! (docs/theory.md §8), and its line in the run's summary.

use super::csv::{format, table};
use crate::simulation::beam::{column_turns, StepBeam};
use serde::Serialize;

/// A row of `beam.csv`.
#[derive(Serialize, Default)]
struct BeamRow {
    step: usize,
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    #[serde(serialize_with = "format::e10")]
    twist: f64,
    #[serde(serialize_with = "format::e10")]
    force: f64,
    #[serde(serialize_with = "format::e10")]
    torque: f64,
    #[serde(serialize_with = "format::e10")]
    radius: f64,
    #[serde(serialize_with = "format::e10")]
    axial: f64,
    #[serde(serialize_with = "format::e10")]
    torsional: f64,
    #[serde(serialize_with = "format::opt_e10")]
    bending: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    bending_curvature: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    euler_turns: Option<f64>,
    #[serde(serialize_with = "format::e10")]
    radial: f64,
    #[serde(serialize_with = "format::e10")]
    twist_coupling: f64,
    #[serde(serialize_with = "format::e10")]
    radius_coupling: f64,
}

/// `beam.csv`: the tube's effective stiffnesses per unit length at every output step.
pub fn beam_csv(case: &str, steps: &[StepBeam]) -> String {
    let comments = [
        format!("spira beam of the tube cell, case {case}"),
        "the infinite tube as a beam, per unit of its current length, strains counted on the current tube (dh/h, twist per length tau = phi/h); eps: axial strain (h0-h)/h0; twist: tau (rad/m); force: the tube's axial force F (N, all n rods, tension positive); torque: T (N m); radius: mean radius a (m); axial: EA = dF/d(dh/h) (N); torsional: GJ = dT/dtau (N m^2); bending: EI (N m^2), the long-wave limit of the energy of the tube's bending wave (the Bloch block of the translation across the axis, its axis amplitude held; empty where the fits of two phase steps disagree); bending_curvature: EI = dM/dkappa (N m^2) at kappa = 0 by a curvature imposed on the tube, exact from the constrained tangent of its bending cell (every rod over one axial period, periodic under a rotation about a transverse axis; held axial strain; the axis the arc-length mean of the rods, as for bending; empty under a twist and with sliding crossings); euler_turns: the length in turns of the helices, pi sqrt(EI/P)/(turn rise), at which a pinned-pinned column of the tube buckles under its compression P = -F (K = 1; divide by the effective length factor K of other ends: 0.5 clamped-clamped, 2 clamped-free; empty unless compressed); radial: -dq/da at held F and twist (N/m^2, q the pressure per rod in N/m); twist_coupling: dT/d(dh/h) = dF/dtau (N m); radius_coupling: da/d(dh/h) at held pressure and twist (m); all but bending exact from the cell's constrained tangent, bending to the fit's 1e-6 or better".to_string(),
    ];
    let rows = steps.iter().map(|s| {
        let b = &s.stiffness;
        BeamRow {
            step: s.step,
            eps: b.eps,
            twist: b.twist,
            force: b.force,
            torque: b.torque,
            radius: b.radius,
            axial: b.axial,
            torsional: b.torsional,
            bending: s.bending,
            bending_curvature: s.bending_curvature,
            euler_turns: column_turns(s, 1.0),
            radial: b.radial,
            twist_coupling: b.twist_coupling,
            radius_coupling: b.radius_coupling,
        }
    });
    table(&comments, rows)
}

/// The run summary's line: the beam at the first and the last output step.
pub fn beam_summary(steps: &[StepBeam]) -> Option<String> {
    let line = |s: &StepBeam| {
        let b = &s.stiffness;
        let bending = s
            .bending
            .map_or("EI not found".to_string(), |ei| format!("EI {ei:.4} N m2"));
        let curvature = match (s.bending_curvature, &s.bending_curvature_refused) {
            (Some(ei), _) => format!("EI by curvature {ei:.4} N m2"),
            (None, Some(why)) => format!("no EI by curvature ({why})"),
            (None, None) => "EI by curvature not found".to_string(),
        };
        format!(
            "eps = {:.4}: EA {:.6e} N, GJ {:.6e} N m2, {bending}, {curvature}, F {:.6e} N",
            b.eps, b.axial, b.torsional, b.force
        )
    };
    let (first, last) = (steps.first()?, steps.last()?);
    Some(format!(
        "the tube as a beam (beam.csv): at {}; at {}",
        line(first),
        line(last)
    ))
}
