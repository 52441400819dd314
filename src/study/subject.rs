//! The subject of a study, what it solves: a case's load path or Love's helix, the measures taken of each
//! solution and their theoretical orders.

use crate::case::{num, Case};
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::fields;
use crate::discretisation::shape::Order;
use crate::model::assembly::Assembly;
use crate::model::helix::Chirality;
use crate::model::loading::Control;
use crate::model::love::LoveHelix;
use crate::results::Snapshot;
use crate::run::run_path_with;
use crate::simulation::{Simulation, SolveError};
use crate::solver::continuation::ContinuationSettings;
use crate::solver::interrupt::Interrupt;

/// Largest mesh a study considers (elements per rod).
pub const MAX_ELEMENTS: usize = 8192;

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

    pub(super) fn index(self) -> usize {
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
    /// - **Curvature, recovered at the element vertices: `p + 1`.** The curvature is
    ///   sampled at the Barlow points of every element (the `p` Gauss–Legendre points,
    ///   `fields::barlow_points`), where the slope of the interpolation error's leading term
    ///   `h^{p+1} q^{(p+1)} ω(ξ)/(p+1)!` vanishes: there `q'` is off by `O(h^{p+1})`, not
    ///   `O(h^p)`, and so is `2 Im(q̄ q')/|q|²`. The vertex values are recovered by a
    ///   least-squares fit of degree `p` to the samples of the neighbouring elements
    ///   (superconvergent patch recovery), whose own error is `O(h^{p+1})` for a smooth
    ///   field; the patches stop at joints and rod ends, where one-sided fits keep the order.
    ///   *Quadratic: 3, linear: 2*, at the clamped ends too (the vertex means of the former
    ///   evaluation gave 2 and, at an end, 1).
    pub fn theoretical_order(self, order: Order, uniform_curvature: bool) -> f64 {
        let p = order.degree() as f64;
        match (self, order) {
            (Measure::Response, Order::Linear) if uniform_curvature => 4.0,
            (Measure::Response | Measure::Critical, _) => 2.0 * p,
            (Measure::Curvature, _) => p + 1.0,
        }
    }
}

// ---------------------------------------------------------------- subjects

/// The discrete model of Love's problem (docs/theory.md §6): one right-handed rod, naturally the
/// helix `(a0, b0)`. One rod has no joints, so its meshes are uniform and a doubling ladder
/// nests.
fn love_model(love: &LoveHelix, order: Order, elements: usize) -> DiscreteModel {
    DiscreteModel::with_hypotheses(
        Assembly::new(1, love.radius0, love.pitch0, love.length),
        love.stiffness,
        elements,
        order,
        love.elasticity,
        love.reference,
    )
}

/// What a study solves: the subject of its ladder of meshes.
#[derive(Clone, Debug, PartialEq)]
pub enum Subject {
    /// A case's load path, from the natural state through its output steps to its target.
    Path(Box<Case>),
    /// Love's helix: one equilibrium with a closed-form solution.
    Love(LoveHelix),
}

/// The measured values of one solve.
#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    /// See [`Subject::response_label`].
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

impl Subject {
    /// Name of the subject in titles and files.
    pub fn name(&self) -> String {
        match self {
            Subject::Path(case) => case.name.clone(),
            Subject::Love(love) => format!("love-helix-b{}", love.pitch),
        }
    }

    /// One line on what is solved.
    pub fn describe(&self) -> String {
        match self {
            Subject::Path(case) => format!(
                "n = {}, {} control 0 → {} in {} steps; {}, {} reference curvatures",
                case.geometry.helices,
                case.loading.control.name(),
                num(case.loading.target),
                case.loading.steps,
                case.rod.describe(),
                case.discretisation.reference.name()
            ),
            Subject::Love(love) => format!(
                "Love's helix: a rod of a0 = {} m, b0 = {} m held on b = {} m; {}, {} reference curvatures",
                love.radius0,
                love.pitch0,
                love.pitch,
                love.elasticity.describe(),
                love.reference.name()
            ),
        }
    }

    /// What [`Values::response`] is.
    pub fn response_label(&self) -> String {
        match self {
            Subject::Path(case) => match case.loading.control {
                Control::Displacement => {
                    format!("Fz/(n Pcrit) at ε = {}", num(case.loading.target))
                }
                Control::Force => format!("ε at P/Pcrit = {}", num(case.loading.target)),
            },
            Subject::Love(_) => "tip force Fz (N)".to_string(),
        }
    }

    /// Whether the exact curvature is uniform along every rod (Love's helix), which raises
    /// the order of linear elements' reactions (see [`Measure::theoretical_order`]).
    pub fn uniform_curvature(&self) -> bool {
        matches!(self, Subject::Love(_))
    }

    /// The theoretical order of measure `m` for elements of `order` on this subject.
    pub fn theoretical_order(&self, m: Measure, order: Order) -> f64 {
        m.theoretical_order(order, self.uniform_curvature())
    }

    fn turns(&self) -> f64 {
        match self {
            Subject::Path(case) => case.geometry.turns(),
            Subject::Love(love) => love.turns(),
        }
    }

    fn model(&self, order: Order, elements: usize) -> DiscreteModel {
        match self {
            Subject::Path(case) => with_mesh(case, order, elements).model(),
            Subject::Love(love) => love_model(love, order, elements),
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
    /// least `elements_per_turn` elements per turn.
    /// The doubling stops at [`MAX_ELEMENTS`] (and cannot overflow): a
    /// case of more turns than that allows gets a coarsest mesh beyond it, which the
    /// caller refuses.
    pub fn coarsest(&self, order: Order) -> usize {
        let m = self.joint_intervals().max(1);
        let min = (elements_per_turn(order) * self.turns()).ceil().max(2.0);
        let cap = MAX_ELEMENTS.max(m);
        let mut n = m;
        while (n as f64) < min && n <= cap {
            n = n.saturating_mul(2);
        }
        n
    }

    /// The vertices of the mesh of `elements` elements per rod (of any order), rod by rod
    /// of the full assembly (as a [`Snapshot`] lists them).
    pub fn vertices(&self, elements: usize) -> Probes {
        let model = self.model(Order::Linear, elements);
        (0..model.full_rods())
            .map(|k| model.rods[model.source_rod(k)].mesh.vertices.clone())
            .collect()
    }

    /// What the closed form is, where the subject has one.
    pub fn closed_form(&self) -> Option<String> {
        let Subject::Love(love) = self else {
            return None;
        };
        let k = love.curvature(Chirality::Right);
        let source = match love.elasticity.energy {
            crate::model::elasticity::Energy::Kirchhoff => "Love's helix, docs/theory.md §6",
            crate::model::elasticity::Energy::Sadowsky(_) => {
                "a uniform ribbon helix, docs/theory.md §7 (balance laws, m = ∂W/∂u)"
            }
        };
        Some(format!(
            "{source}: Fz = {:.6} N, (κ1, κ2, Ω) = ({:.4}, 0, {:.4}) 1/m",
            love.force(),
            k[0],
            k[2]
        ))
    }

    /// The closed-form values where the subject has them.
    pub fn exact(&self, probes: &Probes) -> Option<Values> {
        let Subject::Love(love) = self else {
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

    /// Solves the subject on a mesh and measures it; curvatures at `probes`.
    pub fn solve(
        &self,
        order: Order,
        elements: usize,
        probes: &Probes,
    ) -> Result<Values, SolveError> {
        self.solve_with(order, elements, probes, None)
    }

    /// [`Subject::solve`], stopped (an error of reason
    /// [`StopReason::Interrupted`](crate::solver::continuation::StopReason)) when
    /// `interrupt` is raised: the path checks it between Newton iterations.
    pub fn solve_with(
        &self,
        order: Order,
        elements: usize,
        probes: &Probes,
        interrupt: Option<&Interrupt>,
    ) -> Result<Values, SolveError> {
        match self {
            Subject::Path(case) => {
                let case = with_mesh(case, order, elements);
                let targets = case.output_parameters(case.loading.target, case.loading.steps);
                let outcome = run_path_with(&case, &targets, interrupt.cloned(), None, |_, _| {})?;
                if let Some(e) = outcome.error {
                    return Err(e);
                }
                let last = outcome.points.last().expect("step 0 is always there");
                let response = match case.loading.control {
                    Control::Displacement => last.load[2],
                    Control::Force => last.compression_ratio,
                };
                Ok(Values {
                    response,
                    curvature: sample_curvature(&outcome.model, &outcome.snapshot, probes),
                    critical: outcome.critical.first().map(|c| c.parameter),
                    unknowns: outcome.unknowns,
                    elements: outcome.model.max_elements(),
                })
            }
            Subject::Love(love) => {
                let model = love_model(love, order, elements);
                let sim = Simulation::held_on_helices(
                    model,
                    love.radius(),
                    love.pitch,
                    ContinuationSettings::default(),
                )?;
                let point = sim.load_point(0);
                let response = point.reactions.iter().map(|r| r.tip.force[2]).sum::<f64>()
                    / point.reactions.len() as f64;
                Ok(Values {
                    response,
                    curvature: sample_curvature(sim.model(), &sim.snapshot(), probes),
                    critical: None,
                    unknowns: sim.system().n,
                    elements: sim.model().max_elements(),
                })
            }
        }
    }
}

/// `case` with the mesh `order` x `elements` (and no accuracy target).
pub(crate) fn with_mesh(case: &Case, order: Order, elements: usize) -> Case {
    let mut c = case.clone();
    c.discretisation.order = order;
    c.discretisation.elements = elements;
    c.discretisation.accuracy = None;
    c
}

/// Curvatures `(κ1, κ2, Ω)` (1/m) of every rod of `snapshot` at the arc lengths `probes`
/// (m, rod by rod), as [`fields::curvature_at`] gives them.
pub fn sample_curvature(
    model: &DiscreteModel,
    snapshot: &Snapshot,
    probes: &Probes,
) -> Vec<[f64; 3]> {
    snapshot
        .rods
        .iter()
        .zip(probes)
        .flat_map(|(shape, s)| s.iter().map(|&s| fields::curvature_at(model, shape, s)))
        .collect()
}
