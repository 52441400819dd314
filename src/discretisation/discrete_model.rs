//! The discrete model: every rod meshed, and the numbering of its unknowns (nodal
//! quaternions, 4 per quaternion node, then vertex positions, 3 per element vertex).

use super::element;
use super::mesh::RodMesh;
use super::shape::{self, Order, QuadraturePoint, MAX_NODES};
use crate::model::assembly::{Assembly, RodId};
use crate::model::cell::Cell;
use crate::model::elasticity::{Elasticity, Energy, StressFree};
use crate::model::helix::{Chirality, Helix};
use crate::model::loading::{LineLoad, Loads};
use crate::model::quaternion::Quat;
use crate::model::stiffness::Stiffness;
use crate::model::symmetry::TurnZ;
use nalgebra::Vector3;

pub use crate::model::elasticity::Reference;

/// Rod end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    Base,
    Tip,
}

/// One rod of the discrete model.
#[derive(Clone, Debug)]
pub struct DiscreteRod {
    /// The natural helix (initial state; intrinsic curvature of a helical rod).
    pub helix: Helix,
    pub mesh: RodMesh,
    /// Reference curvatures `(κ1*, κ2*, Ω*)` (1/m) at every quadrature point, element by
    /// element (`rule.len()` per element): zero for rods stress-free when straight, else
    /// as [`Reference`] says.
    pub reference: Vec<Vector3<f64>>,
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
    /// Reference curvatures at the quadrature points of element `e`, `points` per element.
    pub fn element_reference(&self, e: usize, points: usize) -> &[Vector3<f64>] {
        &self.reference[e * points..(e + 1) * points]
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
    /// The elastic hypotheses (stress-free shape, energy) of every rod.
    pub elasticity: Elasticity,
    /// Where the reference curvatures of helical rods come from.
    pub reference: Reference,
    /// Tip height `h0` (m) of the natural state, the `ε = 0` of the load path: the
    /// analytic `b L / c` with the continuum reference, the mean tip height of the
    /// discrete natural state with the discrete one (they differ by `O(h⁴)`).
    height0: f64,
    pub order: Order,
    pub rule: Vec<QuadraturePoint>,
    /// Number of primal unknowns (quaternions and positions, then the contacts' arc
    /// lengths of sliding joints).
    pub n_primal: usize,
    /// The joints (indices into the assembly's) that slide: each has two arc-length
    /// unknowns (m), on its right and its left rod, after the rods' unknowns.
    pub slides: Vec<usize>,
    /// First arc-length unknown of the sliding joints (the rods' unknowns end there).
    slide_offset: usize,
    /// The element count the meshes were asked for (before joints split them).
    pub requested_elements: usize,
}

impl DiscreteModel {
    /// Meshes every rod with about `elements` elements of the given order, with vertices
    /// at its joints: Kirchhoff rods stress-free in their discrete natural configuration.
    pub fn new(
        assembly: Assembly,
        stiffness: Stiffness,
        elements: usize,
        order: Order,
    ) -> DiscreteModel {
        DiscreteModel::with_hypotheses(
            assembly,
            stiffness,
            elements,
            order,
            Elasticity::default(),
            Reference::Discrete,
        )
    }

    /// [`DiscreteModel::new`] with the elastic hypotheses `elasticity` and the reference
    /// curvatures of helical rods taken as `reference` says.
    pub fn with_hypotheses(
        assembly: Assembly,
        stiffness: Stiffness,
        elements: usize,
        order: Order,
        elasticity: Elasticity,
        reference: Reference,
    ) -> DiscreteModel {
        let rule = shape::quadrature(order);
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
                let reference_curvatures =
                    reference_curvatures(helix, &mesh, order, &rule, elasticity, reference);
                DiscreteRod {
                    helix: *helix,
                    reference: reference_curvatures,
                    mesh,
                    q_offset,
                    r_offset,
                }
            })
            .collect();
        let mut model = DiscreteModel {
            rule,
            height0: assembly.height(),
            assembly,
            rods,
            stiffness,
            elasticity,
            reference,
            order,
            n_primal: offset,
            slides: Vec::new(),
            slide_offset: offset,
            requested_elements: elements,
        };
        if reference == Reference::Discrete && !model.rods.is_empty() {
            let x = model.natural_state();
            let n = model.rods.len() as f64;
            model.height0 = (0..model.rods.len())
                .map(|id| model.vertex(&x, id, model.rods[id].mesh.elements())[2])
                .sum::<f64>()
                / n;
        }
        model
    }

    /// This model with its crossings sliding (`true`) or not: every joint strictly inside the
    /// rods gets two arc-length unknowns (a joint at a rod end is held by the supports there
    /// and stays a pin). In the cell of an infinite tube every joint slides, the one at the
    /// rods' near ends too: the cell's ends are not supports, and the crossing there is the
    /// cell's own (the one at its far ends is its screw image).
    pub fn with_sliding_joints(mut self, sliding: bool) -> DiscreteModel {
        let l = self.length();
        let cell = self.assembly.cell.is_some();
        self.slides = if sliding {
            let inside = |s: f64| cell || (s > 1e-9 * l && s < l * (1.0 - 1e-9));
            (0..self.assembly.joints.len())
                .filter(|&j| inside(self.assembly.joints[j].s))
                .collect()
        } else {
            Vec::new()
        };
        self.n_primal = self.slide_offset + 2 * self.slides.len();
        self
    }

    /// Unknown of the arc length (m) of sliding joint `k`'s contact on its right (`side`
    /// 0) or left (`side` 1) rod.
    pub fn slide_dof(&self, k: usize, side: usize) -> usize {
        self.slide_offset + 2 * k + side
    }

    /// The sliding joint (index into [`DiscreteModel::slides`]) of the assembly's joint
    /// `joint`, if it slides.
    pub fn slide_of(&self, joint: usize) -> Option<usize> {
        self.slides.iter().position(|&j| j == joint)
    }

    /// The primal state `x` of this model carried to `other` (the same rods and meshes,
    /// with or without sliding joints): the rods' unknowns copied, the contacts' arc lengths
    /// of `other` where this model has them, else at their crossings' natural arc lengths.
    pub fn carry_state(&self, x: &[f64], other: &DiscreteModel) -> Vec<f64> {
        let mut y = vec![0.0; other.n_primal];
        let rods = self.slide_offset.min(other.slide_offset);
        y[..rods].copy_from_slice(&x[..rods]);
        for (k, &joint) in other.slides.iter().enumerate() {
            for side in 0..2 {
                y[other.slide_dof(k, side)] = match self.slide_of(joint) {
                    Some(m) => x[self.slide_dof(m, side)],
                    None => other.assembly.joints[joint].s,
                };
            }
        }
        y
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
        Some(
            DiscreteModel::with_hypotheses(
                full,
                self.stiffness,
                self.requested_elements,
                self.order,
                self.elasticity,
                self.reference,
            )
            .with_sliding_joints(!self.slides.is_empty()),
        )
    }

    /// Rod length `L` (m).
    pub fn length(&self) -> f64 {
        self.assembly.length
    }

    /// The length `ℓ` (m) that weighs the constraints on positions against those on
    /// rotations in the regularisation of the eigenvalue searches' KKT matrices (a rotation
    /// by one radian moves a point `ℓ` away by `ℓ`): the rod length of a finite assembly; for
    /// a cell, the arc length of one turn of its helices when that is longer, since a cell
    /// spans a fraction of a turn that shrinks with the number of helices (`π c/m`), and rows
    /// on positions weighed by its square alone are penalised so strongly that rounding in
    /// the factorisation blurs the counts (the n = 8 cell's by 2e-3 of its lowest
    /// eigenvalue, the n = 64 cell's map off a dense solve by up to 9e-4).
    pub fn stability_length(&self) -> f64 {
        let own = self.length();
        if self.assembly.cell.is_none() {
            return own;
        }
        self.assembly
            .rods
            .iter()
            .filter(|h| !h.is_straight())
            .map(|h| h.length_of_turns(1.0))
            .fold(own, f64::max)
    }

    /// Initial tip height `h0` (m): that of the natural state (see the field).
    pub fn height0(&self) -> f64 {
        self.height0
    }

    /// The natural state: nodal quaternions and positions of the free helices.
    pub fn natural_state(&self) -> Vec<f64> {
        let helices: Vec<Helix> = self.rods.iter().map(|r| r.helix).collect();
        self.helix_state(&helices)
    }

    /// The primal state in which rod `i` lies on `helices[i]` (nodal quaternions of its
    /// directors and vertex positions), e.g. to prescribe ends on other helices. With the
    /// discrete reference the vertices are where the chords `∫ d3 ds` of the interpolated
    /// field put them from the helix's base, so that the state is the discrete helix (it
    /// meets the inextensibility constraints exactly); with the continuum one they are on
    /// the analytic helix.
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
            match self.reference {
                Reference::Continuum => {
                    for (v, &sv) in rod.mesh.vertices.iter().enumerate() {
                        let r = helix.position(sv);
                        for c in 0..3 {
                            x[rod.r_dof(v, c)] = r[c];
                        }
                    }
                }
                Reference::Discrete => {
                    let mut r = helix.position(rod.mesh.vertices[0]);
                    for c in 0..3 {
                        x[rod.r_dof(0, c)] = r[c];
                    }
                    for e in 0..rod.mesh.elements() {
                        let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                        let q = self.element_quaternions(&x, rod, e);
                        let chord = element::chord(self.order, &self.rule, h, &q);
                        for c in 0..3 {
                            r[c] += chord[c];
                            x[rod.r_dof(e + 1, c)] = r[c];
                        }
                    }
                }
            }
        }
        if let Some(cell) = &self.assembly.cell {
            centre_on_axis(self, cell, &mut x);
        }
        for (k, &joint) in self.slides.iter().enumerate() {
            for side in 0..2 {
                x[self.slide_dof(k, side)] = self.assembly.joints[joint].s;
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

    /// The nodal quaternions of element `e` of `rod` in state `x` (the first
    /// `order.nodes()` entries used).
    pub fn element_quaternions(
        &self,
        x: &[f64],
        rod: &DiscreteRod,
        e: usize,
    ) -> [[f64; 4]; MAX_NODES] {
        self.element_nodes(e, |k| std::array::from_fn(|c| x[rod.q_dof(k, c)]))
    }

    /// The nodal quaternions of element `e` of a rod whose quaternion node `k` is
    /// `node(k)` (the first `order.nodes()` entries used): the one gather of an element's
    /// nodes, from a state vector or from a reported shape.
    pub fn element_nodes(
        &self,
        e: usize,
        node: impl Fn(usize) -> [f64; 4],
    ) -> [[f64; 4]; MAX_NODES] {
        let p = self.order.degree();
        let mut q = [[0.0; 4]; MAX_NODES];
        for (a, qa) in q.iter_mut().enumerate().take(p + 1) {
            *qa = node(e * p + a);
        }
        q
    }

    /// Whether the problem is invariant under the rotation about the z axis that turns
    /// every position about it and every material frame back about its tangent: straight
    /// Kirchhoff rods on the axis (radius 0) of isotropic bending stiffness (`B1 = B2`),
    /// under loads that keep the axis (no tilt, no lateral dead load); every support
    /// condition holds at the axis what it held. The buckled states of such a problem form
    /// circles of equilibria of equal energy (a neutral direction along every branch),
    /// which a phase condition fixes ([`System::with_phase`](super::system::System::with_phase)).
    pub fn turns_freely_about_axis(&self, loads: &Loads) -> bool {
        let b = self.stiffness;
        let isotropic = (b.b1 - b.b2).abs() <= 1e-12 * b.b1.abs().max(b.b2.abs());
        let on_axis = self.rods.iter().all(|r| r.helix.radius == 0.0);
        let axial = loads.keeps_cyclic_symmetry()
            && loads.along_rods().iter().all(|l| match l {
                LineLoad::Dead { direction, .. } => direction[0] == 0.0 && direction[1] == 0.0,
                LineLoad::Radial { .. } => true,
            });
        isotropic && on_axis && axial && self.elasticity.energy == Energy::Kirchhoff
    }

    /// Rods of the full assembly: the model's, or all the images of a symmetric pair.
    pub fn full_rods(&self) -> usize {
        self.assembly
            .symmetry
            .map_or(self.rods.len(), |s| s.full_rods())
    }

    /// The rod of this model that rod `k` of the full assembly is (or is an image of).
    pub fn source_rod(&self, k: RodId) -> RodId {
        self.assembly.symmetry.map_or(k, |s| s.image(k).0)
    }

    /// Elements of the most finely meshed rod (0 without rods).
    pub fn max_elements(&self) -> usize {
        self.rods
            .iter()
            .map(|r| r.mesh.elements())
            .max()
            .unwrap_or(0)
    }
}

/// Reference curvatures of a rod naturally on `helix` at every quadrature point of its
/// mesh (see [`DiscreteRod::reference`]).
fn reference_curvatures(
    helix: &Helix,
    mesh: &RodMesh,
    order: Order,
    rule: &[QuadraturePoint],
    elasticity: Elasticity,
    reference: Reference,
) -> Vec<Vector3<f64>> {
    let points = mesh.elements() * rule.len();
    match (elasticity.stress_free, reference) {
        (StressFree::Straight, _) => vec![Vector3::zeros(); points],
        (StressFree::Helix, Reference::Continuum) => vec![helix.natural_curvature(); points],
        (StressFree::Helix, Reference::Discrete) => {
            let s: Vec<f64> = (0..mesh.quaternion_nodes())
                .map(|k| mesh.node_arc_length(k))
                .collect();
            let field = helix.quaternion_field(&s);
            let p = order.degree();
            (0..mesh.elements())
                .flat_map(|e| {
                    let mut q = [[0.0; 4]; MAX_NODES];
                    for (a, qa) in q.iter_mut().enumerate().take(p + 1) {
                        *qa = std::array::from_fn(|c| field[e * p + a][c]);
                    }
                    let h = mesh.vertices[e + 1] - mesh.vertices[e];
                    element::curvatures_at_points(order, rule, h, &q)
                })
                .collect()
        }
    }
}

/// Moves every helical rod of a cell's primal state `x` across the axis so that its far
/// vertex is the screw image of its near one: the discrete helix, whose vertices its chords
/// place, is a regular polygon about an axis a rounding away from z.
fn centre_on_axis(model: &DiscreteModel, cell: &Cell, x: &mut [f64]) {
    for (id, rod) in model.rods.iter().enumerate() {
        if rod.helix.is_straight() {
            continue;
        }
        // the turn of the rod's own screw: a bending cell's rod spans 1/m of a turn
        let own = if cell.bending {
            let m = cell.m as f64;
            match rod.helix.chirality {
                Chirality::Right => 2.0 * std::f64::consts::PI / m,
                Chirality::Left => -2.0 * std::f64::consts::PI / m,
            }
        } else {
            cell.turns[id]
        };
        let turn = TurnZ::new(own);
        let (v0, ve) = (
            model.vertex(x, id, 0),
            model.vertex(x, id, rod.mesh.elements()),
        );
        let image = turn.apply([v0[0], v0[1], 0.0]);
        // (I − R) c = v_far − R v_near in x–y
        let (b0, b1) = (ve[0] - image[0], ve[1] - image[1]);
        let (cos, sin) = (own.cos(), own.sin());
        let (a00, a01, a10, a11) = (1.0 - cos, sin, -sin, 1.0 - cos);
        let det = a00 * a11 - a01 * a10;
        if det.abs() < 1e-12 {
            continue;
        }
        let c = [(a11 * b0 - a01 * b1) / det, (a00 * b1 - a10 * b0) / det];
        for v in 0..=rod.mesh.elements() {
            for k in 0..2 {
                x[rod.r_dof(v, k)] -= c[k];
            }
        }
    }
}
