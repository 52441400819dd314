//! Quaternion rod elements: Lagrange interpolation of the nodal quaternions, the bending
//! and twisting energy of the rod's elastic hypotheses (Kirchhoff's, docs/theory.md §1, or
//! Sadowsky's ribbon, docs/theory.md §7 and [`crate::model::elasticity`]) with reference
//! curvatures given at each quadrature point, and the element's inextensibility integral
//! `∫ d3 ds` (docs/theory.md §5), with exact first and second derivatives.
//!
//! The interpolated quaternion need not be unit between nodes; curvatures and directors
//! are evaluated for the normalised rotation (`u = 2 Im(q̄ q')/|q|²`, `d3 = R(q) e3/|q|²`),
//! so every point of the element carries a proper rotation.

use super::shape::{Order, QuadraturePoint, MAX_NODES};
use crate::model::elasticity::Elasticity;
use crate::model::stiffness::Stiffness;
use nalgebra::Vector3;

/// Largest number of quaternion unknowns of an element.
pub const MAX_Q: usize = 4 * MAX_NODES;

/// `u_i = 2 qᵀ C_i p / |q|²` with `p = q'`: the non-zero entries `(j, k, sign)` of `C_i`,
/// from `Im(q̄ ∘ p) = q4 p_v − p4 q_v − q_v × p_v`.
const DARBOUX: [[(usize, usize, f64); 4]; 3] = [
    [(3, 0, 1.0), (0, 3, -1.0), (1, 2, -1.0), (2, 1, 1.0)],
    [(3, 1, 1.0), (1, 3, -1.0), (2, 0, -1.0), (0, 2, 1.0)],
    [(3, 2, 1.0), (2, 3, -1.0), (0, 1, -1.0), (1, 0, 1.0)],
];

/// Body curvatures `(κ1, κ2, Ω)` of the rotation field at a point from `q` and `q' = p`.
pub fn curvature(q: &[f64; 4], p: &[f64; 4]) -> Vector3<f64> {
    let d: f64 = q.iter().map(|x| x * x).sum();
    let mut u = Vector3::zeros();
    for i in 0..3 {
        for &(j, k, sg) in &DARBOUX[i] {
            u[i] += 2.0 * sg * q[j] * p[k];
        }
        u[i] /= d;
    }
    u
}

/// The curvatures `u_i = N_i / D` at a point (`N_i = 2 qᵀ C_i p`, `D = |q|²`) with the
/// parts of their derivatives with respect to `x = (q, p)` that the energy's gradient and
/// Hessian are made of.
struct Curvatures {
    d: f64,
    n: [f64; 3],
    /// `∇N_i`.
    gn: [[f64; 8]; 3],
    u: Vector3<f64>,
    /// `∇u_i = ∇N_i / D − N_i ∇D / D²`, `∇D = (2q, 0)`.
    gu: [[f64; 8]; 3],
}

impl Curvatures {
    fn at(q: &[f64; 4], p: &[f64; 4]) -> Curvatures {
        let d: f64 = q.iter().map(|x| x * x).sum();
        let inv_d = 1.0 / d;
        let mut n = [0.0; 3];
        let mut gn = [[0.0; 8]; 3];
        let mut u = Vector3::zeros();
        let mut gu = [[0.0; 8]; 3];
        for i in 0..3 {
            for &(j, k, sg) in &DARBOUX[i] {
                n[i] += 2.0 * sg * q[j] * p[k];
                gn[i][j] += 2.0 * sg * p[k];
                gn[i][4 + k] += 2.0 * sg * q[j];
            }
            // divided as in `curvature`, so that the natural state is stress-free to the bit
            u[i] = n[i] / d;
            for a in 0..8 {
                gu[i][a] = gn[i][a] * inv_d;
            }
            for a in 0..4 {
                gu[i][a] -= n[i] * 2.0 * q[a] * inv_d * inv_d;
            }
        }
        Curvatures { d, n, gn, u, gu }
    }
}

/// The energy density `W(u(q, p))` (J/m) of the hypotheses `elasticity` at a point and its
/// gradient with respect to `x = (q, p)` (as [`strain_energy_density`], without the
/// Hessian: what a residual needs).
pub fn strain_energy_gradient(
    q: &[f64; 4],
    p: &[f64; 4],
    stiffness: &Stiffness,
    elasticity: &Elasticity,
    reference: &Vector3<f64>,
) -> (f64, [f64; 8]) {
    let c = Curvatures::at(q, p);
    let (w, wu, _) = elasticity.density(stiffness, &c.u, reference);
    let mut grad = [0.0; 8];
    for a in 0..8 {
        grad[a] = (0..3).map(|i| wu[i] * c.gu[i][a]).sum();
    }
    (w, grad)
}

/// Kirchhoff's energy density `W = ½ Σ B_i (u_i − u*_i)²` (J/m) at a point and its
/// gradient and Hessian with respect to `x = (q, p)`, `p = q'`.
pub fn energy_density(
    q: &[f64; 4],
    p: &[f64; 4],
    stiffness: &Stiffness,
    natural: &Vector3<f64>,
) -> (f64, [f64; 8], [[f64; 8]; 8]) {
    strain_energy_density(q, p, stiffness, &Elasticity::default(), natural)
}

/// The energy density `W(u(q, p))` (J/m) of the hypotheses `elasticity`
/// ([`Elasticity::density`]) with reference curvatures `reference` (1/m) at a point, and
/// its gradient and Hessian with respect to `x = (q, p)`, `p = q'`, by the chain rule
/// `∇W = Σ_i W_,i ∇u_i`, `∇²W = Σ_ij W_,ij ∇u_i ∇u_jᵀ + Σ_i W_,i ∇²u_i`.
pub fn strain_energy_density(
    q: &[f64; 4],
    p: &[f64; 4],
    stiffness: &Stiffness,
    elasticity: &Elasticity,
    reference: &Vector3<f64>,
) -> (f64, [f64; 8], [[f64; 8]; 8]) {
    let c = Curvatures::at(q, p);
    let (inv_d, n, gn, gu) = (1.0 / c.d, c.n, c.gn, c.gu);
    let (w, wu, wuu) = elasticity.density(stiffness, &c.u, reference);
    let mut grad = [0.0; 8];
    for a in 0..8 {
        grad[a] = (0..3).map(|i| wu[i] * gu[i][a]).sum();
    }
    // Σ_i W_,i ∇²u_i with ∇²u_i = ∇²N_i / D − (∇N_i ∇Dᵀ + ∇D ∇N_iᵀ) / D²
    // + 2 N_i ∇D ∇Dᵀ / D³ − N_i ∇²D / D², summed first over i: with G = Σ W_,i ∇N_i and
    // S = Σ W_,i N_i it is Σ W_,i ∇²N_i / D − (G ∇Dᵀ + ∇D Gᵀ) / D² + 2 S ∇D ∇Dᵀ / D³
    // − 2 S I_q / D²
    let mut g = [0.0; 8];
    let mut s = 0.0;
    for i in 0..3 {
        s += wu[i] * n[i];
        for a in 0..8 {
            g[a] += wu[i] * gn[i][a];
        }
    }
    let mut hess = [[0.0; 8]; 8];
    for i in 0..3 {
        for &(j, k, sg) in &DARBOUX[i] {
            let v = 2.0 * sg * wu[i] * inv_d;
            hess[j][4 + k] += v;
            hess[4 + k][j] += v;
        }
    }
    let (inv_d2, inv_d3) = (inv_d * inv_d, inv_d * inv_d * inv_d);
    for a in 0..8 {
        for b in 0..4 {
            // ∇D_b = 2 q_b (zero on the p unknowns)
            let gd_b = 2.0 * q[b];
            hess[a][b] -= g[a] * gd_b * inv_d2;
            hess[b][a] -= g[a] * gd_b * inv_d2;
        }
    }
    for a in 0..4 {
        for b in 0..4 {
            hess[a][b] += 8.0 * s * q[a] * q[b] * inv_d3;
        }
        hess[a][a] -= 2.0 * s * inv_d2;
    }
    // Σ_ij W_,ij ∇u_i ∇u_jᵀ
    for i in 0..3 {
        for j in 0..3 {
            let c = wuu[(i, j)];
            if c == 0.0 {
                continue;
            }
            for a in 0..8 {
                let ca = c * gu[i][a];
                for b in 0..8 {
                    hess[a][b] += ca * gu[j][b];
                }
            }
        }
    }
    (w, grad, hess)
}

/// `d3_j = qᵀ M_j q / |q|²`: the non-zero entries `(k, l, value)` of the symmetric `M_j`,
/// from the third column of `R(q)`.
const TANGENT: [&[(usize, usize, f64)]; 3] = [
    &[(0, 2, 1.0), (2, 0, 1.0), (1, 3, 1.0), (3, 1, 1.0)],
    &[(1, 2, 1.0), (2, 1, 1.0), (0, 3, -1.0), (3, 0, -1.0)],
    &[(0, 0, -1.0), (1, 1, -1.0), (2, 2, 1.0), (3, 3, 1.0)],
];

/// `M_j q` and `qᵀ M_j q` (see [`TANGENT`]).
fn tangent_row(q: &[f64; 4], j: usize) -> ([f64; 4], f64) {
    let mut mq = [0.0; 4];
    for &(k, l, v) in TANGENT[j] {
        mq[k] += v * q[l];
    }
    let qmq: f64 = (0..4).map(|k| q[k] * mq[k]).sum();
    (mq, qmq)
}

/// Unit tangent `d3` of the normalised rotation of `q` with its gradient
/// `[j][k] = ∂d3_j/∂q_k` (as [`tangent`], without the Hessians).
pub fn tangent_gradient(q: &[f64; 4]) -> ([f64; 3], [[f64; 4]; 3]) {
    let d: f64 = q.iter().map(|x| x * x).sum();
    let mut t = [0.0; 3];
    let mut g = [[0.0; 4]; 3];
    for j in 0..3 {
        let (mq, qmq) = tangent_row(q, j);
        t[j] = qmq / d;
        for k in 0..4 {
            g[j][k] = 2.0 * mq[k] / d - 2.0 * qmq * q[k] / (d * d);
        }
    }
    (t, g)
}

/// Unit tangent `d3` of the normalised rotation of `q`, with its gradient `[j][k] = ∂d3_j/∂q_k`
/// and Hessians `[j][k][l]`.
#[allow(clippy::type_complexity)]
pub fn tangent(q: &[f64; 4]) -> ([f64; 3], [[f64; 4]; 3], [[[f64; 4]; 4]; 3]) {
    let d: f64 = q.iter().map(|x| x * x).sum();
    let (t, g) = tangent_gradient(q);
    let mut h = [[[0.0; 4]; 4]; 3];
    for j in 0..3 {
        let (mq, qmq) = tangent_row(q, j);
        for &(k, l, v) in TANGENT[j] {
            h[j][k][l] += 2.0 * v / d;
        }
        for k in 0..4 {
            for l in 0..4 {
                h[j][k][l] += -4.0 * (mq[k] * q[l] + q[k] * mq[l]) / (d * d)
                    + 8.0 * qmq * q[k] * q[l] / (d * d * d);
            }
            h[j][k][k] -= 2.0 * qmq / (d * d);
        }
    }
    (t, g, h)
}

/// What one element contributes, in its local quaternion unknowns `4a + k` (node `a`,
/// component `k`).
#[derive(Clone, Debug)]
pub struct ElementTerms {
    /// Elastic energy of the element (J).
    pub energy: f64,
    /// `∂E/∂q` (J).
    pub energy_gradient: [f64; MAX_Q],
    /// `∂²E/∂q²` plus `Σ_j λ_j ∂²gap_j/∂q²` (the inextensibility term of the Lagrangian).
    pub hessian: [[f64; MAX_Q]; MAX_Q],
    /// `∫ d3 ds` over the element (m); the gap is `r_end − r_start − chord`.
    pub chord: [f64; 3],
    /// `∂chord_j/∂q` (m).
    pub chord_gradient: [[f64; MAX_Q]; 3],
    /// The part of the potential of the element's line load that moves with its quaternions,
    /// `−f·∫₀ʰ (h − s) d3 ds` (J): with `r(s) = r_start + ∫₀ˢ d3`, the whole potential is
    /// `−f·∫ r ds = −h f·r_start + load_potential`.
    pub load_potential: f64,
    /// `∂load_potential/∂q` (J); its Hessian is in `hessian`.
    pub load_gradient: [f64; MAX_Q],
}

/// A dead force per unit length `force` (N/m), uniform over an element: the slot of the
/// loads along the rods in the element kernel.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ElementLoad {
    pub force: [f64; 3],
}

impl ElementLoad {
    /// No load.
    pub const NONE: ElementLoad = ElementLoad { force: [0.0; 3] };

    fn is_none(&self) -> bool {
        self.force == [0.0; 3]
    }
}

/// The interpolated quaternion `q` and its arc-length derivative `q'` at quadrature point
/// `gp` of an element of length `h` (m), with the shape functions' derivatives `dN_a/ds`.
fn at_point(
    order: Order,
    gp: &QuadraturePoint,
    h: f64,
    q: &[[f64; 4]; MAX_NODES],
) -> ([f64; 4], [f64; 4], [f64; MAX_NODES]) {
    let mut qg = [0.0; 4];
    let mut pg = [0.0; 4];
    let mut b = [0.0; MAX_NODES];
    for a in 0..order.nodes() {
        b[a] = gp.dn[a] / h;
        for k in 0..4 {
            qg[k] += gp.n[a] * q[a][k];
            pg[k] += b[a] * q[a][k];
        }
    }
    (qg, pg, b)
}

/// Curvatures `(κ1, κ2, Ω)` (1/m) of the interpolated field of nodal quaternions `q` at
/// every point of `rule` on an element of length `h` (m): the reference curvatures of a
/// rod whose discrete natural configuration is `q`.
pub fn curvatures_at_points(
    order: Order,
    rule: &[QuadraturePoint],
    h: f64,
    q: &[[f64; 4]; MAX_NODES],
) -> Vec<Vector3<f64>> {
    rule.iter()
        .map(|gp| {
            let (qg, pg, _) = at_point(order, gp, h, q);
            curvature(&qg, &pg)
        })
        .collect()
}

/// `∫ d3 ds` over an element of length `h` (m) with nodal quaternions `q` (m), by the
/// quadrature `rule` of [`element_terms`] (the same sum, so the same rounding).
pub fn chord(
    order: Order,
    rule: &[QuadraturePoint],
    h: f64,
    q: &[[f64; 4]; MAX_NODES],
) -> [f64; 3] {
    let mut out = [0.0; 3];
    for gp in rule {
        let jw = gp.weight * h;
        let (qg, _, _) = at_point(order, gp, h, q);
        let (t, _, _) = tangent(&qg);
        for j in 0..3 {
            out[j] += jw * t[j];
        }
    }
    out
}

/// Evaluates an element of length `h` (m) with nodal quaternions `q` (only the first
/// `order.nodes()` used), the energy of the hypotheses `elasticity` with reference
/// curvatures `reference[g]` (1/m) at quadrature point `g` of `rule`, the inextensibility
/// multiplier `lambda` (N) that weights the chord's Hessian, and the potential of the line
/// load `load`; without `hessian`, the Hessian is left zero (a residual needs the rest only).
// The kernel's inputs are the element's own quantities, named as in the equations; a struct
// of them would only rename them at its call sites.
#[allow(clippy::too_many_arguments)]
pub fn element_terms(
    order: Order,
    rule: &[QuadraturePoint],
    h: f64,
    q: &[[f64; 4]; MAX_NODES],
    stiffness: &Stiffness,
    elasticity: &Elasticity,
    reference: &[Vector3<f64>],
    lambda: &[f64; 3],
    load: &ElementLoad,
    hessian: bool,
) -> ElementTerms {
    debug_assert_eq!(reference.len(), rule.len());
    let nn = order.nodes();
    let mut out = ElementTerms {
        energy: 0.0,
        energy_gradient: [0.0; MAX_Q],
        hessian: [[0.0; MAX_Q]; MAX_Q],
        chord: [0.0; 3],
        chord_gradient: [[0.0; MAX_Q]; 3],
        load_potential: 0.0,
        load_gradient: [0.0; MAX_Q],
    };
    let loaded = !load.is_none();
    for (gp, reference) in rule.iter().zip(reference) {
        let jw = gp.weight * h;
        let (qg, pg, b) = at_point(order, gp, h, q);
        let (w, gw, hw) = if hessian {
            let (w, g, hw) = strain_energy_density(&qg, &pg, stiffness, elasticity, reference);
            (w, g, Some(hw))
        } else {
            let (w, g) = strain_energy_gradient(&qg, &pg, stiffness, elasticity, reference);
            (w, g, None)
        };
        let (t, gt, ht) = if hessian {
            let (t, g, ht) = tangent(&qg);
            (t, g, Some(ht))
        } else {
            let (t, g) = tangent_gradient(&qg);
            (t, g, None)
        };
        out.energy += jw * w;
        for j in 0..3 {
            out.chord[j] += jw * t[j];
        }
        for a in 0..nn {
            for k in 0..4 {
                let ia = 4 * a + k;
                out.energy_gradient[ia] += jw * (gp.n[a] * gw[k] + b[a] * gw[4 + k]);
                for j in 0..3 {
                    out.chord_gradient[j][ia] += jw * gp.n[a] * gt[j][k];
                }
            }
        }
        // the line load's potential −f·∫ (h − s) d3 ds: at the point, a dead force f (h − s)
        // on the tangent
        let moment_arm = h * (1.0 - gp.xi);
        if loaded {
            let fw = load.force.map(|f| f * moment_arm);
            out.load_potential -= jw * (0..3).map(|j| fw[j] * t[j]).sum::<f64>();
            for a in 0..nn {
                for k in 0..4 {
                    out.load_gradient[4 * a + k] -=
                        jw * gp.n[a] * (0..3).map(|j| fw[j] * gt[j][k]).sum::<f64>();
                }
            }
        }
        let (Some(hw), Some(ht)) = (hw, ht) else {
            continue;
        };
        // λ·(−∂²chord) Hessian at the point, in q only (with the line load's −f (h − s)·∂²d3)
        let mut hl = [[0.0; 4]; 4];
        for k in 0..4 {
            for l in 0..4 {
                hl[k][l] = -(0..3).map(|j| lambda[j] * ht[j][k][l]).sum::<f64>();
                if loaded {
                    hl[k][l] -= (0..3)
                        .map(|j| load.force[j] * moment_arm * ht[j][k][l])
                        .sum::<f64>();
                }
            }
        }
        for a in 0..nn {
            for k in 0..4 {
                let ia = 4 * a + k;
                for c in 0..nn {
                    for l in 0..4 {
                        let ic = 4 * c + l;
                        let v = gp.n[a] * gp.n[c] * (hw[k][l] + hl[k][l])
                            + gp.n[a] * b[c] * hw[k][4 + l]
                            + b[a] * gp.n[c] * hw[4 + k][l]
                            + b[a] * b[c] * hw[4 + k][4 + l];
                        out.hessian[ia][ic] += jw * v;
                    }
                }
            }
        }
    }
    out
}
