//! Meshes chosen for an accuracy target: two coarse solves per element order, the error
//! constant estimated from their difference and the theoretical order, and the element order
//! and number of elements that meet the target at the least predicted wall time.

use super::subject::{with_mesh, Measure, Subject, ORDERS};
use crate::case::{AccuracyTarget, Case};
use crate::discretisation::shape::Order;
use crate::solver::interrupt::{Interrupt, Interruption};
use std::time::{Duration, Instant};

/// The mesh is chosen for this fraction of the target: the error estimate holds only
/// asymptotically, so a margin of 2 keeps a slightly pre-asymptotic estimate on the safe
/// side.
pub const SAFETY: f64 = 0.5;
/// Largest mesh considered (elements per rod).
pub use super::subject::MAX_ELEMENTS;
/// Smallest relative accuracy that can be asked for: Newton stops at a residual of 1e-9
/// (N, N m), and on Love's helix the reactions stop converging at about 5e-10 relative, so
/// a smaller target could be neither met nor checked.
pub const ACCURACY_FLOOR: f64 = 1e-9;

/// What two coarse solves of one element order say.
#[derive(Clone, Debug, PartialEq)]
pub struct Pilot {
    pub order: Order,
    /// Elements per rod of the two solves (the second twice the first).
    pub elements: [usize; 2],
    pub response: [f64; 2],
    pub time: [Duration; 2],
    /// Estimated relative error of the finer solve: `|Q2 − Q1| / (2^k − 1) / |Q2|`.
    pub error: f64,
    /// Exponent `k` of the response error, [`Measure::theoretical_order`].
    pub exponent: f64,
    /// The first critical point's load parameter on the two solves and its estimated
    /// relative error, when both solves meet one: the accuracy bounds it as it bounds the
    /// response.
    pub critical: Option<CriticalPilot>,
    /// Elements per rod predicted to meet `SAFETY · target`, if within [`MAX_ELEMENTS`].
    pub needed: Option<usize>,
    /// Predicted wall time at `needed`.
    pub predicted_time: Option<Duration>,
}

/// What the two coarse solves of a pilot say of its first critical point.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalPilot {
    /// Load parameter of the first critical point on each solve.
    pub parameter: [f64; 2],
    /// Estimated relative error of the finer solve's, `|c2 − c1| / (2^k − 1) / |c2|`.
    pub error: f64,
    /// Exponent `k` of its error ([`Measure::Critical`]).
    pub exponent: f64,
}

impl Pilot {
    /// Estimated relative error at `elements` per rod, `e2 (N2/N)^k`, of the response or,
    /// where larger, of the first critical point's load parameter.
    pub fn error_at(&self, elements: usize) -> f64 {
        let at = |error: f64, exponent: f64| {
            error * (self.elements[1] as f64 / elements as f64).powf(exponent)
        };
        let critical = self
            .critical
            .as_ref()
            .map_or(0.0, |c| at(c.error, c.exponent));
        at(self.error, self.exponent).max(critical)
    }
}

/// `|q2 − q1| / (2^k − 1) / |q2|`, the estimated relative error of the finer of two solves
/// of `q` whose error falls as `h^k`; below roundoff the difference says nothing, and it
/// counts as the Newton floor.
fn two_mesh_error(q1: f64, q2: f64, exponent: f64) -> f64 {
    let scale = if q2 != 0.0 { q2.abs() } else { 1.0 };
    ((q2 - q1).abs() / (2f64.powf(exponent) - 1.0) / scale).max(1e-14)
}

/// The mesh chosen for an accuracy target.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshChoice {
    /// Relative accuracy asked for on the response.
    pub target: f64,
    /// What the response is ([`Subject::response_label`]).
    pub response: String,
    pub order: Order,
    /// Elements per rod of the chosen mesh.
    pub elements: usize,
    /// Estimated relative error of the response at the chosen mesh.
    pub estimated_error: f64,
    pub pilots: Vec<Pilot>,
    /// Wall time of the pilot solves.
    pub cost: Duration,
}

impl MeshChoice {
    fn pilot(&self) -> Option<&Pilot> {
        self.pilots.iter().find(|p| p.order == self.order)
    }

    /// The a-posteriori estimate once the chosen mesh is solved with `response`: the
    /// two-mesh estimate from the pilot's finer solve and this one,
    /// `|Q − Q2| / ((N/N2)^k − 1) / |Q|`; the prediction when the meshes coincide.
    pub fn estimate_with(&self, response: f64) -> f64 {
        let Some(p) = self.pilot() else {
            return self.estimated_error;
        };
        let ratio = self.elements as f64 / p.elements[1] as f64;
        if ratio <= 1.0 + 1e-12 || response == 0.0 {
            return self.estimated_error;
        }
        let e = (response - p.response[1]).abs() / (ratio.powf(p.exponent) - 1.0) / response.abs();
        if e.is_finite() {
            e
        } else {
            self.estimated_error
        }
    }
}

/// Why no mesh was chosen.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AccuracyError {
    /// Stopped from outside (a signal, the explorer's cancel) after the pilot solves of
    /// `orders_done` element orders.
    #[error("the mesh choice for accuracy {target:e} was {why} after {:.1} s, with the pilot solves of {orders_done} of {orders} element order(s) done; no mesh was chosen", elapsed.as_secs_f64())]
    Interrupted {
        target: f64,
        why: Interruption,
        orders_done: usize,
        orders: usize,
        elapsed: Duration,
    },
    #[error("accuracy {target:e}: the pilot solves failed ({reasons})")]
    PilotFailed { target: f64, reasons: String },
    #[error("accuracy {target:e} is out of reach: {reasons}")]
    Unreachable { target: f64, reasons: String },
}

/// Chooses the element order (among `orders`) and elements per rod that meet the relative
/// accuracy `target` on the response at the least predicted time.
///
/// Per order: solves the meshes `N1` ([`Subject::coarsest`]) and `N2 = 2 N1`; estimates the
/// error of the finer as `e2 = |Q2 − Q1| / (2^k − 1) / |Q2|` with the theoretical exponent `k`
/// of the response; predicts `e(N) = e2 (N2/N)^k`, so the mesh for `SAFETY · target` is
/// `N = N2 (e2 / (SAFETY · target))^{1/k}` (not below `N1`, rounded up to whole elements
/// between joints), and its time `t2 (N/N2)^α`, `α` the observed growth of the time from
/// `N1` to `N2`, kept in [1, 2] (work per Newton step grows linearly in a banded system).
pub fn choose_mesh(
    subject: &Subject,
    target: f64,
    orders: &[Order],
) -> Result<MeshChoice, AccuracyError> {
    choose_mesh_with(subject, target, orders, None)
}

/// [`choose_mesh`], stopped when `interrupt` is raised (the pilot solves check it between
/// Newton iterations).
pub fn choose_mesh_with(
    subject: &Subject,
    target: f64,
    orders: &[Order],
    interrupt: Option<&Interrupt>,
) -> Result<MeshChoice, AccuracyError> {
    if target.is_nan() || target < ACCURACY_FLOOR {
        return Err(AccuracyError::Unreachable {
            target,
            reasons: format!(
                "below {ACCURACY_FLOOR:e}, where the Newton tolerance, not the mesh, sets the error"
            ),
        });
    }
    let t0 = Instant::now();
    let m = subject.joint_intervals().max(1);
    let mut pilots = Vec::new();
    let mut failures = Vec::new();
    for (done, &order) in orders.iter().enumerate() {
        let outcome = pilot(subject, order, SAFETY * target, m, interrupt);
        if let Some(why) = interrupt.and_then(Interrupt::check) {
            return Err(AccuracyError::Interrupted {
                target,
                why,
                orders_done: done,
                orders: orders.len(),
                elapsed: t0.elapsed(),
            });
        }
        match outcome {
            Ok(p) => pilots.push(p),
            Err(reason) => failures.push(reason),
        }
    }
    if pilots.is_empty() {
        return Err(AccuracyError::PilotFailed {
            target,
            reasons: failures.join("; "),
        });
    }
    let best = pilots
        .iter()
        .filter(|p| p.needed.is_some())
        .min_by_key(|p| p.predicted_time);
    let Some(best) = best else {
        let reasons = pilots
            .iter()
            .map(|p| {
                format!(
                    "{} elements would need more than {MAX_ELEMENTS} per rod (estimated error {:.1e} at {})",
                    p.order.name(),
                    p.error,
                    p.elements[1]
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        return Err(AccuracyError::Unreachable { target, reasons });
    };
    let elements = best.needed.expect("filtered");
    Ok(MeshChoice {
        target,
        response: subject.response_label(),
        order: best.order,
        elements,
        estimated_error: best.error_at(elements),
        cost: t0.elapsed(),
        pilots: pilots.clone(),
    })
}

/// The two coarse solves of `order` ([`Subject::coarsest`] and twice that) and what they
/// predict for the relative error `goal` on meshes of `m` elements between joints; the
/// reason when they cannot be made.
fn pilot(
    subject: &Subject,
    order: Order,
    goal: f64,
    m: usize,
    interrupt: Option<&Interrupt>,
) -> Result<Pilot, String> {
    let n1 = subject.coarsest(order);
    if n1.saturating_mul(2) > MAX_ELEMENTS {
        return Err(format!(
            "{}: the pilot meshes would have {} and {} elements per rod, more than {MAX_ELEMENTS}",
            order.name(),
            n1,
            n1.saturating_mul(2)
        ));
    }
    let probes = subject.vertices(n1);
    let solve = |n: usize| {
        let t = Instant::now();
        subject
            .solve_with(order, n, &probes, interrupt)
            .map(|v| (v, t.elapsed()))
            .map_err(|e| format!("{}: {e}", order.name()))
    };
    let first = solve(n1)?;
    let second = solve(2 * n1)?;
    let exponent = subject.theoretical_order(Measure::Response, order);
    let (q1, q2) = (first.0.response, second.0.response);
    let error = two_mesh_error(q1, q2, exponent);
    let critical = first.0.critical.zip(second.0.critical).map(|(c1, c2)| {
        let exponent = subject.theoretical_order(Measure::Critical, order);
        CriticalPilot {
            parameter: [c1, c2],
            error: two_mesh_error(c1, c2, exponent),
            exponent,
        }
    });
    let mut pilot = Pilot {
        order,
        elements: [first.0.elements, second.0.elements],
        response: [q1, q2],
        time: [first.1, second.1],
        error,
        exponent,
        critical,
        needed: None,
        predicted_time: None,
    };
    pilot.predict(goal, m);
    Ok(pilot)
}

impl Pilot {
    /// Sets the elements per rod predicted to meet the relative error `goal` (a multiple of
    /// the `m` intervals between joints, not below the coarser solve) and the predicted wall
    /// time there, when within [`MAX_ELEMENTS`].
    fn predict(&mut self, goal: f64, m: usize) {
        let (elements, time) = (self.elements, self.time);
        // the mesh that brings an error `e2` at the finer solve, falling as `h^k`, to `goal`
        let for_error = |error: f64, exponent: f64| {
            let n = elements[1] as f64 * (error / goal).powf(1.0 / exponent);
            (((n / m as f64).ceil() as usize) * m).max(elements[0])
        };
        let needed = if self.error_at(elements[0]) <= goal {
            elements[0]
        } else {
            let critical = self
                .critical
                .as_ref()
                .map_or(0, |c| for_error(c.error, c.exponent));
            for_error(self.error, self.exponent).max(critical)
        };
        if needed <= MAX_ELEMENTS {
            let growth = (time[1].as_secs_f64() / time[0].as_secs_f64().max(1e-9))
                .log2()
                .clamp(1.0, 2.0);
            let t = time[1].as_secs_f64() * (needed as f64 / elements[1] as f64).powf(growth);
            self.needed = Some(needed);
            self.predicted_time = Some(Duration::from_secs_f64(t));
        }
    }
}

/// The case to solve: `case` itself when it gives a mesh; when it gives an accuracy
/// (`[discretisation] accuracy`), the case with the mesh [`choose_mesh`] picks (among both
/// element orders, or the one the case names) and the choice. This is where an accuracy
/// target becomes a mesh: the faces (`spira run`, `spira bench`, the explorer) call it
/// before solving.
pub fn resolve_accuracy(case: &Case) -> Result<(Case, Option<MeshChoice>), AccuracyError> {
    resolve_accuracy_with(case, None)
}

/// [`resolve_accuracy`], stopped when `interrupt` is raised.
pub fn resolve_accuracy_with(
    case: &Case,
    interrupt: Option<&Interrupt>,
) -> Result<(Case, Option<MeshChoice>), AccuracyError> {
    let Some(AccuracyTarget { target, order }) = case.discretisation.accuracy else {
        return Ok((case.clone(), None));
    };
    let orders: Vec<Order> = match order {
        Some(o) => vec![o],
        None => ORDERS.to_vec(),
    };
    let subject = Subject::Path(Box::new(case.clone()));
    let choice = choose_mesh_with(&subject, target, &orders, interrupt)?;
    Ok((with_mesh(case, choice.order, choice.elements), Some(choice)))
}
