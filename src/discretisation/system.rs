//! The discrete model and its global KKT system (DESIGN.md §5).
//!
//! Unknowns: nodal quaternions (4 per quaternion node) and vertex positions (3 per
//! element vertex) of every rod, then Lagrange multipliers:
//! - per element, a 3-vector `λ` for `r_end − r_start − ∫ d3 ds = 0`: it is the internal
//!   force `n` (N) carried by the element;
//! - per quaternion node, `μ` for `|q|² − 1 = 0`;
//! - linear constraints: supports, prescribed tip height, pin joints.
//!
//! Stationarity of `E + Σ λ·gap + Σ μ (|q|²−1) + Σ ν (a·x − b)` gives the residual; its
//! Jacobian is the symmetric KKT matrix `[[H, Jᵀ], [J, 0]]`, assembled into a sparse
//! pattern that is built once per set of constraints.

use super::element::{self, ElementTerms, Order, QuadraturePoint, Stiffness, MAX_NODES};
use super::mesh::RodMesh;
use crate::model::assembly::{Assembly, Joint, RodId};
use crate::model::boundary::{BoundaryConditions, EndCondition, Rotation, Translation};
use crate::model::helix::Helix;
use crate::model::quaternion::{self, Quat};
use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat};
use nalgebra::{Vector3, Vector4};

/// How the tips are loaded along the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipLoad {
    /// Displacement control: every tip held at height `z = h` (m).
    Height(f64),
    /// Load control: a dead compressive force `P` (N) on every tip, along −z.
    Force(f64),
}

/// Rod end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    Base,
    Tip,
}

/// What a linear constraint represents (used to read reactions off its multiplier).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Held by the support at a rod end.
    Support { rod: RodId, end: End },
    /// The prescribed tip height `z = h` of a rod.
    TipHeight { rod: RodId },
    /// A pin joint (index into the model's joints).
    Joint(usize),
}

/// `Σ c_k x_k − value = 0`.
#[derive(Clone, Debug)]
pub struct LinearConstraint {
    pub terms: Vec<(usize, f64)>,
    pub value: f64,
    pub role: Role,
}

/// One rod of the discrete model.
#[derive(Clone, Debug)]
pub struct DiscreteRod {
    /// The natural helix (initial state, intrinsic curvature).
    pub helix: Helix,
    pub mesh: RodMesh,
    /// Intrinsic curvatures `(κ1*, κ2*, Ω*)` (1/m).
    pub natural: Vector3<f64>,
    /// First quaternion unknown.
    pub q_offset: usize,
    /// First position unknown.
    pub r_offset: usize,
}

impl DiscreteRod {
    /// Unknown of component `k` of quaternion node `node`.
    pub fn q_dof(&self, node: usize, k: usize) -> usize {
        self.q_offset + 4 * node + k
    }
    /// Unknown of component `k` of vertex `vertex`.
    pub fn r_dof(&self, vertex: usize, k: usize) -> usize {
        self.r_offset + 3 * vertex + k
    }
    /// Quaternion node at an end.
    pub fn end_node(&self, end: End) -> usize {
        match end {
            End::Base => 0,
            End::Tip => self.mesh.quaternion_nodes() - 1,
        }
    }
    /// Vertex at an end.
    pub fn end_vertex(&self, end: End) -> usize {
        match end {
            End::Base => 0,
            End::Tip => self.mesh.elements(),
        }
    }
}

/// Rods, meshes, stiffness and joints: everything but the boundary conditions.
#[derive(Clone, Debug)]
pub struct DiscreteModel {
    pub assembly: Assembly,
    pub rods: Vec<DiscreteRod>,
    pub stiffness: Stiffness,
    pub order: Order,
    pub rule: Vec<QuadraturePoint>,
    /// Number of primal unknowns (quaternions and positions).
    pub n_primal: usize,
    /// The element count the meshes were asked for (before joints split them).
    pub requested_elements: usize,
}

impl DiscreteModel {
    /// Meshes every rod with about `elements` elements of the given order, with vertices
    /// at its joints.
    pub fn new(
        assembly: Assembly,
        stiffness: Stiffness,
        elements: usize,
        order: Order,
    ) -> DiscreteModel {
        let mut offset = 0;
        let rods = assembly
            .rods
            .iter()
            .enumerate()
            .map(|(id, helix)| {
                let mesh = RodMesh::new(
                    assembly.length,
                    elements,
                    order,
                    &assembly.joint_arc_lengths(id),
                );
                let q_offset = offset;
                let r_offset = q_offset + 4 * mesh.quaternion_nodes();
                offset = r_offset + 3 * (mesh.elements() + 1);
                DiscreteRod {
                    helix: *helix,
                    natural: helix.natural_curvature(),
                    mesh,
                    q_offset,
                    r_offset,
                }
            })
            .collect();
        DiscreteModel {
            rule: element::quadrature(order),
            assembly,
            rods,
            stiffness,
            order,
            n_primal: offset,
            requested_elements: elements,
        }
    }

    /// For a symmetric pair: the full model it stands for (same meshes).
    pub fn full_model(&self) -> Option<DiscreteModel> {
        let sym = self.assembly.symmetry?;
        let pair = &self.assembly.rods;
        let full = Assembly::new(
            sym.full_rods(),
            pair[0].radius,
            pair[0].pitch,
            self.length(),
        );
        Some(DiscreteModel::new(
            full,
            self.stiffness,
            self.requested_elements,
            self.order,
        ))
    }

    /// Rod length `L` (m).
    pub fn length(&self) -> f64 {
        self.assembly.length
    }

    /// Initial tip height `h0` (m).
    pub fn height0(&self) -> f64 {
        self.assembly.height()
    }

    /// The natural state: nodal quaternions and positions of the free helices.
    pub fn natural_state(&self) -> Vec<f64> {
        let helices: Vec<Helix> = self.rods.iter().map(|r| r.helix).collect();
        self.helix_state(&helices)
    }

    /// The primal state in which rod `i` lies on `helices[i]` (nodal quaternions of its
    /// directors and vertex positions), e.g. to prescribe ends on other helices.
    pub fn helix_state(&self, helices: &[Helix]) -> Vec<f64> {
        let mut x = vec![0.0; self.n_primal];
        for (rod, helix) in self.rods.iter().zip(helices) {
            let s: Vec<f64> = (0..rod.mesh.quaternion_nodes())
                .map(|k| rod.mesh.node_arc_length(k))
                .collect();
            for (k, q) in helix.quaternion_field(&s).iter().enumerate() {
                for c in 0..4 {
                    x[rod.q_dof(k, c)] = q[c];
                }
            }
            for (v, &sv) in rod.mesh.vertices.iter().enumerate() {
                let r = helix.position(sv);
                for c in 0..3 {
                    x[rod.r_dof(v, c)] = r[c];
                }
            }
        }
        x
    }

    /// Nodal quaternion of a rod in state `x`.
    pub fn quaternion(&self, x: &[f64], rod: RodId, node: usize) -> Quat {
        let r = &self.rods[rod];
        Quat::from_fn(|k, _| x[r.q_dof(node, k)])
    }

    /// Vertex position of a rod in state `x` (m).
    pub fn vertex(&self, x: &[f64], rod: RodId, vertex: usize) -> Vector3<f64> {
        let r = &self.rods[rod];
        Vector3::from_fn(|k, _| x[r.r_dof(vertex, k)])
    }

    fn element_quaternions(&self, x: &[f64], rod: &DiscreteRod, e: usize) -> [[f64; 4]; MAX_NODES] {
        let p = self.order.degree();
        let mut q = [[0.0; 4]; MAX_NODES];
        for (a, qa) in q.iter_mut().enumerate().take(p + 1) {
            for (k, v) in qa.iter_mut().enumerate() {
                *v = x[rod.q_dof(e * p + a, k)];
            }
        }
        q
    }
}

/// Sparse-matrix sink: either records the pattern or scatters values into it, visited in
/// the same order by the same assembly code.
trait Sink {
    fn add(&mut self, row: usize, col: usize, v: f64);
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
    /// First row of each rod's inextensibility multipliers.
    compat_rows: Vec<usize>,
    /// First row of each rod's unit-norm multipliers.
    unit_rows: Vec<usize>,
    /// First row of the linear constraints.
    linear_row: usize,
    /// Total number of unknowns (primal and multipliers).
    pub n: usize,
    /// The axial loading of the tips.
    pub tip_load: TipLoad,
    pattern: SymbolicSparseColMat<usize>,
    slots: Vec<usize>,
}

/// What an evaluation of the system returns besides the residual.
#[derive(Clone, Copy, Debug, Default)]
pub struct Evaluation {
    /// Total elastic energy (J).
    pub energy: f64,
}

impl System {
    /// Builds the constraints of `bc`, holding what they hold at the values of the state
    /// `x` (so that a change of conditions mid-path continues from the current state),
    /// with the tips loaded by `tip_load`.
    pub fn new(
        model: &DiscreteModel,
        bc: BoundaryConditions,
        x: &[f64],
        tip_load: TipLoad,
    ) -> System {
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
        for (id, rod) in model.rods.iter().enumerate() {
            for (end, cond) in [(End::Base, bc.base), (End::Tip, bc.tip)] {
                support_constraints(model, x, id, rod, end, cond, tip_load, &mut linear);
            }
        }
        if bc.joints {
            for (j, joint) in model.assembly.joints.iter().enumerate() {
                joint_constraints(model, x, &bc, j, joint, &mut linear);
            }
        }
        let n = linear_row + linear.len();
        let mut sys = System {
            bc,
            linear,
            compat_rows,
            unit_rows,
            linear_row,
            n,
            tip_load,
            pattern: SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, vec![]),
            slots: Vec::new(),
        };
        // record the pattern with the same code that assembles the values
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
        sys
    }

    /// The sparsity pattern of the KKT matrix.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
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

    /// Sets the tip loading; the kind (height or force) must stay the one the system was
    /// built with, since it decides the constraints.
    pub fn set_tip_load(&mut self, tip_load: TipLoad) {
        debug_assert_eq!(
            std::mem::discriminant(&tip_load),
            std::mem::discriminant(&self.tip_load)
        );
        self.tip_load = tip_load;
        if let TipLoad::Height(h) = tip_load {
            for c in &mut self.linear {
                if matches!(c.role, Role::TipHeight { .. }) {
                    c.value = h;
                }
            }
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
        }
        self.assemble(model, x, residual, &mut Null)
    }

    /// Row of the inextensibility multiplier of element `e` of rod `rod` (its first component).
    pub fn compat_row(&self, rod: RodId, e: usize) -> usize {
        self.compat_rows[rod] + 3 * e
    }

    /// Row of the unit-norm multiplier of quaternion node `k` of rod `rod`.
    pub fn unit_row(&self, rod: RodId, k: usize) -> usize {
        self.unit_rows[rod] + k
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
            .filter(|(_, c)| matches!(c.role, Role::TipHeight { .. }))
            .map(|(i, _)| self.linear_row + i)
    }

    /// `∂R/∂P` of the tip load parameter: the tip-height rows (`∂g/∂h = −1`) under
    /// displacement control, the tip z unknowns (`+1`) under load control.
    pub fn load_derivative(&self, model: &DiscreteModel) -> Vec<f64> {
        let mut d = vec![0.0; self.n];
        match self.tip_load {
            TipLoad::Height(_) => {
                for row in self.height_rows() {
                    d[row] = -1.0;
                }
            }
            TipLoad::Force(_) => {
                for rod in &model.rods {
                    d[rod.r_dof(rod.end_vertex(End::Tip), 2)] = 1.0;
                }
            }
        }
        d
    }

    fn assemble(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        residual: &mut [f64],
        sink: &mut dyn Sink,
    ) -> Evaluation {
        residual.iter_mut().for_each(|v| *v = 0.0);
        let nn = model.order.nodes();
        let p = model.order.degree();
        let mut energy = 0.0;
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
                    &rod.natural,
                    &lambda,
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
                    for k in 0..nq {
                        sink.add(gi, dofs(k), t.hessian[i][k]);
                    }
                    for j in 0..3 {
                        sink.add(gi, lrow + j, -t.chord_gradient[j][i]);
                        sink.add(lrow + j, gi, -t.chord_gradient[j][i]);
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
        if let TipLoad::Force(p) = self.tip_load {
            // potential of the dead load: +P z_tip per rod
            for rod in &model.rods {
                residual[rod.r_dof(rod.end_vertex(End::Tip), 2)] += p;
            }
        }
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
        Evaluation { energy }
    }

    /// Force (N) and moment (N m) that the support (and, under load control, the dead
    /// load at the tip) applies to rod `rod` at `end`, in the global frame, from the
    /// multipliers of its support constraints: the generalised
    /// reaction is `−ν ∂g/∂x`, and a virtual rotation `δθ` moves `q` by `½ (δθ, 0) ∘ q`.
    pub fn reaction(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        rod: RodId,
        end: End,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let r = &model.rods[rod];
        let node = r.end_node(end);
        let vertex = r.end_vertex(end);
        let mut force = Vector3::zeros();
        let mut fq = Vector4::zeros();
        for (i, c) in self.linear.iter().enumerate() {
            let held = match c.role {
                Role::Support { rod: rr, end: ee } => rr == rod && ee == end,
                Role::TipHeight { rod: rr } => rr == rod && end == End::Tip,
                Role::Joint(_) => false,
            };
            if !held {
                continue;
            }
            let nu = x[self.linear_row + i];
            for &(d, a) in &c.terms {
                for k in 0..3 {
                    if d == r.r_dof(vertex, k) {
                        force[k] -= nu * a;
                    }
                }
                for k in 0..4 {
                    if d == r.q_dof(node, k) {
                        fq[k] -= nu * a;
                    }
                }
            }
        }
        if let (TipLoad::Force(p), End::Tip) = (self.tip_load, end) {
            // under load control the tip is loaded by the dead load itself
            force[2] -= p;
        }
        let q = model.quaternion(x, rod, node);
        let moment = Vector3::from_fn(|i, _| {
            let mut e = Quat::zeros();
            e[i] = 1.0;
            0.5 * fq.dot(&quaternion::mul(&e, &q))
        });
        (force, moment)
    }
}

/// Orthonormal directions along which a support of this kind holds an end at `position`,
/// besides the axial one: `Fixed` holds x and y, `Radial` the azimuthal direction,
/// `Slide` nothing.
fn held_directions(t: Translation, position: &Vector3<f64>) -> Vec<Vector3<f64>> {
    match t {
        Translation::Fixed => vec![Vector3::x(), Vector3::y()],
        Translation::Slide => vec![],
        Translation::Radial => {
            let radial = Vector3::new(position[0], position[1], 0.0);
            if radial.norm() > 0.0 {
                let er = radial / radial.norm();
                vec![Vector3::new(-er[1], er[0], 0.0)]
            } else {
                vec![Vector3::x(), Vector3::y()]
            }
        }
    }
}

/// In-plane directions left free by a support of this kind (the complement of
/// [`held_directions`] in the x–y plane).
fn free_directions(t: Translation, position: &Vector3<f64>) -> Vec<Vector3<f64>> {
    match t {
        Translation::Fixed => vec![],
        Translation::Slide => vec![Vector3::x(), Vector3::y()],
        Translation::Radial => {
            let radial = Vector3::new(position[0], position[1], 0.0);
            if radial.norm() > 0.0 {
                vec![radial / radial.norm()]
            } else {
                vec![]
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn support_constraints(
    model: &DiscreteModel,
    x: &[f64],
    id: RodId,
    rod: &DiscreteRod,
    end: End,
    cond: EndCondition,
    tip_load: TipLoad,
    out: &mut Vec<LinearConstraint>,
) {
    let v = rod.end_vertex(end);
    let r = model.vertex(x, id, v);
    let role = Role::Support { rod: id, end };
    // axial: the base held where it is (z = 0), the tip at z = h under displacement control
    match (end, tip_load) {
        (End::Base, _) => out.push(LinearConstraint {
            terms: vec![(rod.r_dof(v, 2), 1.0)],
            value: r[2],
            role,
        }),
        (End::Tip, TipLoad::Height(h)) => out.push(LinearConstraint {
            terms: vec![(rod.r_dof(v, 2), 1.0)],
            value: h,
            role: Role::TipHeight { rod: id },
        }),
        (End::Tip, TipLoad::Force(_)) => {}
    }
    for dir in held_directions(cond.translation, &r) {
        let terms: Vec<(usize, f64)> = (0..2)
            .filter(|&k| dir[k] != 0.0)
            .map(|k| (rod.r_dof(v, k), dir[k]))
            .collect();
        out.push(LinearConstraint {
            terms,
            value: dir.dot(&r),
            role,
        });
    }
    // g = Im(q̄_held ∘ q) is linear in q and, with |q| = 1, zero only at q = ±q_held; near
    // q_held it is half the rotation from q_held in the body frame, R_heldᵀ δθ / 2, so
    // R_held g is half the spatial rotation and its z row holds the twist about z only
    let node = rod.end_node(end);
    let held = model.quaternion(x, id, node);
    let held = held / held.norm();
    let conj = quaternion::conj(&held);
    // rows[i][k] = ∂g_i/∂q_k
    let rows: [[f64; 4]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            quaternion::mul(&conj, &ek)[i]
        })
    });
    let push = |coeffs: [f64; 4], out: &mut Vec<LinearConstraint>| {
        let terms: Vec<(usize, f64)> = (0..4)
            .filter(|&k| coeffs[k].abs() > 1e-15)
            .map(|k| (rod.q_dof(node, k), coeffs[k]))
            .collect();
        out.push(LinearConstraint {
            terms,
            value: 0.0,
            role,
        });
    };
    match cond.rotation {
        Rotation::Clamped => {
            for row in rows {
                push(row, out);
            }
        }
        Rotation::Pinned => {
            let rh = quaternion::rotation(&held);
            let twist: [f64; 4] =
                std::array::from_fn(|k| (0..3).map(|i| rh[(2, i)] * rows[i][k]).sum());
            push(twist, out);
        }
        Rotation::Free => {}
    }
}

/// Pin joint: equal positions of the two rods at the joint's arc length. At a rod end,
/// only the directions that the supports leave free are tied (the others are already
/// prescribed on both rods, and tying them again would make the system singular).
fn joint_constraints(
    model: &DiscreteModel,
    x: &[f64],
    bc: &BoundaryConditions,
    index: usize,
    joint: &Joint,
    out: &mut Vec<LinearConstraint>,
) {
    let (ri, rj) = (&model.rods[joint.right], &model.rods[joint.left]);
    let (Some(vi), Some(vj)) = (ri.mesh.vertex_at(joint.s), rj.mesh.vertex_at(joint.s)) else {
        return;
    };
    let length = model.length();
    let position = model.vertex(x, joint.right, vi);
    let dirs: Vec<Vector3<f64>> = if joint.s <= 1e-9 * length {
        free_directions(bc.base.translation, &position)
    } else if joint.s >= length * (1.0 - 1e-9) {
        free_directions(bc.tip.translation, &position)
    } else {
        vec![Vector3::x(), Vector3::y(), Vector3::z()]
    };
    // dir · (r_right − Rot(turn) r_left) = dir · r_right − (Rotᵀ dir) · r_left
    let (st, ct) = joint.left_turn.sin_cos();
    let turned =
        |d: &Vector3<f64>| Vector3::new(ct * d[0] + st * d[1], -st * d[0] + ct * d[1], d[2]);
    let left_position = model.vertex(x, joint.left, vj);
    for dir in dirs {
        let back = turned(&dir);
        let mut terms = Vec::new();
        for k in 0..3 {
            if dir[k].abs() > 1e-15 {
                terms.push((ri.r_dof(vi, k), dir[k]));
            }
            if back[k].abs() > 1e-15 {
                terms.push((rj.r_dof(vj, k), -back[k]));
            }
        }
        out.push(LinearConstraint {
            terms,
            value: dir.dot(&position) - back.dot(&left_position),
            role: Role::Joint(index),
        });
    }
}

/// Expands the state `x` of a symmetric pair (in `pair_system`'s layout) to the state of
/// the full model in `full_system`'s layout: every rod is the image of one rod of the pair
/// turned about z; support and joint multipliers are zero (they do not enter the Hessian).
pub fn expand_state(
    pair: &DiscreteModel,
    pair_system: &System,
    x: &[f64],
    full: &DiscreteModel,
    full_system: &System,
) -> Vec<f64> {
    let sym = pair
        .assembly
        .symmetry
        .expect("expand_state needs a symmetric pair");
    let mut out = vec![0.0; full_system.n];
    for (k, rod) in full.rods.iter().enumerate() {
        let (src, angle) = sym.image(k);
        let from = &pair.rods[src];
        let (sn, cs) = angle.sin_cos();
        let turn = |v: [f64; 3]| [cs * v[0] - sn * v[1], sn * v[0] + cs * v[1], v[2]];
        let qz = quaternion::about_z(angle);
        for node in 0..rod.mesh.quaternion_nodes() {
            let q = pair.quaternion(x, src, node);
            let q = quaternion::mul(&qz, &q);
            for c in 0..4 {
                out[rod.q_dof(node, c)] = q[c];
            }
            out[full_system.unit_row(k, node)] = x[pair_system.unit_row(src, node)];
        }
        for v in 0..=rod.mesh.elements() {
            let r = turn([
                x[from.r_dof(v, 0)],
                x[from.r_dof(v, 1)],
                x[from.r_dof(v, 2)],
            ]);
            for c in 0..3 {
                out[rod.r_dof(v, c)] = r[c];
            }
        }
        for e in 0..rod.mesh.elements() {
            let row = pair_system.compat_row(src, e);
            let l = turn([x[row], x[row + 1], x[row + 2]]);
            let full_row = full_system.compat_row(k, e);
            out[full_row..full_row + 3].copy_from_slice(&l);
        }
    }
    out
}
