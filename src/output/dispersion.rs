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

/// For a run's summary: where each wavenumber's first unstable band opened (between two
/// output steps) and the bands of the last step, in rad per cell; `None` when no band
/// opened. The count of unstable directions printed step by step is judged on the coarser
/// grid of phases the path uses, which a narrow band can fall between.
pub fn bands_summary(steps: &[StepDispersion]) -> Option<String> {
    let last = steps.last()?;
    let band = |(a, b): (f64, f64)| format!("k {a:.3}–{b:.3}");
    // bands that meet at a phase of the grid (where the gauge holds the rigid translation
    // of the cells, k = π/m for p = 1) are one band
    let bands_of = |s: &StepDispersion, p: usize| {
        let mut merged: Vec<(f64, f64)> = Vec::new();
        for (a, b) in s.dispersion.unstable_bands(p) {
            match merged.last_mut() {
                Some(last) if (a - last.1).abs() < 1e-12 => last.1 = b,
                _ => merged.push((a, b)),
            }
        }
        merged
    };
    let mut opened = Vec::new();
    for p in 0..last.dispersion.lowest.len() {
        let first = steps
            .iter()
            .position(|s| !s.dispersion.unstable_bands(p).is_empty());
        if let Some(i) = first {
            let before = i.checked_sub(1).map_or(0.0, |j| steps[j].eps);
            let bands: Vec<String> = bands_of(&steps[i], p).into_iter().map(band).collect();
            opened.push(format!(
                "p = {p} opens between eps = {before:.6} and {:.6} ({})",
                steps[i].eps,
                bands.join(", ")
            ));
        }
    }
    if opened.is_empty() {
        return None;
    }
    let now: Vec<String> = (0..last.dispersion.lowest.len())
        .flat_map(|p| {
            bands_of(last, p)
                .into_iter()
                .map(move |b| format!("p = {p} {}", band(b)))
        })
        .collect();
    Some(format!(
        "unstable bands of the infinite tube (rad per cell; bands.csv): {}; at eps = {:.6}: {}",
        opened.join("; "),
        last.eps,
        if now.is_empty() {
            "none".to_string()
        } else {
            now.join(", ")
        }
    ))
}
