//! The rotational part of welded and elastic joints (docs/theory.md §2): the relative
//! rotation of the two rods' frames at a crossing, held (welded) or resisted by springs
//! (elastic).
//!
//! With `q_R`, `q_L` the nodal quaternions of the two rods at the crossing (the left one
//! turned about z when it stands for an image) and `q_0 = q̄_R0 ∘ q_L0` their natural
//! relative rotation, the deviation from it in the right rod's frame is
//! `p = q̄_R ∘ q_L ∘ q̄_0`, bilinear in `(q_R, q_L)`: `p_i = q_Rᵀ M_i q_L`. It is `±1` exactly
//! when the relative rotation is the natural one, whatever the rotations of the rods; its
//! vector part is `sin(φ/2) e` for a deviation by `φ` about the unit axis `e`.
//! - welded: `vec p = 0` (three rows; fewer at a rod end whose support already holds rotations);
//! - elastic: `W = ½ θᵀ K θ` with `θ = 2 vec p` and `K = k_o I + (k_s − k_o) n nᵀ`, `n` the
//!   normal to the tube's surface at the crossing in the right rod's frame.

use super::constraints::TipPlace;
use super::discrete_model::DiscreteModel;
use crate::model::assembly::Joint;
use crate::model::boundary::{BoundaryConditions, Joints, Rotation};
use crate::model::quaternion::{self, Quat};
use crate::model::symmetry::TurnZ;
use nalgebra::{Matrix3, Vector3};

/// How a joint resists the relative rotation of its rods.
#[derive(Clone, Debug)]
pub enum Resistance {
    /// Held: one constraint row `w · vec p = 0` per weight `w` (a vector of the right rod's frame).
    Welded { weights: Vec<Vector3<f64>> },
    /// Springs of stiffness matrix `K` (N m/rad) in the right rod's frame.
    Elastic { stiffness: Matrix3<f64> },
}

/// The rotational part of one joint.
#[derive(Clone, Debug)]
pub struct JointRotation {
    /// Index of the joint in the model's joints.
    pub joint: usize,
    /// The unknowns of the right rod's quaternion at the crossing, then the left rod's.
    pub dofs: [usize; 8],
    /// `p_i = q_Rᵀ M_i q_L` (`i = 0, 1, 2` the vector part, 3 the scalar part).
    m: [[[f64; 4]; 4]; 4],
    /// Rows: the surface normal `n`, the right rod's natural tangent `t` and `n × t`, in the
    /// right rod's frame: the axes the relative rotation is reported on.
    pub axes: Matrix3<f64>,
    pub resistance: Resistance,
}

/// What a joint's rotational part adds at a state: its energy (J), its gradient and Hessian
/// over [`JointRotation::dofs`], and its constraint rows (values and gradients).
pub struct JointTerms {
    pub energy: f64,
    pub gradient: [f64; 8],
    pub hessian: [[f64; 8]; 8],
    pub rows: Vec<(f64, [f64; 8])>,
}

impl JointRotation {
    /// The rotational part of joint `index` under `bc`, with the natural state `natural`;
    /// `held_axis` is the axis a `Pinned` support at the joint's end holds rotations about,
    /// and `x` the state the end's held directions are taken at. `None` for pins, or where
    /// there is nothing left to hold (a welded joint at an end whose rods are clamped).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        model: &DiscreteModel,
        natural: &[f64],
        x: &[f64],
        bc: &BoundaryConditions,
        index: usize,
        joint: &Joint,
        held_axis: Vector3<f64>,
    ) -> Option<JointRotation> {
        let mut out = JointRotation::measure(model, natural, index, joint)?;
        let n = Vector3::from(out.axes.row(0).transpose());
        out.resistance = match bc.joints {
            Joints::Pin | Joints::None | Joints::Sliding => return None,
            Joints::Elastic(k) => Resistance::Elastic {
                stiffness: Matrix3::identity() * k.out_of_plane
                    + n * n.transpose() * (k.scissor - k.out_of_plane),
            },
            Joints::Welded => {
                let length = model.length();
                // a cell's rods end at crossings but have no supports there: its periodic
                // conditions tie the ends' frames to their images, not to the world
                let end = if model.assembly.cell.is_some() {
                    None
                } else if joint.s <= 1e-9 * length {
                    Some(bc.base.rotation)
                } else if joint.s >= length * (1.0 - 1e-9) {
                    Some(bc.tip.rotation)
                } else {
                    None
                };
                let q = Quat::from(std::array::from_fn(|k| x[out.dofs[k]]));
                let rot = quaternion::rotation(&q);
                let weights = match end {
                    Some(Rotation::Clamped) => return None,
                    // the rotation about the held axis is held on both rods already: the
                    // two directions normal to it, in the right rod's frame
                    Some(Rotation::Pinned) => {
                        let a = held_axis / held_axis.norm();
                        let u = if a[0].abs() < 0.9 {
                            Vector3::x()
                        } else {
                            Vector3::y()
                        };
                        let u = (u - a * a.dot(&u)).normalize();
                        let v = a.cross(&u);
                        vec![rot.transpose() * u, rot.transpose() * v]
                    }
                    Some(Rotation::Free) | None => {
                        vec![Vector3::x(), Vector3::y(), Vector3::z()]
                    }
                };
                Resistance::Welded { weights }
            }
        };
        Some(out)
    }

    /// The relative rotation of joint `index` as a measure only (springs of no stiffness):
    /// what a pin's rods turn by. `None` where the joint is at no vertex of its rods.
    pub fn measure(
        model: &DiscreteModel,
        natural: &[f64],
        index: usize,
        joint: &Joint,
    ) -> Option<JointRotation> {
        let (ri, rj) = (&model.rods[joint.right], &model.rods[joint.left]);
        let p = model.order.degree();
        let vi = ri.mesh.vertex_at(joint.s)?;
        let vj = rj.mesh.vertex_at(joint.s)?;
        let (ni, nj) = (vi * p, vj * p);
        let turn = TurnZ::new(joint.left_turn);
        let unit = |q: Quat| q / q.norm();
        let qr0 = unit(model.quaternion(natural, joint.right, ni));
        let ql0 = turn.rotate(&unit(model.quaternion(natural, joint.left, nj)));
        let c = quaternion::conj(&quaternion::mul(&quaternion::conj(&qr0), &ql0));
        let basis = |k: usize| {
            let mut e = Quat::zeros();
            e[k] = 1.0;
            e
        };
        let m = std::array::from_fn(|i| {
            std::array::from_fn(|a| {
                std::array::from_fn(|b| {
                    let left = quaternion::mul(&turn.rotate(&basis(b)), &c);
                    quaternion::mul(&quaternion::conj(&basis(a)), &left)[i]
                })
            })
        });
        let r = model.vertex(natural, joint.right, vi);
        let radial = Vector3::new(r[0], r[1], 0.0);
        let radial = if radial.norm() > 0.0 {
            radial / radial.norm()
        } else {
            Vector3::x()
        };
        let n = quaternion::rotation(&qr0).transpose() * radial;
        let t = Vector3::z() - n * n[2];
        let t = t / t.norm();
        let axes = Matrix3::from_rows(&[n.transpose(), t.transpose(), n.cross(&t).transpose()]);
        let dofs = std::array::from_fn(|k| {
            if k < 4 {
                ri.q_dof(ni, k)
            } else {
                rj.q_dof(nj, k - 4)
            }
        });
        Some(JointRotation {
            joint: index,
            dofs,
            m,
            axes,
            resistance: Resistance::Elastic {
                stiffness: Matrix3::zeros(),
            },
        })
    }

    /// Constraint rows it adds (welded), none for springs.
    pub fn rows(&self) -> usize {
        match &self.resistance {
            Resistance::Welded { weights } => weights.len(),
            Resistance::Elastic { .. } => 0,
        }
    }

    fn quaternions(&self, x: &[f64]) -> ([f64; 4], [f64; 4]) {
        (
            std::array::from_fn(|k| x[self.dofs[k]]),
            std::array::from_fn(|k| x[self.dofs[4 + k]]),
        )
    }

    /// The deviation `p` from the natural relative rotation at the state `x`.
    pub fn deviation(&self, x: &[f64]) -> Quat {
        let (qr, ql) = self.quaternions(x);
        Quat::from_fn(|i, _| {
            let mut v = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    v += qr[a] * self.m[i][a][b] * ql[b];
                }
            }
            v
        })
    }

    /// `∂p_i/∂(q_R, q_L)`.
    fn deviation_gradient(&self, x: &[f64], i: usize) -> [f64; 8] {
        let (qr, ql) = self.quaternions(x);
        std::array::from_fn(|k| {
            if k < 4 {
                (0..4).map(|b| self.m[i][k][b] * ql[b]).sum()
            } else {
                (0..4).map(|a| qr[a] * self.m[i][a][k - 4]).sum()
            }
        })
    }

    /// The relative rotation `θ` (rad) from the natural one at the state `x`, in the right
    /// rod's frame on [`JointRotation::axes`] (normal, tangent, binormal): `2 vec p` with
    /// the sign of `p` that makes its scalar part positive.
    pub fn rotation(&self, x: &[f64]) -> Vector3<f64> {
        let p = self.deviation(x);
        let sign = if p[3] < 0.0 { -2.0 } else { 2.0 };
        self.axes * Vector3::new(p[0], p[1], p[2]) * sign
    }

    /// Energy, gradient, Hessian and rows at the state `x`; `multipliers` are the values
    /// of its rows' multipliers (welded).
    pub fn terms(&self, x: &[f64], multipliers: &[f64]) -> JointTerms {
        let grads: [[f64; 8]; 3] = std::array::from_fn(|i| self.deviation_gradient(x, i));
        let p = self.deviation(x);
        let v = Vector3::new(p[0], p[1], p[2]);
        let mut out = JointTerms {
            energy: 0.0,
            gradient: [0.0; 8],
            hessian: [[0.0; 8]; 8],
            rows: Vec::new(),
        };
        // the second derivative of Σ c_i p_i: c_i M_i in the (q_R, q_L) block
        let cross = |c: Vector3<f64>, hessian: &mut [[f64; 8]; 8]| {
            for a in 0..4 {
                for b in 0..4 {
                    let h: f64 = (0..3).map(|i| c[i] * self.m[i][a][b]).sum();
                    hessian[a][4 + b] += h;
                    hessian[4 + b][a] += h;
                }
            }
        };
        match &self.resistance {
            Resistance::Welded { weights } => {
                let mut c = Vector3::zeros();
                for (w, nu) in weights.iter().zip(multipliers) {
                    let g: [f64; 8] =
                        std::array::from_fn(|k| (0..3).map(|i| w[i] * grads[i][k]).sum());
                    for k in 0..8 {
                        out.gradient[k] += nu * g[k];
                    }
                    c += w * *nu;
                    out.rows.push((w.dot(&v), g));
                }
                cross(c, &mut out.hessian);
            }
            Resistance::Elastic { stiffness } => {
                // W = ½ (2v)ᵀ K (2v) = 2 vᵀ K v
                let kv = stiffness * v;
                out.energy = 2.0 * v.dot(&kv);
                for k in 0..8 {
                    out.gradient[k] = 4.0 * (0..3).map(|i| kv[i] * grads[i][k]).sum::<f64>();
                }
                for a in 0..8 {
                    for b in 0..8 {
                        let mut h = 0.0;
                        for i in 0..3 {
                            for j in 0..3 {
                                h += stiffness[(i, j)] * grads[i][a] * grads[j][b];
                            }
                        }
                        out.hessian[a][b] = 4.0 * h;
                    }
                }
                cross(kv * 4.0, &mut out.hessian);
            }
        }
        out
    }

    /// The moments (N m, global frame) the joint applies to its right rod and to its left
    /// rod (the one of the model, not its image) at the state `x`, from the generalised
    /// forces `−∂(W + ν·g)/∂q`: a virtual rotation `δθ` moves `q` by `½ (δθ, 0) ∘ q`.
    pub fn moments(&self, x: &[f64], multipliers: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let t = self.terms(x, multipliers);
        let (qr, ql) = self.quaternions(x);
        let moment = |f: &[f64], q: [f64; 4]| {
            let q = Quat::from(q);
            Vector3::from_fn(|i, _| {
                let mut e = Quat::zeros();
                e[i] = 1.0;
                let d = quaternion::mul(&e, &q);
                -0.5 * (0..4).map(|k| f[k] * d[k]).sum::<f64>()
            })
        };
        (moment(&t.gradient[..4], qr), moment(&t.gradient[4..], ql))
    }
}

/// The rotational parts of the joints of a welded or elastic assembly under `bc` (none for
/// pins), the tip support at `tip`.
pub(super) fn of_assembly(
    model: &DiscreteModel,
    x: &[f64],
    bc: &BoundaryConditions,
    tip: TipPlace,
) -> Vec<JointRotation> {
    if !matches!(bc.joints, Joints::Welded | Joints::Elastic(_)) {
        return Vec::new();
    }
    let natural = model.natural_state();
    let tip_axis = match tip {
        TipPlace::Turned { pose, .. } => quaternion::rotation(&pose.rotation) * Vector3::z(),
        TipPlace::Upright { .. } => Vector3::z(),
    };
    let length = model.length();
    model
        .assembly
        .joints
        .iter()
        .enumerate()
        .filter_map(|(j, joint)| {
            let axis = if joint.s >= length * (1.0 - 1e-9) {
                tip_axis
            } else {
                Vector3::z()
            };
            JointRotation::new(model, &natural, x, bc, j, joint, axis)
        })
        .collect()
}

/// The joints' rotational terms at `x`, the rows of part `i` from `rows[i]`: the springs'
/// energy, gradient and Hessian, or the rows of welded joints and their multipliers' terms,
/// added to `residual` and, entry by entry, to the KKT matrix by `add(row, col, value)`
/// (every entry, zero or not, so that the pattern is the same at every state). Returns the
/// springs' energy (J).
pub(super) fn assemble(
    parts: &[JointRotation],
    rows: &[usize],
    x: &[f64],
    residual: &mut [f64],
    add: &mut dyn FnMut(usize, usize, f64),
) -> f64 {
    let mut energy = 0.0;
    for (r, &row) in parts.iter().zip(rows) {
        let t = r.terms(x, &x[row..row + r.rows()]);
        energy += t.energy;
        for (a, &da) in r.dofs.iter().enumerate() {
            residual[da] += t.gradient[a];
            for (b, &db) in r.dofs.iter().enumerate() {
                add(da, db, t.hessian[a][b]);
            }
        }
        for (k, (value, gradient)) in t.rows.iter().enumerate() {
            residual[row + k] = *value;
            for (&d, &g) in r.dofs.iter().zip(gradient) {
                add(d, row + k, g);
                add(row + k, d, g);
            }
        }
    }
    energy
}
