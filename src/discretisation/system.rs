//! The discrete model and its global KKT system (docs/theory.md §5).
//!
//! Unknowns: nodal quaternions (4 per quaternion node) and vertex positions (3 per
//! element vertex) of every rod, then Lagrange multipliers:
//! - per element, a 3-vector `λ` for `r_end − r_start − ∫ d3 ds = 0`: it is the internal
//!   force `n` (N) carried by the element;
//! - per quaternion node, `μ` for `|q|² − 1 = 0`;
//! - linear constraints: supports, prescribed tip height, the positions of joints;
//! - welded joints: the relative rotation of the two rods (bilinear rows, after the linear);
//! - sliding joints: the contact's position on both rods (three rows each, after those;
//!   their arc-length unknowns are primal, [`slide`]).
//!
//! Stationarity of `E + Σ λ·gap + Σ μ (|q|²−1) + Σ ν (a·x − b)` gives the residual; its
//! Jacobian is the symmetric KKT matrix `[[H, Jᵀ], [J, 0]]`, assembled into a sparse
//! pattern that is built once per set of constraints.

use super::cell::end_constraints;
use super::constraints::{joint_constraints, LinearConstraint, Role, TipPlace};
use super::discrete_model::{DiscreteModel, End};
use super::element::{self, ElementLoad, ElementTerms};
use super::joint_rotation::{self, JointRotation};
use super::pressure;
use super::slide::{self, SlideWindow};
use super::support::SupportPose;
use crate::model::assembly::RodId;
use crate::model::boundary::BoundaryConditions;
use crate::model::loading::{AxisLoad, LineLoad, Loads, SupportAxis};
use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat};
use nalgebra::Vector3;

/// Sparse-matrix sink: either records the pattern or scatters values into it, visited in
/// the same order by the same assembly code.
trait Sink {
    fn add(&mut self, row: usize, col: usize, v: f64);
    /// Whether the Jacobian's entries are wanted at all (a residual alone does without the
    /// elements' Hessians).
    fn wants_jacobian(&self) -> bool {
        true
    }
}

struct Recorder(Vec<Pair<usize, usize>>);
impl Sink for Recorder {
    fn add(&mut self, row: usize, col: usize, _v: f64) {
        self.0.push(Pair { row, col });
    }
}

struct Scatter<'a> {
    slots: &'a [usize],
    values: &'a mut [f64],
    next: usize,
}
impl Sink for Scatter<'_> {
    #[inline]
    fn add(&mut self, _row: usize, _col: usize, v: f64) {
        self.values[self.slots[self.next]] += v;
        self.next += 1;
    }
}

/// The KKT system of a discrete model under given boundary conditions.
#[derive(Clone, Debug)]
pub struct System {
    pub bc: BoundaryConditions,
    /// Linear constraints (supports, tip height, joints), in row order after the
    /// inextensibility and unit-norm rows.
    pub linear: Vec<LinearConstraint>,
    /// The rotational parts of welded and elastic joints; the rows of welded ones follow
    /// the linear constraints.
    pub rotations: Vec<JointRotation>,
    /// First row of each rotational part's constraints.
    rotation_rows: Vec<usize>,
    /// The sliding joints and the elements of the pattern around their contacts; their
    /// rows follow the rotational parts'.
    pub slides: Vec<SlideWindow>,
    /// First row of each sliding joint's three multipliers.
    slide_rows: Vec<usize>,
    /// First row of each rod's inextensibility multipliers.
    compat_rows: Vec<usize>,
    /// First row of each rod's unit-norm multipliers.
    unit_rows: Vec<usize>,
    /// First row of the linear constraints.
    linear_row: usize,
    /// Total number of unknowns (primal and multipliers).
    pub n: usize,
    /// What is applied to the assembly, as functions of the load parameter.
    loads: Loads,
    /// The load parameter the system is set to.
    lambda: f64,
    /// The units of the tip support's axial measures: the natural tip height `h0` (m), in
    /// which the compression ratio is measured, and the Euler load `Pcrit` (N), in which the
    /// dead tip load is.
    height0: f64,
    pcrit: f64,
    /// The tip support of a cell: its tilt turns the far ends about the centre of the
    /// tube's curvature ([`SupportPose::of_cell`]), not about the tip's centre.
    cell: bool,
    pattern: SymbolicSparseColMat<usize>,
    slots: Vec<usize>,
}

/// The rows and units of a system that do not depend on its linear constraints.
struct Frame {
    compat_rows: Vec<usize>,
    unit_rows: Vec<usize>,
    linear_row: usize,
    height0: f64,
    pcrit: f64,
    rotations: Vec<JointRotation>,
    slides: Vec<SlideWindow>,
}

/// What an evaluation of the system returns besides the residual.
#[derive(Clone, Copy, Debug, Default)]
pub struct Evaluation {
    /// Total elastic energy (J).
    pub energy: f64,
    /// Potential of the loads along the rods, `−Σ ∫ f·r ds` (J).
    pub potential: f64,
}

impl System {
    /// Builds the constraints of `bc`, holding what they hold at the values of the state
    /// `x` (so that a change of conditions mid-path continues from the current state),
    /// under `loads` at load parameter `lambda`.
    pub fn new(
        model: &DiscreteModel,
        bc: BoundaryConditions,
        x: &[f64],
        loads: &Loads,
        lambda: f64,
    ) -> System {
        let height0 = model.height0();
        let pcrit = model.stiffness.euler_load(model.length());
        let tip = if loads.tip().turns() {
            TipPlace::Turned {
                pose: SupportPose::at(loads, height0, lambda, model.assembly.cell.is_some()),
                height_held: matches!(loads.tip().axis(SupportAxis::Z), AxisLoad::Motion(_)),
            }
        } else {
            TipPlace::Upright {
                height: tip_height(loads, height0, lambda),
            }
        };
        let mut row = model.n_primal;
        let mut compat_rows = Vec::new();
        for rod in &model.rods {
            compat_rows.push(row);
            row += 3 * rod.mesh.elements();
        }
        let mut unit_rows = Vec::new();
        for rod in &model.rods {
            unit_rows.push(row);
            row += rod.mesh.quaternion_nodes();
        }
        let linear_row = row;
        let mut linear = Vec::new();
        end_constraints(model, x, &bc, tip, &mut linear);
        if bc.joints.active() && model.assembly.cell.is_none() {
            for (j, joint) in model.assembly.joints.iter().enumerate() {
                // a sliding joint's rows are its own; one at a rod end stays a pin
                if model.slide_of(j).is_none() {
                    joint_constraints(model, x, &bc, j, joint, &mut linear);
                }
            }
        }
        let rotations = joint_rotation::of_assembly(model, x, &bc, tip);
        let slides = if bc.joints.slides() {
            SlideWindow::of_model(model, x)
        } else {
            Vec::new()
        };
        let frame = Frame {
            compat_rows,
            unit_rows,
            linear_row,
            height0,
            pcrit,
            rotations,
            slides,
        };
        System::with_constraints(model, bc, frame, linear, x, loads, lambda)
    }

    /// This system with the phase condition `phase` added (see
    /// [`constraints::axis_phase`](super::constraints::axis_phase) and
    /// [`constraints::mirror_phase`](super::constraints::mirror_phase)); the
    /// system itself when it already holds one. `x` is the state the pattern is recorded
    /// at.
    pub fn with_phase(&self, model: &DiscreteModel, x: &[f64], phase: LinearConstraint) -> System {
        if self.has_phase() {
            return self.clone();
        }
        let mut linear = self.linear.clone();
        linear.push(phase);
        let frame = Frame {
            compat_rows: self.compat_rows.clone(),
            unit_rows: self.unit_rows.clone(),
            linear_row: self.linear_row,
            height0: self.height0,
            pcrit: self.pcrit,
            rotations: self.rotations.clone(),
            slides: self.slides.clone(),
        };
        let primal = &x[..model.n_primal];
        System::with_constraints(
            model,
            self.bc,
            frame,
            linear,
            primal,
            &self.loads,
            self.lambda,
        )
    }

    /// The phase condition the system holds, if any.
    pub fn phase(&self) -> Option<&LinearConstraint> {
        self.linear.iter().find(|c| c.role == Role::Phase)
    }

    /// The row of the phase condition's multiplier, if the system holds one (the rows of
    /// the joints' rotations follow it).
    pub fn phase_row(&self) -> Option<usize> {
        let i = self.linear.iter().position(|c| c.role == Role::Phase)?;
        Some(self.linear_row + i)
    }

    /// Whether the system holds a phase condition (see [`System::with_phase`]).
    pub fn has_phase(&self) -> bool {
        self.phase().is_some()
    }

    /// The system of the constraints `linear` (rows from `frame.linear_row` on), its
    /// pattern recorded at the state `x` (primal unknowns at least).
    fn with_constraints(
        model: &DiscreteModel,
        bc: BoundaryConditions,
        frame: Frame,
        linear: Vec<LinearConstraint>,
        x: &[f64],
        loads: &Loads,
        lambda: f64,
    ) -> System {
        let Frame {
            compat_rows,
            unit_rows,
            linear_row,
            height0,
            pcrit,
            rotations,
            slides,
        } = frame;
        // the joints' rotation rows follow the linear constraints, the sliding joints' those
        let mut row = linear_row + linear.len();
        let mut rotation_rows = Vec::new();
        for r in &rotations {
            rotation_rows.push(row);
            row += r.rows();
        }
        let mut slide_rows = Vec::new();
        for _ in &slides {
            slide_rows.push(row);
            row += 3;
        }
        let n = row;
        let mut sys = System {
            bc,
            linear,
            rotations,
            rotation_rows,
            slides,
            slide_rows,
            compat_rows,
            unit_rows,
            linear_row,
            n,
            loads: loads.clone(),
            lambda,
            height0,
            pcrit,
            cell: model.assembly.cell.is_some(),
            pattern: SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, vec![]),
            slots: Vec::new(),
        };
        sys.record_pattern(model, x);
        sys
    }

    /// This system with the windows of its sliding joints re-centred on where the state `x`
    /// (all unknowns) has their contacts: the same unknowns and rows, another pattern.
    pub fn recentred(&self, model: &DiscreteModel, x: &[f64]) -> System {
        let mut sys = self.clone();
        sys.slides = SlideWindow::of_model(model, x);
        sys.record_pattern(model, x);
        sys
    }

    /// Whether a sliding joint's contact in the state `x` is near its window's edge
    /// ([`SlideWindow::stale`]): then [`System::recentred`] should follow.
    pub fn slides_stale(&self, model: &DiscreteModel, x: &[f64]) -> bool {
        self.slides.iter().any(|w| w.stale(model, x))
    }

    /// Row of sliding joint `k`'s first multiplier `ν` (N), of `g = r_R − T r_L`: the joint
    /// pushes the right rod with `−ν` and the left one with `Tᵀ ν`.
    pub fn slide_row(&self, k: usize) -> usize {
        self.slide_rows[k]
    }

    /// Records the KKT pattern at the state `x` (primal unknowns at least) with the same
    /// code that assembles the values.
    fn record_pattern(&mut self, model: &DiscreteModel, x: &[f64]) {
        let sys = self;
        let n = sys.n;
        let mut full = x.to_vec();
        full.resize(n, 0.0);
        let mut rec = Recorder(Vec::new());
        let mut res = vec![0.0; n];
        sys.assemble(model, &full, &mut res, &mut rec);
        let pairs = rec.0;
        let (pattern, _) = SymbolicSparseColMat::try_new_from_indices(n, n, &pairs)
            .expect("KKT pattern indices are in range");
        let col_ptr = pattern.col_ptr();
        let row_idx = pattern.row_idx();
        sys.slots = pairs
            .iter()
            .map(|p| {
                let rows = &row_idx[col_ptr[p.col]..col_ptr[p.col + 1]];
                col_ptr[p.col] + rows.binary_search(&p.row).expect("entry in pattern")
            })
            .collect();
        sys.pattern = pattern;
    }

    /// The sparsity pattern of the KKT matrix.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    /// The position in the KKT matrix's values of its entry `(row, col)`, which the
    /// pattern must store.
    pub fn entry(&self, row: usize, col: usize) -> usize {
        let cp = self.pattern.col_ptr();
        let rows = &self.pattern.row_idx()[cp[col]..cp[col + 1]];
        cp[col] + rows.binary_search(&row).expect("entry in the KKT pattern")
    }

    /// Number of stored entries of the KKT matrix.
    pub fn nnz(&self) -> usize {
        self.pattern.row_idx().len()
    }

    /// A zeroed value array matching the pattern.
    pub fn new_values(&self) -> Vec<f64> {
        vec![0.0; self.pattern.row_idx().len()]
    }

    /// The KKT matrix as a faer sparse view over `values`.
    pub fn matrix<'a>(&'a self, values: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.pattern.as_ref(), values)
    }

    /// What is applied to the assembly.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// The load parameter the system is set to.
    pub fn parameter(&self) -> f64 {
        self.lambda
    }

    /// The tip support's pose at `lambda`.
    pub fn pose(&self, lambda: f64) -> SupportPose {
        SupportPose::at(&self.loads, self.height0, lambda, self.cell)
    }

    /// Sets the load parameter: the prescribed motions of the supports and the dead loads
    /// take their values at `lambda`.
    pub fn set_parameter(&mut self, lambda: f64) {
        self.lambda = lambda;
        if let Some(h) = tip_height(&self.loads, self.height0, lambda) {
            for c in &mut self.linear {
                if matches!(c.role, Role::TipHeight { .. }) && c.moving.is_none() {
                    c.value = h;
                }
            }
        }
        let pose = self.pose(lambda);
        for c in &mut self.linear {
            if let Some(moving) = &c.moving {
                let (coeffs, value) = moving.coefficients(&pose, false);
                for (term, a) in c.terms.iter_mut().zip(coeffs) {
                    term.1 = a;
                }
                c.value = value;
            }
        }
    }

    /// The dead force (N) on every rod's tip along z at the current load parameter: `−P`,
    /// `P = Pcrit · (P/Pcrit)` (compressive positive), when the tip support's z carries a
    /// dead load.
    pub(super) fn tip_force_z(&self) -> Option<f64> {
        match self.loads.tip().axis(SupportAxis::Z) {
            AxisLoad::Force(r) => Some(-(self.pcrit * r.at(self.lambda))),
            AxisLoad::Motion(_) => None,
        }
    }

    /// Residual `∇L` (into `residual`) and KKT matrix (into `values`) at `x`.
    pub fn evaluate(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        residual: &mut [f64],
        values: &mut [f64],
    ) -> Evaluation {
        values.iter_mut().for_each(|v| *v = 0.0);
        let mut sink = Scatter {
            slots: &self.slots,
            values,
            next: 0,
        };
        self.assemble(model, x, residual, &mut sink)
    }

    /// Residual only (no matrix).
    pub fn residual(&self, model: &DiscreteModel, x: &[f64], residual: &mut [f64]) -> Evaluation {
        struct Null;
        impl Sink for Null {
            fn add(&mut self, _: usize, _: usize, _: f64) {}
            fn wants_jacobian(&self) -> bool {
                false
            }
        }
        self.assemble(model, x, residual, &mut Null)
    }

    /// Weights that make every row of the residual dimensionless, for Newton's
    /// convergence test (`max_i |w_i R_i| ≤ tolerance`), in the problem's own scales: the
    /// stiffness `B1` (N m²) and the rod length `L` (m), the length `Pcrit = B1 (2π/L)²` is
    /// measured in. Balance rows of a quaternion unknown are moments (J): `w = L/B1`; of a
    /// position unknown, forces (N): `w = L²/B1`; inextensibility rows and linear
    /// constraints on positions (supports, tip height, joints) are lengths (m): `w = 1/L`;
    /// unit norms and constraints on quaternions (held orientations) are pure numbers:
    /// `w = 1`. Changing the units of length or force (every length ×s, every stiffness
    /// ×f s²) therefore leaves every weighted row, and so the path, unchanged.
    pub fn residual_weights(&self, model: &DiscreteModel, weights: &mut [f64]) {
        let b1 = model.stiffness.b1;
        let l = model.length();
        weights.fill(1.0);
        // primal rows: quaternions first marked as moments, positions as forces
        let mut is_position = vec![false; model.n_primal];
        for rod in &model.rods {
            for node in 0..rod.mesh.quaternion_nodes() {
                for k in 0..4 {
                    weights[rod.q_dof(node, k)] = l / b1;
                }
            }
            for vertex in 0..=rod.mesh.elements() {
                for k in 0..3 {
                    weights[rod.r_dof(vertex, k)] = l * l / b1;
                    is_position[rod.r_dof(vertex, k)] = true;
                }
            }
        }
        for (id, rod) in model.rods.iter().enumerate() {
            for e in 0..rod.mesh.elements() {
                for k in 0..3 {
                    weights[self.compat_row(id, e) + k] = 1.0 / l;
                }
            }
        }
        for (i, c) in self.linear.iter().enumerate() {
            if c.terms.iter().any(|&(dof, _)| is_position[dof]) {
                weights[self.linear_row(i)] = 1.0 / l;
            }
        }
        // a contact's arc length balances forces along the rods (N); its rows are lengths
        for (k, row) in self.slide_rows.iter().enumerate() {
            for side in 0..2 {
                weights[model.slide_dof(k, side)] = l * l / b1;
            }
            for j in 0..3 {
                weights[row + j] = 1.0 / l;
            }
        }
    }

    /// Row of the inextensibility multiplier of element `e` of rod `rod` (its first component).
    pub fn compat_row(&self, rod: RodId, e: usize) -> usize {
        self.compat_rows[rod] + 3 * e
    }

    /// Row of the unit-norm multiplier of quaternion node `k` of rod `rod`.
    pub fn unit_row(&self, rod: RodId, k: usize) -> usize {
        self.unit_rows[rod] + k
    }

    /// The multiplier (a generalised force) of the phase condition in the state `x`, if the
    /// system holds one: zero at every solution when the symmetry the condition stands on
    /// holds.
    pub fn phase_multiplier(&self, x: &[f64]) -> Option<f64> {
        x.get(self.phase_row()?).copied()
    }

    /// Row of linear constraint `i`.
    pub fn linear_row(&self, i: usize) -> usize {
        self.linear_row + i
    }

    /// Rows whose constraint value moves with the tip height, with `∂g/∂h = −1`.
    pub fn height_rows(&self) -> impl Iterator<Item = usize> + '_ {
        self.linear
            .iter()
            .enumerate()
            .filter(|(_, c)| matches!(c.role, Role::TipHeight { .. }) && c.moving.is_none())
            .map(|(i, _)| self.linear_row + i)
    }

    /// Whether `∂R/∂λ` is the same at every state and load parameter (the loads' values
    /// are affine in `λ` and none depends on the state).
    pub fn load_derivative_is_constant(&self) -> bool {
        self.loads.along_rods().is_empty() && self.linear.iter().all(|c| c.moving.is_none())
    }

    /// `∂R/∂λ` at the state `x` and load parameter `lambda`, from the loads: on the tip-height rows
    /// `∂g/∂λ = −∂h/∂λ = h0 ∂ε/∂λ` under a prescribed axial motion; on the tip z unknowns
    /// `−∂F/∂λ = Pcrit ∂(P/Pcrit)/∂λ` under a dead axial load.
    pub fn load_derivative(&self, model: &DiscreteModel, x: &[f64], lambda: f64, out: &mut [f64]) {
        out.fill(0.0);
        match self.loads.tip().axis(SupportAxis::Z) {
            AxisLoad::Motion(r) => {
                let rate = self.height0 * r.rate(lambda);
                for row in self.height_rows() {
                    out[row] = rate;
                }
            }
            AxisLoad::Force(r) => {
                let rate = self.pcrit * r.rate(lambda);
                for rod in &model.rods {
                    out[rod.r_dof(rod.end_vertex(End::Tip), 2)] = rate;
                }
            }
        }
        self.add_line_load_derivative(model, x, lambda, out);
        self.add_turning_derivative(x, lambda, out);
        let rate = self.loads.pressure(lambda).1;
        if rate != 0.0 {
            for share in pressure::shares(model, x) {
                for k in 0..2 {
                    out[share.dofs[k]] += rate * share.gradient[k];
                }
            }
        }
    }

    /// `∂R/∂λ` of the constraints of a turning tip support, added to `out`:
    /// `(∂a/∂λ)·x − ∂b/∂λ` on each one's row and `ν ∂a/∂λ` on its unknowns.
    fn add_turning_derivative(&self, x: &[f64], lambda: f64, out: &mut [f64]) {
        if self.linear.iter().all(|c| c.moving.is_none()) {
            return;
        }
        let pose = self.pose(lambda);
        for (i, c) in self.linear.iter().enumerate() {
            let Some(moving) = &c.moving else { continue };
            let row = self.linear_row + i;
            let nu = x[row];
            let (rates, value_rate) = moving.coefficients(&pose, true);
            let mut g = -value_rate;
            for (&(d, _), da) in c.terms.iter().zip(rates) {
                g += da * x[d];
                out[d] += nu * da;
            }
            out[row] += g;
        }
    }

    fn assemble(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        residual: &mut [f64],
        sink: &mut dyn Sink,
    ) -> Evaluation {
        residual.iter_mut().for_each(|v| *v = 0.0);
        let jacobian = sink.wants_jacobian();
        let nn = model.order.nodes();
        let p = model.order.degree();
        let mut energy = 0.0;
        let mut potential = 0.0;
        let line = self.line_load(self.lambda);
        // explicit diagonal, so that every row has a stored diagonal entry
        for i in 0..self.n {
            sink.add(i, i, 0.0);
        }
        for (id, rod) in model.rods.iter().enumerate() {
            for e in 0..rod.mesh.elements() {
                let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                let q = model.element_quaternions(x, rod, e);
                let lrow = self.compat_row(id, e);
                let lambda = [x[lrow], x[lrow + 1], x[lrow + 2]];
                let t: ElementTerms = element::element_terms(
                    model.order,
                    &model.rule,
                    h,
                    &q,
                    &model.stiffness,
                    &model.elasticity,
                    rod.element_reference(e, model.rule.len()),
                    &lambda,
                    &line,
                    jacobian,
                );
                energy += t.energy;
                let dofs = |i: usize| rod.q_dof(e * p + i / 4, i % 4);
                let nq = 4 * nn;
                for i in 0..nq {
                    let gi = dofs(i);
                    let mut g = t.energy_gradient[i];
                    for j in 0..3 {
                        g -= lambda[j] * t.chord_gradient[j][i];
                    }
                    residual[gi] += g;
                    if !jacobian {
                        continue;
                    }
                    for k in 0..nq {
                        sink.add(gi, dofs(k), t.hessian[i][k]);
                    }
                    for j in 0..3 {
                        sink.add(gi, lrow + j, -t.chord_gradient[j][i]);
                        sink.add(lrow + j, gi, -t.chord_gradient[j][i]);
                    }
                }
                if line != ElementLoad::NONE {
                    // −f·∫ r ds = −h f·r_start − f·∫ (h − s) d3 ds
                    potential += t.load_potential;
                    for i in 0..nq {
                        residual[dofs(i)] += t.load_gradient[i];
                    }
                    for j in 0..3 {
                        potential -= h * line.force[j] * x[rod.r_dof(e, j)];
                        residual[rod.r_dof(e, j)] -= h * line.force[j];
                    }
                }
                for j in 0..3 {
                    let (ra, rb) = (rod.r_dof(e, j), rod.r_dof(e + 1, j));
                    residual[ra] -= lambda[j];
                    residual[rb] += lambda[j];
                    residual[lrow + j] = x[rb] - x[ra] - t.chord[j];
                    sink.add(ra, lrow + j, -1.0);
                    sink.add(lrow + j, ra, -1.0);
                    sink.add(rb, lrow + j, 1.0);
                    sink.add(lrow + j, rb, 1.0);
                }
            }
            self.assemble_unit_norms(model, id, x, residual, sink);
        }
        if let Some(f) = self.tip_force_z() {
            // potential of the dead load: −F z_tip per rod
            for rod in &model.rods {
                residual[rod.r_dof(rod.end_vertex(End::Tip), 2)] -= f;
            }
        }
        potential += self.assemble_pressure(model, x, residual, sink);
        self.assemble_linear(x, residual, sink);
        energy += self.assemble_rotations(x, residual, sink);
        let mut add = |row: usize, col: usize, v: f64| sink.add(row, col, v);
        slide::assemble(model, &self.slides, &self.slide_rows, x, residual, &mut add);
        Evaluation { energy, potential }
    }

    /// The unit-norm rows `|q|² − 1 = 0` of rod `id`'s quaternion nodes, with their
    /// multipliers' terms `μ (|q|² − 1)` in the balance of the quaternions.
    fn assemble_unit_norms(
        &self,
        model: &DiscreteModel,
        id: RodId,
        x: &[f64],
        residual: &mut [f64],
        sink: &mut dyn Sink,
    ) {
        let rod = &model.rods[id];
        for k in 0..rod.mesh.quaternion_nodes() {
            let row = self.unit_row(id, k);
            let mu = x[row];
            let mut norm2 = 0.0;
            for c in 0..4 {
                let d = rod.q_dof(k, c);
                norm2 += x[d] * x[d];
                residual[d] += 2.0 * mu * x[d];
                sink.add(d, d, 2.0 * mu);
                sink.add(d, row, 2.0 * x[d]);
                sink.add(row, d, 2.0 * x[d]);
            }
            residual[row] = norm2 - 1.0;
        }
    }

    /// The radial pressure's terms (its gradient and Hessian, [`pressure`]), and its
    /// potential (J). Visited whenever the loads have a radial pressure, at any value, so
    /// that the pattern holds its entries.
    fn assemble_pressure(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        residual: &mut [f64],
        sink: &mut dyn Sink,
    ) -> f64 {
        let radial = self
            .loads
            .along_rods()
            .iter()
            .any(|l| matches!(l, LineLoad::Radial { .. }));
        if !radial {
            return 0.0;
        }
        let q = self.loads.pressure(self.lambda).0;
        let jacobian = sink.wants_jacobian();
        let mut potential = 0.0;
        for share in pressure::shares(model, x) {
            potential += q * share.potential;
            for i in 0..2 {
                residual[share.dofs[i]] += q * share.gradient[i];
                if jacobian {
                    for j in 0..2 {
                        sink.add(share.dofs[i], share.dofs[j], q * share.hessian[i][j]);
                    }
                }
            }
        }
        potential
    }

    /// The linear constraints' rows `a·x − b` and their multipliers' terms `ν a`.
    fn assemble_linear(&self, x: &[f64], residual: &mut [f64], sink: &mut dyn Sink) {
        for (i, c) in self.linear.iter().enumerate() {
            let row = self.linear_row + i;
            let nu = x[row];
            let mut g = -c.value;
            for &(d, a) in &c.terms {
                g += a * x[d];
                residual[d] += nu * a;
                sink.add(d, row, a);
                sink.add(row, d, a);
            }
            residual[row] = g;
        }
    }

    /// The joints' rotational terms ([`joint_rotation::assemble`]): the springs' energy (J).
    fn assemble_rotations(&self, x: &[f64], residual: &mut [f64], sink: &mut dyn Sink) -> f64 {
        let mut add = |row: usize, col: usize, v: f64| sink.add(row, col, v);
        joint_rotation::assemble(&self.rotations, &self.rotation_rows, x, residual, &mut add)
    }

    /// The multipliers (rows) of rotational part `i` of the joints in the state `x`.
    pub fn rotation_multipliers<'a>(&self, x: &'a [f64], i: usize) -> &'a [f64] {
        let row = self.rotation_rows[i];
        &x[row..row + self.rotations[i].rows()]
    }

    /// First row of rotational part `i` of the joints.
    pub fn rotation_row(&self, i: usize) -> usize {
        self.rotation_rows[i]
    }

    /// The force per unit length (N/m) of the loads along the rods at load parameter
    /// `lambda` (their sum: every one is uniform), or its rate `d/dλ` with `rate`.
    fn line_load_of(&self, lambda: f64, rate: bool) -> ElementLoad {
        let mut force = [0.0; 3];
        for load in self.loads.along_rods() {
            let f = if rate {
                load.rate(lambda)
            } else {
                load.force(lambda)
            };
            for j in 0..3 {
                force[j] += f[j];
            }
        }
        ElementLoad { force }
    }

    fn line_load(&self, lambda: f64) -> ElementLoad {
        self.line_load_of(lambda, false)
    }

    /// The force per unit length (N/m) of the loads along the rods at the system's load
    /// parameter.
    pub fn element_load(&self) -> ElementLoad {
        self.line_load(self.lambda)
    }

    /// `∂R/∂λ` of the loads along the rods at the state `x`, added to `out`: the gradient of
    /// the potential of a line load of the rate's force.
    fn add_line_load_derivative(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        lambda: f64,
        out: &mut [f64],
    ) {
        let rate = self.line_load_of(lambda, true);
        if rate == ElementLoad::NONE {
            return;
        }
        let nq = 4 * model.order.nodes();
        let p = model.order.degree();
        for (id, rod) in model.rods.iter().enumerate() {
            for e in 0..rod.mesh.elements() {
                let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                let q = model.element_quaternions(x, rod, e);
                let lrow = self.compat_row(id, e);
                let t = element::element_terms(
                    model.order,
                    &model.rule,
                    h,
                    &q,
                    &model.stiffness,
                    &model.elasticity,
                    rod.element_reference(e, model.rule.len()),
                    &[x[lrow], x[lrow + 1], x[lrow + 2]],
                    &rate,
                    false,
                );
                for i in 0..nq {
                    out[rod.q_dof(e * p + i / 4, i % 4)] += t.load_gradient[i];
                }
                for j in 0..3 {
                    out[rod.r_dof(e, j)] -= h * rate.force[j];
                }
            }
        }
    }

    /// Internal force `n` (N, global frame) carried by element `e` of rod `rod` in state `x`:
    /// the multiplier `λ` of its constraint `r_end − r_start − ∫ d3 ds = 0`, the force that
    /// the rod beyond the element exerts on it (at the tip it equals the tip support's force).
    pub fn internal_force(&self, x: &[f64], rod: RodId, e: usize) -> Vector3<f64> {
        let row = self.compat_row(rod, e);
        Vector3::new(x[row], x[row + 1], x[row + 2])
    }
}

/// The tip's height (m) at load parameter `lambda` when the tip support's z is a prescribed
/// motion: `h = h0 (1 − ε)`, `ε` the compression ratio it prescribes.
fn tip_height(loads: &Loads, height0: f64, lambda: f64) -> Option<f64> {
    match loads.tip().axis(SupportAxis::Z) {
        AxisLoad::Motion(r) => Some(height0 * (1.0 - r.at(lambda))),
        AxisLoad::Force(_) => None,
    }
}
