//! The discrete model: every rod meshed, and the numbering of its unknowns (nodal
//! quaternions, 4 per quaternion node, then vertex positions, 3 per element vertex).

use super::mesh::RodMesh;
use super::shape::{self, Order, QuadraturePoint, MAX_NODES};
use crate::model::assembly::{Assembly, RodId};
use crate::model::helix::Helix;
use crate::model::quaternion::Quat;
use crate::model::stiffness::Stiffness;
use nalgebra::Vector3;

/// Rod end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    Base,
    Tip,
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
            rule: shape::quadrature(order),
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
