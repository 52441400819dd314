//! Speed against accuracy (issue 5): work-precision studies and meshes chosen for a target
//! accuracy.
//!
//! A **study** solves one problem on a ladder of meshes (elements per rod, doubling) for
//! each element order, times every solve (best of several runs after a warm-up) and
//! measures its error against a reference:
//!
//! - the **response** at the final load: the axial reaction `Fz/(n Pcrit)` under
//!   displacement control (`ε` under load control, where the load is prescribed), or the
//!   tip force of Love's helix;
//! - the **curvature** profiles `(κ1, κ2, Ω)` of every rod, in the max norm over the
//!   vertices of the coarsest mesh (common to every mesh of a doubling ladder), relative to
//!   the largest reference curvature;
//! - the **critical load** parameter of the first critical point, when there is one.
//!
//! The reference is a closed form where the problem has one (Love's helix, DESIGN.md §6),
//! otherwise Richardson's extrapolation of the two finest quadratic solutions with the
//! theoretical order of each measure ([`Measure::theoretical_order`]).
//!
//! An **accuracy-driven mesh** ([`choose_mesh`], [`resolve_accuracy`]) solves two coarse
//! meshes per element order, estimates the error constant from their difference and the
//! known order, and picks the element order and number of elements that meet the target at
//! the least predicted time.
//!
//! Nothing here prints; the faces (CLI, explorer) format the results.

use crate::case::{Accuracy, Case};
use crate::chart::{self, Panel, Series};
use crate::discretisation::element;
use crate::discretisation::model::DiscreteModel;
use crate::discretisation::shape::{self, Order, MAX_NODES};
use crate::model::assembly::Assembly;
use crate::model::helix::Chirality;
use crate::model::loading::Control;
use crate::model::love::LoveHelix;
use crate::results::{RodShape, Snapshot};
use crate::run::run_path;
use crate::simulation::Simulation;
use crate::solver::continuation::ContinuationSettings;
use std::fmt::Write as _;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

/// Element orders compared, coarse to fine in accuracy per element.
pub const ORDERS: [Order; 2] = [Order::Linear, Order::Quadratic];

/// The coarsest mesh of a ladder has at least this many elements per turn of helix:
/// a quadratic element spans at most a quarter turn, a linear one an eighth.
fn elements_per_turn(order: Order) -> f64 {
    match order {
        Order::Linear => 8.0,
        Order::Quadratic => 4.0,
    }
}

/// Name of an element order in tables and charts.
pub fn order_name(order: Order) -> &'static str {
    match order {
        Order::Linear => "linear",
        Order::Quadratic => "quadratic",
    }
}

// ---------------------------------------------------------------- what is measured

/// A measured quantity of a solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    /// The response at the final load (reaction `Fz`, or `ε` under load control).
    Response,
    /// Curvature profiles, max norm over the common vertices.
    Curvature,
    /// Load parameter of the first critical point.
    Critical,
}

impl Measure {
    pub const ALL: [Measure; 3] = [Measure::Response, Measure::Curvature, Measure::Critical];

    fn index(self) -> usize {
        self as usize
    }

    /// Short name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Measure::Response => "Fz",
            Measure::Curvature => "curvature",
            Measure::Critical => "critical",
        }
    }

    /// The exponent `k` of the error `O(h^k)` of this measure for elements of degree `p`,
    /// `h` the element length. Stated from the theory, not fitted:
    ///
    /// - **Response and critical load: `2p`.** The tip reaction is the multiplier of the
    ///   prescribed tip position, i.e. the derivative of the minimum energy with respect
    ///   to it, and the critical load an eigenvalue of the stiffness on the constraints'
    ///   tangent space. Both converge like the energy, whose error is the square of the
    ///   `O(h^p)` error of a degree-`p` interpolation in the energy norm: `O(h^{2p})`
    ///   (Strang & Fix, *An analysis of the finite element method*, ch. 1 and 6). The
    ///   Gauss rules (2 points linear, 3 quadratic) are exact enough not to spoil it.
    ///   *Except linear elements on a uniform helix: 4.* There the quaternion field runs
    ///   on a great circle, and the normalised linear chord across an element (angle `θ`)
    ///   has the curvature `sin θ / (θ (1 − 2t(1 − t)(1 − cos θ)))` times the exact one,
    ///   relative error `θ² (t(1 − t) − 1/6) + O(θ⁴)` at `t ∈ [0, 1]`. With a uniform
    ///   stress the energy error is, to first order, the stress times the integral of
    ///   that error, and the 2-point Gauss rule integrates `t(1 − t) − 1/6` to exactly
    ///   zero: the `O(h²)` term cancels and the reactions converge as `O(h⁴)`.
    /// - **Curvature at the element vertices.** In 1-D the nodal values are
    ///   superconvergent, so the error is that of differentiating the interpolant of the
    ///   exact rotation field at its nodes (the curvature is `2 Im(q̄ q')/|q|²`).
    ///   *Quadratic: 2.* The slope of a quadratic interpolant at either end of its element
    ///   is off by `h² q⁽³⁾/12` with the same sign from both sides, so the mean over the
    ///   two elements at a vertex keeps the `O(h²)` term. *Linear: 1, or 2 when the
    ///   curvature is uniform.* At an interior vertex the mean of the two one-sided slopes
    ///   is a central difference, `O(h²)`; at a rod end only one element meets and the
    ///   slope is off by `(h/2) q''`, whose part along the field is the derivative of the
    ///   curvature there: `O(h)` wherever the curvature varies at an end (the clamped ends
    ///   of a deformed assembly). On a uniform helix (Love's) that derivative vanishes,
    ///   and a linear chord of the great circle the quaternion field runs on is `O(h²)`
    ///   everywhere.
    pub fn theoretical_order(self, order: Order, uniform_curvature: bool) -> f64 {
        let p = order.degree() as f64;
        match (self, order) {
            (Measure::Response, Order::Linear) if uniform_curvature => 4.0,
            (Measure::Response | Measure::Critical, _) => 2.0 * p,
            (Measure::Curvature, Order::Quadratic) => 2.0,
            (Measure::Curvature, Order::Linear) => {
                if uniform_curvature {
                    2.0
                } else {
                    1.0
                }
            }
        }
    }
}

// ---------------------------------------------------------------- problems

/// The discrete model of Love's problem (DESIGN.md §6): one right-handed rod, naturally the
/// helix `(a0, b0)`. One rod has no joints, so its meshes are uniform and a doubling ladder
/// nests.
fn love_model(love: &LoveHelix, order: Order, elements: usize) -> DiscreteModel {
    DiscreteModel::new(
        Assembly::new(1, love.radius0, love.pitch0, love.length),
        love.stiffness,
        elements,
        order,
    )
}

/// What a study solves.
#[derive(Clone, Debug, PartialEq)]
pub enum Problem {
    /// A case's load path, from the natural state through its output steps to its target.
    Path(Box<Case>),
    /// Love's helix: one equilibrium with a closed-form solution.
    Love(LoveHelix),
}

/// The measured values of one solve.
#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    /// See [`Problem::response_label`].
    pub response: f64,
    /// `(κ1, κ2, Ω)` (1/m) at the probe points, rod by rod.
    pub curvature: Vec<[f64; 3]>,
    /// Load parameter of the first critical point.
    pub critical: Option<f64>,
    /// Unknowns of the system, multipliers included.
    pub unknowns: usize,
    /// Elements per rod of the mesh (the largest over the rods).
    pub elements: usize,
}

/// Arc lengths (m) at which curvatures are compared, per rod.
pub type Probes = Vec<Vec<f64>>;

impl Problem {
    /// Name of the problem in titles and files.
    pub fn name(&self) -> String {
        match self {
            Problem::Path(case) => case.name.clone(),
            Problem::Love(love) => format!("love-helix-b{}", love.pitch),
        }
    }

    /// One line on what is solved.
    pub fn describe(&self) -> String {
        match self {
            Problem::Path(case) => format!(
                "n = {}, {} control 0 → {} in {} steps",
                case.geometry.helices,
                case.loading.control.name(),
                case.loading.target,
                case.loading.steps
            ),
            Problem::Love(love) => format!(
                "Love's helix: a rod of a0 = {} m, b0 = {} m held on b = {} m",
                love.radius0, love.pitch0, love.pitch
            ),
        }
    }

    /// What [`Values::response`] is.
    pub fn response_label(&self) -> String {
        match self {
            Problem::Path(case) => match case.loading.control {
                Control::Displacement => format!("Fz/(n Pcrit) at ε = {}", case.loading.target),
                Control::Force => format!("ε at P/Pcrit = {}", case.loading.target),
            },
            Problem::Love(_) => "tip force Fz (N)".to_string(),
        }
    }

    /// Whether the exact curvature is uniform along every rod (Love's helix), which raises
    /// the order of linear elements' vertex curvature (see [`Measure::theoretical_order`]).
    pub fn uniform_curvature(&self) -> bool {
        matches!(self, Problem::Love(_))
    }

    /// The theoretical order of measure `m` for elements of `order` on this problem.
    pub fn theoretical_order(&self, m: Measure, order: Order) -> f64 {
        m.theoretical_order(order, self.uniform_curvature())
    }

    fn turns(&self) -> f64 {
        match self {
            Problem::Path(case) => case.geometry.turns(),
            Problem::Love(love) => love.turns(),
        }
    }

    fn model(&self, order: Order, elements: usize) -> DiscreteModel {
        match self {
            Problem::Path(case) => with_mesh(case, order, elements).model(),
            Problem::Love(love) => love_model(love, order, elements),
        }
    }

    /// Number of intervals between joints on a rod. The joints of the thesis assemblies are
    /// equally spaced (every π c/(n/2) of arc length), so a mesh of `k` times this many
    /// elements has equal elements, and doubling it nests the meshes.
    pub fn joint_intervals(&self) -> usize {
        let model = self.model(Order::Linear, 1);
        model
            .rods
            .iter()
            .map(|r| r.mesh.elements())
            .max()
            .unwrap_or(1)
    }

    /// Coarsest mesh of a ladder for `order`: the smallest `joint_intervals · 2^j` with at
    /// least [`elements_per_turn`] elements per turn.
    pub fn coarsest(&self, order: Order) -> usize {
        let m = self.joint_intervals().max(1);
        let min = (elements_per_turn(order) * self.turns()).ceil().max(2.0) as usize;
        let mut n = m;
        while n < min {
            n *= 2;
        }
        n
    }

    /// The vertices of the mesh of `elements` elements per rod (of any order), rod by rod
    /// of the full assembly (as a [`Snapshot`] lists them).
    pub fn vertices(&self, elements: usize) -> Probes {
        let model = self.model(Order::Linear, elements);
        (0..full_rods(&model))
            .map(|k| model.rods[source_rod(&model, k)].mesh.vertices.clone())
            .collect()
    }

    /// What the closed form is, where the problem has one.
    pub fn closed_form(&self) -> Option<String> {
        let Problem::Love(love) = self else {
            return None;
        };
        let k = love.curvature(Chirality::Right);
        Some(format!(
            "Love's helix, DESIGN.md §6: Fz = {:.6} N, (κ1, κ2, Ω) = ({:.4}, 0, {:.4}) 1/m",
            love.force(),
            k[0],
            k[2]
        ))
    }

    /// The closed-form values where the problem has them.
    pub fn exact(&self, probes: &Probes) -> Option<Values> {
        let Problem::Love(love) = self else {
            return None;
        };
        let model = love_model(love, Order::Linear, 1);
        let curvature = model
            .rods
            .iter()
            .zip(probes)
            .flat_map(|(rod, s)| s.iter().map(|_| love.curvature(rod.helix.chirality)))
            .collect();
        Some(Values {
            response: love.force(),
            curvature,
            critical: None,
            unknowns: 0,
            elements: 0,
        })
    }

    /// Solves the problem on a mesh and measures it; curvatures at `probes`.
    pub fn solve(&self, order: Order, elements: usize, probes: &Probes) -> Result<Values, String> {
        match self {
            Problem::Path(case) => {
                let case = with_mesh(case, order, elements);
                let targets = case.output_eps(case.loading.target, case.loading.steps);
                let outcome = run_path(&case, &targets, |_, _| {}).map_err(|e| e.to_string())?;
                if let Some(e) = outcome.error {
                    return Err(e.to_string());
                }
                let last = outcome.points.last().expect("step 0 is always there");
                let response = match case.loading.control {
                    Control::Displacement => last.load[2],
                    Control::Force => last.eps,
                };
                Ok(Values {
                    response,
                    curvature: sample_curvature(&outcome.model, &outcome.snapshot, probes),
                    critical: outcome.critical.first().map(|c| c.parameter),
                    unknowns: outcome.unknowns,
                    elements: mesh_elements(&outcome.model),
                })
            }
            Problem::Love(love) => {
                let model = love_model(love, order, elements);
                let sim = Simulation::held_on_helices(
                    model,
                    love.radius(),
                    love.pitch,
                    ContinuationSettings::default(),
                )
                .map_err(|e| e.to_string())?;
                let point = sim.load_point(0);
                let response = point.reactions.iter().map(|r| r.tip.force[2]).sum::<f64>()
                    / point.reactions.len() as f64;
                Ok(Values {
                    response,
                    curvature: sample_curvature(&sim.model, &sim.snapshot(), probes),
                    critical: None,
                    unknowns: sim.system().n,
                    elements: mesh_elements(&sim.model),
                })
            }
        }
    }
}

/// `case` with the mesh `order` x `elements` (and no accuracy target).
fn with_mesh(case: &Case, order: Order, elements: usize) -> Case {
    let mut c = case.clone();
    c.discretisation.order = order;
    c.discretisation.elements = elements;
    c.discretisation.accuracy = None;
    c
}

/// Rods of the full assembly: the model's, or all the images of a symmetric pair.
fn full_rods(model: &DiscreteModel) -> usize {
    model
        .assembly
        .symmetry
        .map_or(model.rods.len(), |s| s.full_rods())
}

/// The rod of `model` that rod `k` of the full assembly is (or is an image of).
fn source_rod(model: &DiscreteModel, k: usize) -> usize {
    model.assembly.symmetry.map_or(k, |s| s.image(k).0)
}

fn mesh_elements(model: &DiscreteModel) -> usize {
    model
        .rods
        .iter()
        .map(|r| r.mesh.elements())
        .max()
        .unwrap_or(0)
}

/// Curvatures of every rod of `snapshot` at the arc lengths `probes` (rod by rod).
pub fn sample_curvature(
    model: &DiscreteModel,
    snapshot: &Snapshot,
    probes: &Probes,
) -> Vec<[f64; 3]> {
    snapshot
        .rods
        .iter()
        .zip(probes)
        .flat_map(|(shape, s)| s.iter().map(|&s| curvature_at(model, shape, s)))
        .collect()
}

/// Curvature `(κ1, κ2, Ω)` (1/m) of a rod of `model` at arc length `s`, from the nodal
/// quaternions of its shape: at an element vertex the mean of the limits from the elements
/// that meet there (as [`Snapshot`] reports it), elsewhere the element's interpolation.
/// (The curvatures are body components: an image of a rod turned about z has its source's.)
pub fn curvature_at(model: &DiscreteModel, shape: &RodShape, s: f64) -> [f64; 3] {
    let mesh = &model.rods[source_rod(model, shape.rod)].mesh;
    let p = model.order.degree();
    let v = &mesh.vertices;
    let ne = mesh.elements();
    let tol = 1e-9 * v[ne];
    let limit = |e: usize, xi: f64| {
        let (n, dn) = shape::shape(model.order, xi);
        let h = v[e + 1] - v[e];
        let (mut q, mut dq) = ([0.0; 4], [0.0; 4]);
        for a in 0..model.order.nodes().min(MAX_NODES) {
            let qa = shape.nodes[e * p + a].quaternion;
            for k in 0..4 {
                q[k] += n[a] * qa[k];
                dq[k] += dn[a] / h * qa[k];
            }
        }
        element::curvature(&q, &dq)
    };
    if let Some(k) = mesh.vertex_at(s) {
        let mut sum = nalgebra::Vector3::zeros();
        let mut count = 0.0;
        if k > 0 {
            sum += limit(k - 1, 1.0);
            count += 1.0;
        }
        if k < ne {
            sum += limit(k, 0.0);
            count += 1.0;
        }
        return (sum / count).into();
    }
    let s = s.clamp(0.0, v[ne]);
    let e = v.partition_point(|&x| x <= s + tol).clamp(1, ne) - 1;
    let xi = ((s - v[e]) / (v[e + 1] - v[e])).clamp(0.0, 1.0);
    limit(e, xi).into()
}

// ---------------------------------------------------------------- ladders and studies

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
    /// `rungs_linear` and `rungs_quadratic` meshes doubling from [`Problem::coarsest`].
    pub fn doubling(problem: &Problem, rungs_linear: usize, rungs_quadratic: usize) -> Ladder {
        let mut rungs = Vec::new();
        for (order, count) in [
            (Order::Linear, rungs_linear),
            (Order::Quadratic, rungs_quadratic),
        ] {
            let base = problem.coarsest(order);
            rungs.extend((0..count).map(|k| Rung {
                order,
                elements: base << k,
            }));
        }
        Ladder { rungs }
    }

    /// The ladder `spira precision` uses: 5 linear and 4 quadratic meshes.
    pub fn standard(problem: &Problem) -> Ladder {
        Ladder::doubling(problem, 5, 4)
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
    pub values: Result<Values, String>,
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
    /// The problem's closed form.
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

impl Reference {
    /// One line for titles and headers.
    pub fn describe(&self) -> String {
        match self {
            Reference::ClosedForm(what) => format!("closed form: {what}"),
            Reference::Richardson {
                order,
                elements,
                exponents,
                ..
            } => format!(
                "Richardson extrapolation of {} {} and {} elements/rod with the theoretical orders ({} {}, {} {}, {} {})",
                order_name(*order),
                elements[0],
                elements[1],
                Measure::Response.name(),
                exponents[0],
                Measure::Curvature.name(),
                exponents[1],
                Measure::Critical.name(),
                exponents[2]
            ),
        }
    }

    /// A few words for a chart's corner: `closed form`, or `Richardson quadratic 16/32`
    /// (the order and the elements per rod of the two solutions).
    pub fn short_label(&self) -> String {
        match self {
            Reference::ClosedForm(_) => "closed form".to_string(),
            Reference::Richardson {
                order, elements, ..
            } => format!(
                "Richardson {} {}/{}",
                order_name(*order),
                elements[0],
                elements[1]
            ),
        }
    }
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
    /// The exact curvature is uniform ([`Problem::uniform_curvature`]).
    pub uniform_curvature: bool,
}

/// Why a study has no result.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StudyError {
    #[error("the study was cancelled")]
    Cancelled,
    #[error("no reference: {0}")]
    NoReference(String),
}

/// Progress of a study, after each rung.
#[derive(Clone, Debug)]
pub struct Progress<'a> {
    pub done: usize,
    pub total: usize,
    pub last: &'a RungResult,
}

/// Runs a study: every rung of `ladder` solved once as a warm-up (whose values are kept)
/// and `repeats` times timed; then the reference, the errors and the observed orders.
/// `on_rung` is called after each rung and may stop the study.
pub fn run_study(
    problem: &Problem,
    ladder: &Ladder,
    repeats: usize,
    mut on_rung: impl FnMut(&Progress) -> ControlFlow<()>,
) -> Result<Study, StudyError> {
    let probes = problem.vertices(ladder.coarsest_elements());
    let mut rungs: Vec<RungResult> = Vec::new();
    for (k, &rung) in ladder.rungs.iter().enumerate() {
        // the warm-up: its values are kept, its time only when nothing is timed
        let t0 = Instant::now();
        let values = problem.solve(rung.order, rung.elements, &probes);
        let mut time = t0.elapsed();
        if values.is_ok() {
            let mut best: Option<Duration> = None;
            for _ in 0..repeats {
                let t = Instant::now();
                let again = problem.solve(rung.order, rung.elements, &probes);
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
        let progress = Progress {
            done: k + 1,
            total: ladder.rungs.len(),
            last: rungs.last().expect("just pushed"),
        };
        if on_rung(&progress).is_break() {
            return Err(StudyError::Cancelled);
        }
    }
    let (reference, reference_values) = match problem.exact(&probes) {
        Some(v) => (
            Reference::ClosedForm(problem.closed_form().unwrap_or_default()),
            v,
        ),
        None => richardson(&rungs, problem.uniform_curvature())?,
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
        name: problem.name(),
        description: problem.describe(),
        response_label: problem.response_label(),
        reference,
        reference_values,
        rungs,
        repeats,
        uniform_curvature: problem.uniform_curvature(),
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
    /// How the times were taken.
    pub fn timing(&self) -> String {
        match self.repeats {
            0 => "one run (no warm-up)".to_string(),
            1 => "one run after a warm-up".to_string(),
            k => format!("best of {k} runs after a warm-up"),
        }
    }

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

    /// The table `spira precision` prints.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let measures: Vec<Measure> = Measure::ALL
            .into_iter()
            .filter(|&m| m == Measure::Response || self.has(m))
            .collect();
        let _ = write!(
            s,
            "{:<10} {:>8} {:>9} {:>11}",
            "elements", "per rod", "unknowns", "time (ms)"
        );
        for m in &measures {
            let _ = write!(
                s,
                " {:>11} {:>6}",
                format!("{} error", short_name(*m)),
                "order"
            );
        }
        s.push('\n');
        for r in &self.rungs {
            let _ = write!(
                s,
                "{:<10} {:>8} {:>9} {:>11}",
                order_name(r.rung.order),
                r.elements(),
                r.values
                    .as_ref()
                    .map_or("-".into(), |v| v.unknowns.to_string()),
                format!("{:.2}", r.time.as_secs_f64() * 1e3)
            );
            match &r.values {
                Err(e) => {
                    let _ = write!(s, " failed: {e}");
                }
                Ok(_) => {
                    for m in &measures {
                        let err = r.error(*m).map_or("-".into(), |e| format!("{e:.3e}"));
                        let ord = match r.observed(*m) {
                            Some(o) if r.by_construction => format!("({o:.2})"),
                            Some(o) => format!("{o:.2}"),
                            None => "-".into(),
                        };
                        let _ = write!(s, " {err:>11} {ord:>6}");
                    }
                }
            }
            s.push('\n');
        }
        s
    }

    /// Header lines (without `#`) of the CSV and the report.
    pub fn header(&self) -> Vec<String> {
        let mut lines = vec![
            format!("work-precision study, case {}: {}", self.name, self.description),
            format!("reference: {}", self.reference.describe()),
            format!(
                "response: {} = {:.10e} (reference); time of the whole solve: {}",
                self.response_label,
                self.reference_values.response,
                self.timing()
            ),
            "errors relative: response |Q - Q_ref|/|Q_ref|; curvature max |k - k_ref| over rods, coarsest-mesh vertices and k1,k2,Omega / max |k_ref|; critical: first critical load parameter".to_string(),
        ];
        if let Reference::Richardson { order, check, .. } = &self.reference {
            let parts: Vec<String> = Measure::ALL
                .iter()
                .zip(check)
                .filter_map(|(m, c)| c.map(|c| format!("{} {c:.2}", m.name())))
                .collect();
            if !parts.is_empty() {
                lines.push(format!(
                    "check of the reference: orders observed over the three finest {} meshes (independent of the reference): {}",
                    order_name(*order),
                    parts.join(", ")
                ));
            }
            lines.push(format!(
                "orders in parentheses: the finest {} pair defines the reference, so its order equals the theoretical one by construction",
                order_name(*order)
            ));
        }
        let theory: Vec<String> = ORDERS
            .iter()
            .map(|&o| {
                format!(
                    "{} {} {}, curvature {}, critical {}",
                    order_name(o),
                    Measure::Response.name(),
                    self.theory(Measure::Response, o),
                    self.theory(Measure::Curvature, o),
                    self.theory(Measure::Critical, o)
                )
            })
            .collect();
        lines.push(format!("theoretical orders in h: {}", theory.join("; ")));
        lines
    }

    /// `precision.csv`: the header as `#` lines, then one row per rung.
    pub fn csv(&self) -> String {
        let mut s = String::new();
        for l in self.header() {
            let _ = writeln!(s, "# {l}");
        }
        let _ = writeln!(
            s,
            "discretisation,elements_asked,elements,unknowns,time_s,response,critical,error_response,error_curvature,error_critical,order_response,order_curvature,order_critical,by_construction,failure"
        );
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6e}"));
        for r in &self.rungs {
            let (response, critical, unknowns, failure) = match &r.values {
                Ok(v) => (
                    format!("{:.12e}", v.response),
                    opt(v.critical),
                    v.unknowns.to_string(),
                    String::new(),
                ),
                Err(e) => (
                    String::new(),
                    String::new(),
                    String::new(),
                    format!("\"{}\"", e.replace('"', "'")),
                ),
            };
            let _ = writeln!(
                s,
                "{},{},{},{},{:.6e},{},{},{},{},{},{},{},{},{},{}",
                order_name(r.rung.order),
                r.rung.elements,
                r.elements(),
                unknowns,
                r.time.as_secs_f64(),
                response,
                critical,
                opt(r.errors[0]),
                opt(r.errors[1]),
                opt(r.errors[2]),
                opt(r.observed[0]),
                opt(r.observed[1]),
                opt(r.observed[2]),
                u8::from(r.by_construction),
                failure
            );
        }
        s
    }

    /// Chart points of one order and measure, coarse to fine: `x` the time (s), `y` the
    /// error, labelled by elements per rod, hollow where the error is the reference's own
    /// estimate. A zero error has no place on a log scale and is left out.
    pub fn points(&self, order: Order, m: Measure) -> Vec<chart::Point> {
        self.of_order(order)
            .filter_map(|r| {
                let e = r.error(m).filter(|e| *e > 0.0)?;
                let t = r.time.as_secs_f64();
                (t > 0.0).then(|| chart::Point {
                    x: t,
                    y: e,
                    label: r.elements().to_string(),
                    hollow: r.by_construction,
                })
            })
            .collect()
    }

    /// The work-precision chart: one panel per measure that has values, log error against
    /// log time, one line per element order, one point per mesh (labelled by its elements
    /// per rod).
    pub fn svg(&self) -> String {
        let panels: Vec<Panel> = Measure::ALL
            .into_iter()
            .filter(|&m| m == Measure::Response || self.has(m))
            .map(|m| Panel {
                title: match m {
                    Measure::Response => format!("{} (relative error)", self.response_label),
                    Measure::Curvature => "curvature profiles (max norm, relative)".to_string(),
                    Measure::Critical => "first critical load (relative error)".to_string(),
                },
                x_label: "wall time of the whole solve (s)".to_string(),
                y_label: "relative error".to_string(),
                series: ORDERS
                    .iter()
                    .map(|&o| Series {
                        label: match self.finest_observed(m, o) {
                            Some(k) => format!(
                                "{}: order {k:.2} (theory {})",
                                order_name(o),
                                self.theory(m, o)
                            ),
                            None => order_name(o).to_string(),
                        },
                        points: self.points(o, m),
                        style: series_style(o),
                    })
                    .collect(),
            })
            .collect();
        let title = format!("work-precision: {} ({})", self.name, self.description);
        let mut notes = vec![
            format!("reference: {}", self.reference.describe()),
            format!(
                "time of the whole solve: {}; points labelled by elements per rod; legend: orders observed in h (element length) between the two finest meshes",
                self.timing()
            ),
        ];
        if matches!(self.reference, Reference::Richardson { .. }) {
            notes.push(
                "hollow marker: the finest mesh of the reference, whose error is the extrapolation's own estimate (its order is the theoretical one by construction)"
                    .to_string(),
            );
        }
        chart::log_log_svg(&title, &notes, &panels)
    }
}

fn short_name(m: Measure) -> &'static str {
    match m {
        Measure::Response => "Fz",
        Measure::Curvature => "curv.",
        Measure::Critical => "crit.",
    }
}

/// Colour and marker of an element order in charts.
pub fn series_style(order: Order) -> chart::Style {
    match order {
        Order::Linear => chart::Style {
            color: "#1f77b4",
            marker: chart::Marker::Circle,
        },
        Order::Quadratic => chart::Style {
            color: "#d62728",
            marker: chart::Marker::Square,
        },
    }
}

// ---------------------------------------------------------------- accuracy-driven meshes

/// The mesh is chosen for this fraction of the target: the error estimate holds only
/// asymptotically, so a margin of 2 keeps a slightly pre-asymptotic estimate on the safe
/// side.
pub const SAFETY: f64 = 0.5;
/// Largest mesh considered (elements per rod).
pub const MAX_ELEMENTS: usize = 8192;
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
    /// Elements per rod predicted to meet `SAFETY · target`, if within [`MAX_ELEMENTS`].
    pub needed: Option<usize>,
    /// Predicted wall time at `needed`.
    pub predicted_time: Option<Duration>,
}

impl Pilot {
    /// Estimated relative error at `elements` per rod: `e2 (N2/N)^k`.
    pub fn error_at(&self, elements: usize) -> f64 {
        self.error * (self.elements[1] as f64 / elements as f64).powf(self.exponent)
    }
}

/// The mesh chosen for an accuracy target.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshChoice {
    /// Relative accuracy asked for on the response.
    pub target: f64,
    /// What the response is ([`Problem::response_label`]).
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

    /// One line for reports: the chosen mesh and the estimated error.
    pub fn note(&self, estimated: f64) -> String {
        format!(
            "mesh chosen for accuracy {:e} on {}: {} elements, {} per rod, estimated relative error {:.1e}",
            self.target,
            self.response,
            order_name(self.order),
            self.elements,
            estimated
        )
    }

    /// How the choice was made, one line per element order.
    pub fn pilot_lines(&self) -> Vec<String> {
        self.pilots
            .iter()
            .map(|p| {
                let need = match (p.needed, p.predicted_time) {
                    (Some(n), Some(t)) => format!(
                        "needs {n} per rod, predicted {:.1} ms",
                        t.as_secs_f64() * 1e3
                    ),
                    _ => format!("needs more than {MAX_ELEMENTS} per rod"),
                };
                format!(
                    "{}: {} and {} elements/rod in {:.1} and {:.1} ms, estimated error {:.2e} (order {}): {need}",
                    order_name(p.order),
                    p.elements[0],
                    p.elements[1],
                    p.time[0].as_secs_f64() * 1e3,
                    p.time[1].as_secs_f64() * 1e3,
                    p.error,
                    p.exponent
                )
            })
            .collect()
    }
}

/// Why no mesh was chosen.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AccuracyError {
    #[error("accuracy {target:e}: the pilot solves failed ({reasons})")]
    PilotFailed { target: f64, reasons: String },
    #[error("accuracy {target:e} is out of reach: {reasons}")]
    Unreachable { target: f64, reasons: String },
}

/// Chooses the element order (among `orders`) and elements per rod that meet the relative
/// accuracy `target` on the response at the least predicted time.
///
/// Per order: solves the meshes `N1` ([`Problem::coarsest`]) and `N2 = 2 N1`; estimates the
/// error of the finer as `e2 = |Q2 − Q1| / (2^k − 1) / |Q2|` with the theoretical exponent `k`
/// of the response; predicts `e(N) = e2 (N2/N)^k`, so the mesh for `SAFETY · target` is
/// `N = N2 (e2 / (SAFETY · target))^{1/k}` (not below `N1`, rounded up to whole elements
/// between joints), and its time `t2 (N/N2)^α`, `α` the observed growth of the time from
/// `N1` to `N2`, kept in [1, 2] (work per Newton step grows linearly in a banded system).
pub fn choose_mesh(
    problem: &Problem,
    target: f64,
    orders: &[Order],
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
    let m = problem.joint_intervals().max(1);
    let mut pilots = Vec::new();
    let mut failures = Vec::new();
    for &order in orders {
        let n1 = problem.coarsest(order);
        let probes = problem.vertices(n1);
        let solve = |n: usize| {
            let t = Instant::now();
            problem.solve(order, n, &probes).map(|v| (v, t.elapsed()))
        };
        let (first, second) = match (solve(n1), solve(2 * n1)) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => {
                failures.push(format!("{}: {e}", order_name(order)));
                continue;
            }
        };
        let exponent = problem.theoretical_order(Measure::Response, order);
        let (q1, q2) = (first.0.response, second.0.response);
        let scale = if q2 != 0.0 { q2.abs() } else { 1.0 };
        // below roundoff the difference says nothing; count it as the Newton floor
        let error = ((q2 - q1).abs() / (2f64.powf(exponent) - 1.0) / scale).max(1e-14);
        let elements = [first.0.elements, second.0.elements];
        let time = [first.1, second.1];
        let goal = SAFETY * target;
        let mut pilot = Pilot {
            order,
            elements,
            response: [q1, q2],
            time,
            error,
            exponent,
            needed: None,
            predicted_time: None,
        };
        let needed = if pilot.error_at(elements[0]) <= goal {
            elements[0]
        } else {
            let n = elements[1] as f64 * (error / goal).powf(1.0 / exponent);
            (((n / m as f64).ceil() as usize) * m).max(elements[0])
        };
        if needed <= MAX_ELEMENTS {
            let growth = (time[1].as_secs_f64() / time[0].as_secs_f64().max(1e-9))
                .log2()
                .clamp(1.0, 2.0);
            let t = time[1].as_secs_f64() * (needed as f64 / elements[1] as f64).powf(growth);
            pilot.needed = Some(needed);
            pilot.predicted_time = Some(Duration::from_secs_f64(t));
        }
        pilots.push(pilot);
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
                    order_name(p.order),
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
        response: problem.response_label(),
        order: best.order,
        elements,
        estimated_error: best.error_at(elements),
        cost: t0.elapsed(),
        pilots: pilots.clone(),
    })
}

/// The case to solve: `case` itself when it gives a mesh; when it gives an accuracy
/// (`[discretisation] accuracy`), the case with the mesh [`choose_mesh`] picks (among both
/// element orders, or the one the case names) and the choice. This is where an accuracy
/// target becomes a mesh: the faces (`spira run`, `spira bench`, the explorer) call it
/// before solving.
pub fn resolve_accuracy(case: &Case) -> Result<(Case, Option<MeshChoice>), AccuracyError> {
    let Some(Accuracy { target, order }) = case.discretisation.accuracy else {
        return Ok((case.clone(), None));
    };
    let orders: Vec<Order> = match order {
        Some(o) => vec![o],
        None => ORDERS.to_vec(),
    };
    let problem = Problem::Path(Box::new(case.clone()));
    let choice = choose_mesh(&problem, target, &orders)?;
    Ok((with_mesh(case, choice.order, choice.elements), Some(choice)))
}
