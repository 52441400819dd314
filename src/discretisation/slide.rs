//! Sliding joints (docs/theory.md §2, docs/joints.md): at a crossing the point of the right
//! rod at arc length `s_R` and the point of the left rod (or of its turned image) at `s_L`
//! coincide, `g = r_R(s_R) − T r_L(s_L) = 0`, and both arc lengths are unknowns (the slip
//! `s − s0` of the contact along each rod). With no force on the arc lengths, the stationarity
//! in `s` says `ν · r'(s) = 0`: the joint's force `ν` (N) has no component along either rod's
//! tangent — the sliding is frictionless.
//!
//! A rod's point at `s` inside element `e` (start `s_e`, length `h`, `u = s − s_e`) is the
//! element's start vertex plus the element's own chord rule applied to `[s_e, s]`:
//! `r(s) = r_e + u Σ_g w_g d3(q(u ξ_g / h))`, so that at `u = h` it is the element's next
//! vertex exactly (the inextensibility row), and the point moves continuously from one element
//! into the next. Its first and second derivatives in `s`, the vertex and the element's nodal
//! quaternions enter the KKT matrix (the Hessian terms `ν · ∂²r`).

use super::discrete_model::DiscreteModel;
use super::element::{tangent, MAX_Q};
use super::shape::{self, Order, MAX_NODES};
use crate::model::assembly::RodId;
use crate::model::symmetry::TurnZ;

/// Elements on either side of the contact's element that the KKT pattern holds for it: the
/// contact is re-centred when it reaches the window's edge element (see
/// [`SlideWindow::stale`]); beyond the edge, the edge element's field is extended. One: the
/// multipliers of a joint couple every element of its windows, and a wider window costs
/// fill in the factorisation (three on each side made the n = 8 tube ten times slower).
pub const WINDOW: usize = 1;

/// One side of a sliding joint: the rod, its arc-length unknown and the elements of the
/// pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlideSide {
    pub rod: RodId,
    /// The unknown `s` (m).
    pub dof: usize,
    /// First and last element the pattern holds.
    pub first: usize,
    pub last: usize,
}

/// A sliding joint of the system: its two sides and the first row of its three multipliers.
#[derive(Clone, Debug, PartialEq)]
pub struct SlideWindow {
    /// Index of the joint in the model's assembly.
    pub joint: usize,
    pub sides: [SlideSide; 2],
    /// Rotation of the left rod's image (rad about z).
    pub turn: f64,
}

impl SlideWindow {
    /// The windows of the model's sliding joints around where the state `x` has them.
    pub fn of_model(model: &DiscreteModel, x: &[f64]) -> Vec<SlideWindow> {
        model
            .slides
            .iter()
            .enumerate()
            .map(|(k, &joint)| {
                let j = &model.assembly.joints[joint];
                let side = |i: usize, rod: RodId| {
                    let dof = model.slide_dof(k, i);
                    let mesh = &model.rods[rod].mesh;
                    let e = element_of(&mesh.vertices, x[dof]);
                    SlideSide {
                        rod,
                        dof,
                        first: e.saturating_sub(WINDOW),
                        last: (e + WINDOW).min(mesh.elements() - 1),
                    }
                };
                SlideWindow {
                    joint,
                    sides: [side(0, j.right), side(1, j.left)],
                    turn: j.left_turn,
                }
            })
            .collect()
    }

    /// The KKT entries `(row, unknown)` by which the joint couples to its left rod's image:
    /// its three rows (from `first_row`) against the positions and quaternions of the left
    /// side's window (`ν · ∂r_L`, `ν · ∂²r_L/∂s∂q`), and the left contact's arc length
    /// against those quaternions. (The terms `ν · ∂²r_L/∂q∂q` are of the image alone.) The
    /// Bloch blocks give these entries the image's phase.
    pub fn image_entries(&self, model: &DiscreteModel, first_row: usize) -> Vec<(usize, usize)> {
        let side = &self.sides[1];
        let rod = &model.rods[side.rod];
        let degree = model.order.degree();
        let rows = first_row..first_row + 3;
        let mut out = Vec::new();
        for e in side.first..=side.last {
            for row in rows.clone() {
                out.extend((0..3).map(|c| (row, rod.r_dof(e, c))));
            }
            for node in e * degree..=(e + 1) * degree {
                for c in 0..4 {
                    let d = rod.q_dof(node, c);
                    out.extend(rows.clone().map(|row| (row, d)));
                    out.push((side.dof, d));
                }
            }
        }
        out
    }

    /// Whether the contact of a side of this joint in the state `x` is in its window's edge
    /// element or beyond (away from the rod's ends), so that the window should be re-centred.
    pub fn stale(&self, model: &DiscreteModel, x: &[f64]) -> bool {
        self.sides.iter().any(|side| {
            let mesh = &model.rods[side.rod].mesh;
            let e = element_of(&mesh.vertices, x[side.dof]);
            (e <= side.first && side.first > 0)
                || (e >= side.last && side.last + 1 < mesh.elements())
        })
    }
}

/// The element whose span holds arc length `s` (m) on a mesh with vertices `vertices`, the
/// first or last beyond the rod's ends.
pub fn element_of(vertices: &[f64], s: f64) -> usize {
    let elements = vertices.len() - 1;
    vertices[1..elements].partition_point(|&v| v <= s)
}

/// A rod's point at arc length `s` in one element and its derivatives, with the second
/// derivatives contracted with a force `f` (N): the terms `f · r` of the Lagrangian.
#[derive(Clone, Debug)]
pub struct RodPoint {
    /// `r(s)` (m).
    pub r: [f64; 3],
    /// `∂r/∂s`, the tangent (1).
    pub r_s: [f64; 3],
    /// `∂r_j/∂q_i` (m), local quaternion unknowns `4a + k`.
    pub r_q: [[f64; MAX_Q]; 3],
    /// `f · ∂²r/∂s²` (N/m).
    pub f_ss: f64,
    /// `f · ∂²r/∂s∂q_i` (N).
    pub f_sq: [f64; MAX_Q],
    /// `f · ∂²r/∂q_i∂q_k` (N m).
    pub f_qq: [[f64; MAX_Q]; MAX_Q],
}

/// The point at `u = s − s_e` (m) of an element of length `h` (m) with start vertex `start`
/// and nodal quaternions `q`, by the element's rule `rule`, with second derivatives
/// contracted with `f` (see [`RodPoint`]).
pub fn rod_point(
    order: Order,
    rule: &[shape::QuadraturePoint],
    h: f64,
    start: [f64; 3],
    q: &[[f64; 4]; MAX_NODES],
    u: f64,
    f: [f64; 3],
) -> RodPoint {
    let nn = order.nodes();
    let ddn: [f64; MAX_NODES] = match order {
        Order::Linear => [0.0; MAX_NODES],
        Order::Quadratic => [4.0, -8.0, 4.0],
    };
    let mut p = RodPoint {
        r: start,
        r_s: [0.0; 3],
        r_q: [[0.0; MAX_Q]; 3],
        f_ss: 0.0,
        f_sq: [0.0; MAX_Q],
        f_qq: [[0.0; MAX_Q]; MAX_Q],
    };
    for gp in rule {
        let c = gp.xi / h;
        let xi = u * c;
        let (n, dn) = shape::shape(order, xi);
        let mut qg = [0.0; 4];
        let mut qx = [0.0; 4];
        let mut qxx = [0.0; 4];
        for a in 0..nn {
            for k in 0..4 {
                qg[k] += n[a] * q[a][k];
                qx[k] += dn[a] * q[a][k];
                qxx[k] += ddn[a] * q[a][k];
            }
        }
        let (t, d, hess) = tangent(&qg);
        let w = gp.weight;
        // f-contracted gradient and Hessian of d3 at the point
        let fd: [f64; 4] = std::array::from_fn(|k| (0..3).map(|j| f[j] * d[j][k]).sum());
        let fh: [[f64; 4]; 4] = std::array::from_fn(|k| {
            std::array::from_fn(|l| (0..3).map(|j| f[j] * hess[j][k][l]).sum())
        });
        let fh_qx: [f64; 4] = std::array::from_fn(|k| (0..4).map(|l| fh[k][l] * qx[l]).sum());
        for j in 0..3 {
            let d_qx: f64 = (0..4).map(|k| d[j][k] * qx[k]).sum();
            p.r[j] += u * w * t[j];
            p.r_s[j] += w * (t[j] + u * c * d_qx);
            for a in 0..nn {
                for k in 0..4 {
                    p.r_q[j][4 * a + k] += u * w * n[a] * d[j][k];
                }
            }
        }
        let fd_qx: f64 = (0..4).map(|k| fd[k] * qx[k]).sum();
        let fd_qxx: f64 = (0..4).map(|k| fd[k] * qxx[k]).sum();
        let fh_qx_qx: f64 = (0..4).map(|k| fh_qx[k] * qx[k]).sum();
        p.f_ss += w * (2.0 * c * fd_qx + u * c * c * (fh_qx_qx + fd_qxx));
        for a in 0..nn {
            for k in 0..4 {
                p.f_sq[4 * a + k] += w * (n[a] * fd[k] + u * c * (dn[a] * fd[k] + n[a] * fh_qx[k]));
                for b in 0..nn {
                    for l in 0..4 {
                        p.f_qq[4 * a + k][4 * b + l] += u * w * n[a] * n[b] * fh[k][l];
                    }
                }
            }
        }
    }
    p
}

/// The point of rod `rod` at arc length `s` (m) in the state `x`, taken in element `e`, with
/// second derivatives contracted with `f`.
pub fn point_in_element(
    model: &DiscreteModel,
    x: &[f64],
    rod: RodId,
    e: usize,
    s: f64,
    f: [f64; 3],
) -> RodPoint {
    let r = &model.rods[rod];
    let h = r.mesh.vertices[e + 1] - r.mesh.vertices[e];
    let q = model.element_quaternions(x, r, e);
    let start = std::array::from_fn(|k| x[r.r_dof(e, k)]);
    rod_point(
        model.order,
        &model.rule,
        h,
        start,
        &q,
        s - r.mesh.vertices[e],
        f,
    )
}

/// The element a side's contact is taken in: the one holding its arc length, kept in the
/// window.
fn active_element(model: &DiscreteModel, side: &SlideSide, s: f64) -> usize {
    element_of(&model.rods[side.rod].mesh.vertices, s).clamp(side.first, side.last)
}

/// Position (m) of a side's contact in the state `x`.
pub fn contact(model: &DiscreteModel, side: &SlideSide, x: &[f64]) -> [f64; 3] {
    let s = x[side.dof];
    let e = active_element(model, side, s);
    point_in_element(model, x, side.rod, e, s, [0.0; 3]).r
}

/// The terms of the sliding joints `slides` (rows from `rows[i]`) in the residual and the KKT
/// matrix (through `add(row, col, value)`, visiting the same entries in the same order at
/// every state: every element of each window, zero where the contact is not).
pub fn assemble(
    model: &DiscreteModel,
    slides: &[SlideWindow],
    rows: &[usize],
    x: &[f64],
    residual: &mut [f64],
    add: &mut dyn FnMut(usize, usize, f64),
) {
    let p = model.order.degree();
    let nq = 4 * model.order.nodes();
    for (slide, &row) in slides.iter().zip(rows) {
        let nu = [x[row], x[row + 1], x[row + 2]];
        let turn = TurnZ::new(slide.turn);
        // g = r_R − T r_L, so the left rod sees the force −Tᵀ ν
        let back = turn.apply_inverse(nu);
        let tm: [[f64; 3]; 3] = {
            let cols = [
                turn.apply([1.0, 0.0, 0.0]),
                turn.apply([0.0, 1.0, 0.0]),
                turn.apply([0.0, 0.0, 1.0]),
            ];
            std::array::from_fn(|j| std::array::from_fn(|i| cols[i][j]))
        };
        for (i, side) in slide.sides.iter().enumerate() {
            let (sign, f) = if i == 0 { (1.0, nu) } else { (-1.0, back) };
            // ∂g_j/∂(side's r_i) = sign · M[j][i], M = I on the right, T on the left
            let m = |j: usize, k: usize| -> f64 {
                if i == 0 {
                    if j == k {
                        1.0
                    } else {
                        0.0
                    }
                } else {
                    tm[j][k]
                }
            };
            let rod = &model.rods[side.rod];
            let s = x[side.dof];
            let active = active_element(model, side, s);
            let pt = point_in_element(model, x, side.rod, active, s, f);
            for j in 0..3 {
                let mr: f64 = (0..3).map(|k| m(j, k) * pt.r[k]).sum();
                residual[row + j] += sign * mr;
            }
            // ∂/∂s
            let fr_s: f64 = (0..3).map(|k| f[k] * pt.r_s[k]).sum();
            residual[side.dof] += sign * fr_s;
            add(side.dof, side.dof, sign * pt.f_ss);
            for j in 0..3 {
                let v: f64 = sign * (0..3).map(|k| m(j, k) * pt.r_s[k]).sum::<f64>();
                add(row + j, side.dof, v);
                add(side.dof, row + j, v);
            }
            for e in side.first..=side.last {
                let on = e == active;
                let dofs = |a: usize| rod.q_dof(e * p + a / 4, a % 4);
                for k in 0..3 {
                    let rd = rod.r_dof(e, k);
                    if on {
                        residual[rd] += sign * f[k];
                    }
                    for j in 0..3 {
                        let v = if on { sign * m(j, k) } else { 0.0 };
                        add(row + j, rd, v);
                        add(rd, row + j, v);
                    }
                }
                for a in 0..nq {
                    let da = dofs(a);
                    if on {
                        residual[da] += sign * (0..3).map(|k| f[k] * pt.r_q[k][a]).sum::<f64>();
                    }
                    for j in 0..3 {
                        let v = if on {
                            sign * (0..3).map(|k| m(j, k) * pt.r_q[k][a]).sum::<f64>()
                        } else {
                            0.0
                        };
                        add(row + j, da, v);
                        add(da, row + j, v);
                    }
                    let v = if on { sign * pt.f_sq[a] } else { 0.0 };
                    add(side.dof, da, v);
                    add(da, side.dof, v);
                    for b in 0..nq {
                        let v = if on { sign * pt.f_qq[a][b] } else { 0.0 };
                        add(da, dofs(b), v);
                    }
                }
            }
        }
    }
}
