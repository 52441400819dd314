//! The tables of a cell's stability (docs/theory.md §8): `dispersion.csv`, the lowest
//! eigenvalue of every block `H(p, k)` at every output step, and `bands.csv`, the unstable
//! bands in `k` of every wavenumber.

use super::csv::{format, table};
use crate::simulation::cell::StepDispersion;
use serde::Serialize;

/// A row of `dispersion.csv`.
#[derive(Serialize, Default)]
struct DispersionRow {
    step: usize,
    p: usize,
    #[serde(serialize_with = "format::e10")]
    k: f64,
    #[serde(serialize_with = "format::opt_e6")]
    lowest_eig: Option<f64>,
}

/// `dispersion.csv`: `step,p,k,lowest_eig` for every output step, wavenumber and phase.
pub fn dispersion_csv(case: &str, steps: &[StepDispersion]) -> String {
    let comments = [
        format!("spira dispersion of the tube cell, case {case}"),
        "p: circumferential wavenumber (0..m-1); k: axial Bloch phase (rad per cell: the perturbation is exp(i(2 pi p j/m + k l)) in cell (j, l), l counting cells along the screw that carries a crossing onto the next); lowest_eig: lowest eigenvalue of the block H(p, k) (J/m, metric of nodal rotations; negative: unstable); (p, k) and (m-p, -k) are conjugate; at p = 1, k = pi/m lives the tube's rigid translation across its axis, eigenvalue 0".to_string(),
    ];
    let rows = steps.iter().flat_map(|s| {
        let d = &s.dispersion;
        d.lowest.iter().enumerate().flat_map(move |(p, row)| {
            d.phases
                .iter()
                .zip(row)
                .map(move |(&k, &lowest_eig)| DispersionRow {
                    step: s.step,
                    p,
                    k,
                    lowest_eig,
                })
        })
    });
    table(&comments, rows)
}

/// A row of `bands.csv`.
#[derive(Serialize, Default)]
struct BandRow {
    step: usize,
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    p: usize,
    #[serde(serialize_with = "format::e10")]
    k_from: f64,
    #[serde(serialize_with = "format::e10")]
    k_to: f64,
    /// Whether wavenumber `p` had no unstable band at the step before.
    opens: bool,
}

/// `bands.csv`: every unstable band in `k` of every wavenumber at every output step, and
/// whether it opened since the step before.
pub fn bands_csv(case: &str, steps: &[StepDispersion]) -> String {
    let comments = [
        format!("spira unstable bands of the tube cell, case {case}"),
        "p: circumferential wavenumber; k_from, k_to: the band of axial Bloch phases (rad per cell) where the lowest eigenvalue of H(p, k) is negative, its ends placed linearly between the phases of dispersion.csv; opens: p had no band at the step before (a critical state lies between the two steps, at the phases of the band)".to_string(),
    ];
    let mut rows = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        for p in 0..s.dispersion.lowest.len() {
            let before = i
                .checked_sub(1)
                .is_some_and(|j| !steps[j].dispersion.unstable_bands(p).is_empty());
            for (k_from, k_to) in s.dispersion.unstable_bands(p) {
                rows.push(BandRow {
                    step: s.step,
                    eps: s.eps,
                    p,
                    k_from,
                    k_to,
                    opens: !before,
                });
            }
        }
    }
    table(&comments, rows)
}
