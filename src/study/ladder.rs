//! Ladders of meshes and the study run on them: every rung solved and timed, the reference
//! (closed form or Richardson's extrapolation), the errors of every measure against it and
//! the orders they show.

use super::subject::{Measure, Subject, Values, ORDERS};
use crate::discretisation::shape::Order;
use crate::simulation::SolveError;
use crate::solver::interrupt::{Interrupt, Interruption};
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

/// One mesh of a ladder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rung {
    pub order: Order,
    /// Elements per rod asked for (the mesh puts at least this many).
    pub elements: usize,
}

/// The meshes of a study: for each order, element counts doubling from the coarsest.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ladder {
    pub rungs: Vec<Rung>,
}

impl Ladder {
    /// `rungs_linear` and `rungs_quadratic` meshes doubling from [`Subject::coarsest`].
    pub fn doubling(subject: &Subject, rungs_linear: usize, rungs_quadratic: usize) -> Ladder {
        let mut rungs = Vec::new();
        for (order, count) in [
            (Order::Linear, rungs_linear),
            (Order::Quadratic, rungs_quadratic),
        ] {
            let base = subject.coarsest(order);
            rungs.extend((0..count).map(|k| Rung {
                order,
                elements: base << k,
            }));
        }
        Ladder { rungs }
    }

    /// The ladder `spira precision` uses: 5 linear and 4 quadratic meshes.
    pub fn standard(subject: &Subject) -> Ladder {
        Ladder::doubling(subject, 5, 4)
    }

    fn coarsest_elements(&self) -> usize {
        self.rungs.iter().map(|r| r.elements).min().unwrap_or(1)
    }
}

/// One solved rung of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct RungResult {
    pub rung: Rung,
    /// Best wall time of the whole solve over the timed runs.
    pub time: Duration,
    /// The measured values, or why the solve failed.
    pub values: Result<Values, SolveError>,
    /// Relative error of each [`Measure`] (indexed as [`Measure::ALL`]) against the
    /// reference, where both have the value.
    pub errors: [Option<f64>; 3],
    /// Observed order of each measure between the previous rung of the same order and
    /// this one: `log(e_prev/e) / log(h_prev/h)`.
    pub observed: [Option<f64>; 3],
    /// The observed orders of this rung are those of the reference's construction
    /// (the finest quadratic pair of a Richardson reference), not a measurement.
    pub by_construction: bool,
}

impl RungResult {
    pub fn error(&self, m: Measure) -> Option<f64> {
        self.errors[m.index()]
    }
    pub fn observed(&self, m: Measure) -> Option<f64> {
        self.observed[m.index()]
    }
    /// Elements per rod of the mesh (as asked when the solve failed).
    pub fn elements(&self) -> usize {
        self.values
            .as_ref()
            .map_or(self.rung.elements, |v| v.elements)
    }
}

/// What the errors are measured against.
#[derive(Clone, Debug, PartialEq)]
pub enum Reference {
    /// The subject's closed form.
    ClosedForm(String),
    /// Richardson extrapolation `Q + (Q − Q_coarse)/(2^k − 1)` of the two finest solutions
    /// of `order`, with the theoretical order `k` of each measure.
    Richardson {
        order: Order,
        /// Elements per rod of the two solutions, coarse then fine.
        elements: [usize; 2],
        /// The exponent used for each measure.
        exponents: [f64; 3],
        /// Order observed over the three finest solutions of `order`
        /// (`log2(|Q1 − Q2| / |Q2 − Q3|)`), independent of the reference: a check that the
        /// solutions are in the asymptotic range the extrapolation assumes.
        check: [Option<f64>; 3],
    },
}

/// A work-precision study.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    pub name: String,
    pub description: String,
    pub response_label: String,
    pub reference: Reference,
    /// The reference values.
    pub reference_values: Values,
    pub rungs: Vec<RungResult>,
    /// Timed runs per rung after the warm-up.
    pub repeats: usize,
    /// The exact curvature is uniform ([`Subject::uniform_curvature`]).
    pub uniform_curvature: bool,
}

/// Why a study has no result.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StudyError {
    #[error("the study was cancelled")]
    Cancelled,
    /// Stopped from outside (a signal) after `done` of `total` meshes.
    #[error("the study was {why} after {done} of {total} meshes")]
    Interrupted {
        why: Interruption,
        done: usize,
        total: usize,
    },
    #[error("no reference: {0}")]
    NoReference(String),
}

/// A rung of a study solved, with how many are done: what a study says after each rung.
#[derive(Clone, Debug)]
pub struct RungFinished<'a> {
    pub done: usize,
    pub total: usize,
    pub last: &'a RungResult,
}

/// Runs a study: every rung of `ladder` solved once as a warm-up (whose values are kept)
/// and `repeats` times timed; then the reference, the errors and the observed orders.
/// `on_rung` is called after each rung and may stop the study.
pub fn run_study(
    subject: &Subject,
    ladder: &Ladder,
    repeats: usize,
    on_rung: impl FnMut(&RungFinished) -> ControlFlow<()>,
) -> Result<Study, StudyError> {
    run_study_with(subject, ladder, repeats, None, on_rung)
}

/// [`run_study`], stopped when `interrupt` is raised (the solves check it between Newton
/// iterations): [`StudyError::Interrupted`] with the meshes done.
pub fn run_study_with(
    subject: &Subject,
    ladder: &Ladder,
    repeats: usize,
    interrupt: Option<&Interrupt>,
    mut on_rung: impl FnMut(&RungFinished) -> ControlFlow<()>,
) -> Result<Study, StudyError> {
    let probes = subject.vertices(ladder.coarsest_elements());
    let mut rungs: Vec<RungResult> = Vec::new();
    let stopped = |done: usize| {
        interrupt
            .and_then(Interrupt::check)
            .map(|why| StudyError::Interrupted {
                why,
                done,
                total: ladder.rungs.len(),
            })
    };
    for (k, &rung) in ladder.rungs.iter().enumerate() {
        // the warm-up: its values are kept, its time only when nothing is timed
        let t0 = Instant::now();
        let values = subject.solve_with(rung.order, rung.elements, &probes, interrupt);
        if let Some(e) = stopped(k) {
            return Err(e);
        }
        let mut time = t0.elapsed();
        if values.is_ok() {
            let mut best: Option<Duration> = None;
            for _ in 0..repeats {
                let t = Instant::now();
                let again = subject.solve_with(rung.order, rung.elements, &probes, interrupt);
                if let Some(e) = stopped(k) {
                    return Err(e);
                }
                let dt = t.elapsed();
                if again.is_ok() {
                    best = Some(best.map_or(dt, |b| b.min(dt)));
                }
            }
            time = best.unwrap_or(time);
        }
        rungs.push(RungResult {
            rung,
            time,
            values,
            errors: [None; 3],
            observed: [None; 3],
            by_construction: false,
        });
        let progress = RungFinished {
            done: k + 1,
            total: ladder.rungs.len(),
            last: rungs.last().expect("just pushed"),
        };
        if on_rung(&progress).is_break() {
            return Err(StudyError::Cancelled);
        }
    }
    let (reference, reference_values) = match subject.exact(&probes) {
        Some(v) => (
            Reference::ClosedForm(subject.closed_form().unwrap_or_default()),
            v,
        ),
        None => richardson(&rungs, subject.uniform_curvature())?,
    };
    measure_errors(&mut rungs, &reference_values);
    if let Reference::Richardson { order, .. } = &reference {
        let finest = rungs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.rung.order == *order && r.values.is_ok())
            .map(|(i, _)| i)
            .next_back();
        if let Some(i) = finest {
            rungs[i].by_construction = true;
        }
    }
    Ok(Study {
        name: subject.name(),
        description: subject.describe(),
        response_label: subject.response_label(),
        reference,
        reference_values,
        rungs,
        repeats,
        uniform_curvature: subject.uniform_curvature(),
    })
}

/// The reference by Richardson extrapolation of the two finest solutions of the highest
/// order that has two.
fn richardson(rungs: &[RungResult], uniform: bool) -> Result<(Reference, Values), StudyError> {
    for order in ORDERS.iter().rev() {
        let solved: Vec<&Values> = rungs
            .iter()
            .filter(|r| r.rung.order == *order)
            .filter_map(|r| r.values.as_ref().ok())
            .collect();
        if solved.len() < 2 {
            continue;
        }
        let (coarse, fine) = (solved[solved.len() - 2], solved[solved.len() - 1]);
        let ratio = fine.elements as f64 / coarse.elements as f64;
        let exponents = Measure::ALL.map(|m| m.theoretical_order(*order, uniform));
        let extrapolate = |k: f64, q: f64, qc: f64| q + (q - qc) / (ratio.powf(k) - 1.0);
        let curvature = if fine.curvature.len() == coarse.curvature.len() {
            fine.curvature
                .iter()
                .zip(&coarse.curvature)
                .map(|(f, c)| std::array::from_fn(|i| extrapolate(exponents[1], f[i], c[i])))
                .collect()
        } else {
            fine.curvature.clone()
        };
        let critical = match (fine.critical, coarse.critical) {
            (Some(f), Some(c)) => Some(extrapolate(exponents[2], f, c)),
            _ => None,
        };
        let values = Values {
            response: extrapolate(exponents[0], fine.response, coarse.response),
            curvature,
            critical,
            unknowns: 0,
            elements: 0,
        };
        let check = if solved.len() >= 3 {
            let third = solved[solved.len() - 3];
            let diffs = |v: &Values, w: &Values| measured(v, w);
            let (d1, d2) = (diffs(third, coarse), diffs(coarse, fine));
            let r = coarse.elements as f64 / third.elements as f64;
            std::array::from_fn(|i| match (d1[i], d2[i]) {
                // with equal refinement ratios r: |Q1 − Q2| / |Q2 − Q3| = r^k
                (Some(a), Some(b)) if a > 0.0 && b > 0.0 && (r - ratio).abs() < 1e-9 * r => {
                    Some((a / b).ln() / r.ln())
                }
                _ => None,
            })
        } else {
            [None; 3]
        };
        return Ok((
            Reference::Richardson {
                order: *order,
                elements: [coarse.elements, fine.elements],
                exponents,
                check,
            },
            values,
        ));
    }
    Err(StudyError::NoReference(
        "fewer than two meshes of any element order were solved".into(),
    ))
}

/// Relative differences of each measure of `v` from `reference` (None where either lacks
/// it). Response and critical load: `|v − r| / |r|` (absolute when `r = 0`); curvature:
/// `max |κ − κ_r| / max |κ_r|` over rods, probes and components.
pub fn measured(v: &Values, reference: &Values) -> [Option<f64>; 3] {
    let rel = |a: f64, r: f64| {
        let d = (a - r).abs();
        if r.abs() > 0.0 {
            d / r.abs()
        } else {
            d
        }
    };
    let response = rel(v.response, reference.response);
    let curvature = (v.curvature.len() == reference.curvature.len() && !v.curvature.is_empty())
        .then(|| {
            let scale = reference
                .curvature
                .iter()
                .flatten()
                .fold(0.0f64, |m, k| m.max(k.abs()));
            let diff = v
                .curvature
                .iter()
                .zip(&reference.curvature)
                .flat_map(|(a, b)| (0..3).map(move |i| (a[i] - b[i]).abs()))
                .fold(0.0f64, f64::max);
            if scale > 0.0 {
                diff / scale
            } else {
                diff
            }
        });
    let critical = match (v.critical, reference.critical) {
        (Some(a), Some(r)) => Some(rel(a, r)),
        _ => None,
    };
    [Some(response), curvature, critical].map(|e| e.filter(|e| e.is_finite()))
}

fn measure_errors(rungs: &mut [RungResult], reference: &Values) {
    for r in rungs.iter_mut() {
        if let Ok(v) = &r.values {
            r.errors = measured(v, reference);
        }
    }
    for order in ORDERS {
        let idx: Vec<usize> = (0..rungs.len())
            .filter(|&i| rungs[i].rung.order == order && rungs[i].values.is_ok())
            .collect();
        for w in idx.windows(2) {
            let (a, b) = (&rungs[w[0]], &rungs[w[1]]);
            let h_ratio = b.elements() as f64 / a.elements() as f64;
            let observed = std::array::from_fn(|i| match (a.errors[i], b.errors[i]) {
                (Some(ea), Some(eb)) if ea > 0.0 && eb > 0.0 && h_ratio > 1.0 => {
                    Some((ea / eb).ln() / h_ratio.ln())
                }
                _ => None,
            });
            rungs[w[1]].observed = observed;
        }
    }
}

impl Study {
    /// The theoretical order of measure `m` for elements of `order` in this study.
    pub fn theory(&self, m: Measure, order: Order) -> f64 {
        m.theoretical_order(order, self.uniform_curvature)
    }

    /// The observed order of measure `m` between the two finest meshes of `order` that
    /// measure it (not a pair that defines the reference).
    pub fn finest_observed(&self, m: Measure, order: Order) -> Option<f64> {
        self.of_order(order)
            .filter(|r| !r.by_construction)
            .filter_map(|r| r.observed(m))
            .last()
    }

    /// The rungs of one element order, coarse to fine.
    pub fn of_order(&self, order: Order) -> impl Iterator<Item = &RungResult> {
        self.rungs.iter().filter(move |r| r.rung.order == order)
    }

    /// Whether any rung has a value of measure `m`.
    pub fn has(&self, m: Measure) -> bool {
        self.rungs.iter().any(|r| r.error(m).is_some())
    }

    /// The cheapest rung (least time) whose error in the response meets `target`.
    pub fn cheapest_meeting(&self, target: f64) -> Option<&RungResult> {
        self.rungs
            .iter()
            .filter(|r| r.error(Measure::Response).is_some_and(|e| e <= target))
            .min_by_key(|r| r.time)
    }
}
