//! Radial pressure on the rods (a central field toward the tube's axis), discretised by the
//! trapezoidal rule on the element vertices: the potential `q ∫ ρ ds` (`ρ = √(x² + y²)`,
//! `q` in N/m, inward positive) becomes `q Σ_v w_v ρ_v`, `w_v` half the length of the
//! elements meeting at vertex `v`. The rule is exact on every helix about the axis (`ρ` is
//! constant along it) and of second order otherwise; the mean radius that the pressure works
//! on ([`mean_radius`]) is taken by the same rule, so that the discrete pressure's work is
//! exactly `−n L ∫ q d(radius)`.

use super::discrete_model::{DiscreteModel, DiscreteRod};

/// Below this distance from the axis (relative to the rod length) the field's direction is
/// undefined and a vertex carries no radial force.
const ON_AXIS: f64 = 1e-12;

/// The weight `w_v` (m) of vertex `v` of `rod` in the trapezoidal rule.
fn weight(rod: &DiscreteRod, v: usize) -> f64 {
    let s = &rod.mesh.vertices;
    let before = if v > 0 { s[v] - s[v - 1] } else { 0.0 };
    let after = if v + 1 < s.len() {
        s[v + 1] - s[v]
    } else {
        0.0
    };
    0.5 * (before + after)
}

/// One vertex's share of the pressure: its potential per unit `q` (`w ρ`, m²), gradient
/// per unit `q` (`w e_ρ`, over x and y) and Hessian per unit `q` (`w (I − e_ρ e_ρᵀ)/ρ`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexShare {
    /// `(rod index, vertex)` unknowns are the caller's: the x and y position dofs.
    pub dofs: [usize; 2],
    pub potential: f64,
    pub gradient: [f64; 2],
    pub hessian: [[f64; 2]; 2],
}

/// Every vertex's share in the state `x`, in the same order at every state.
pub fn shares<'a>(
    model: &'a DiscreteModel,
    x: &'a [f64],
) -> impl Iterator<Item = VertexShare> + 'a {
    let tiny = ON_AXIS * model.length();
    model.rods.iter().flat_map(move |rod| {
        (0..=rod.mesh.elements()).map(move |v| {
            let dofs = [rod.r_dof(v, 0), rod.r_dof(v, 1)];
            let (px, py) = (x[dofs[0]], x[dofs[1]]);
            let rho = px.hypot(py);
            let w = weight(rod, v);
            if rho <= tiny {
                return VertexShare {
                    dofs,
                    potential: w * rho,
                    gradient: [0.0; 2],
                    hessian: [[0.0; 2]; 2],
                };
            }
            let e = [px / rho, py / rho];
            let h = |i: usize, j: usize| {
                let delta = if i == j { 1.0 } else { 0.0 };
                w * (delta - e[i] * e[j]) / rho
            };
            VertexShare {
                dofs,
                potential: w * rho,
                gradient: [w * e[0], w * e[1]],
                hessian: [[h(0, 0), h(0, 1)], [h(1, 0), h(1, 1)]],
            }
        })
    })
}

/// The rods' mean distance from the axis, `(1/(n L)) Σ ∫ ρ ds` (m), over the modelled
/// rods (the images of a symmetric pair have the same), by the pressure's own rule.
pub fn mean_radius(model: &DiscreteModel, x: &[f64]) -> f64 {
    let total: f64 = shares(model, x).map(|s| s.potential).sum();
    total / (model.rods.len() as f64 * model.length())
}
