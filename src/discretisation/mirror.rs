//! The mirror symmetry of a tube of helices: the reflection `y ↦ −y` in the plane through
//! the axis and the base of rod 0 maps every right-handed helix onto a left-handed one
//! and back (`R_k ↔ L_j`, the meshes alike since the crossings are at the same arc
//! lengths on both). It acts linearly on the primal unknowns — positions reflected,
//! frames reflected with one director turned back so that they stay right-handed — and
//! so on states and modes alike. A wavenumber-1 double point of the cyclic symmetry has
//! a plane of modes that the mirror maps onto itself, as a reflection: the branches
//! leave along its fixed lines (docs/theory.md §7).

use super::discrete_model::DiscreteModel;
use crate::model::quaternion::{self, Quat};

/// The mirror `y ↦ −y` of a model's states: the rod each rod is mapped onto, and how a
/// frame's quaternion maps (`(q1, q2, q3, q4) ↦ (−q1, q2, −q3, q4)`, the reflected frame
/// with its second director turned back, then, for `flip`, turned by π about its tangent).
#[derive(Clone, Debug)]
pub struct Mirror {
    partner: Vec<usize>,
    flip: bool,
}

/// Relative tolerance (on the rod length) to which the natural state must be mirrored.
const TOL: f64 = 1e-9;

impl Mirror {
    /// The mirror of `model`, when its natural state is mirror symmetric (every rod's
    /// reflection is a rod of the model, frames included); `None` otherwise (one helix,
    /// straight rods on the axis, meshes that differ).
    pub fn of(model: &DiscreteModel) -> Option<Mirror> {
        if model.rods.len() < 2 {
            return None;
        }
        let x = model.natural_state();
        let scale = model.length();
        let mut partner = Vec::with_capacity(model.rods.len());
        for (k, rod) in model.rods.iter().enumerate() {
            let found = model.rods.iter().enumerate().position(|(j, other)| {
                other.mesh.elements() == rod.mesh.elements()
                    && (0..=rod.mesh.elements()).all(|v| {
                        let a = model.vertex(&x, k, v);
                        let b = model.vertex(&x, j, v);
                        (a[0] - b[0]).abs() + (a[1] + b[1]).abs() + (a[2] - b[2]).abs()
                            <= TOL * scale
                    })
            })?;
            partner.push(found);
        }
        let flip = [false, true].into_iter().find(|&flip| {
            let mirror = Mirror {
                partner: partner.clone(),
                flip,
            };
            model.rods.iter().enumerate().all(|(k, rod)| {
                (0..rod.mesh.quaternion_nodes()).all(|node| {
                    let image = mirror.quaternion(&model.quaternion(&x, k, node));
                    let there = model.quaternion(&x, partner[k], node);
                    // a quaternion and its negative are the same frame
                    (image - there).norm().min((image + there).norm()) <= 1e-9
                })
            })
        })?;
        Some(Mirror { partner, flip })
    }

    /// The image of a frame's quaternion (linear in `q`).
    fn quaternion(&self, q: &Quat) -> Quat {
        let reflected = Quat::new(-q[0], q[1], -q[2], q[3]);
        if self.flip {
            // ∘ (0, 0, 1, 0): a turn by π about the body's d3
            quaternion::mul(&reflected, &Quat::new(0.0, 0.0, 1.0, 0.0))
        } else {
            reflected
        }
    }

    /// Whether the state `x` is its own mirror image: every vertex mirrored onto its
    /// partner's to `TOL` of the rod length, every frame onto its partner's to 1e-9.
    pub fn keeps(&self, model: &DiscreteModel, x: &[f64]) -> bool {
        let scale = model.length();
        model.rods.iter().enumerate().all(|(k, rod)| {
            let to = self.partner[k];
            (0..=rod.mesh.elements()).all(|v| {
                let a = model.vertex(x, k, v);
                let b = model.vertex(x, to, v);
                (a[0] - b[0]).abs() + (a[1] + b[1]).abs() + (a[2] - b[2]).abs() <= TOL * scale
            }) && (0..rod.mesh.quaternion_nodes()).all(|node| {
                let image = self.quaternion(&model.quaternion(x, k, node));
                let there = model.quaternion(x, to, node);
                (image - there).norm().min((image + there).norm()) <= 1e-9
            })
        })
    }

    /// The mirror image of the primal unknowns of `v` (a state or a mode; multipliers
    /// are not touched and come back zero), in `model`'s layout.
    pub fn apply(&self, model: &DiscreteModel, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        for (k, rod) in model.rods.iter().enumerate() {
            let to = &model.rods[self.partner[k]];
            for node in 0..rod.mesh.quaternion_nodes() {
                let q = self.quaternion(&model.quaternion(v, k, node));
                for c in 0..4 {
                    out[to.q_dof(node, c)] = q[c];
                }
            }
            for vertex in 0..=rod.mesh.elements() {
                let r = model.vertex(v, k, vertex);
                let image = [r[0], -r[1], r[2]];
                for c in 0..3 {
                    out[to.r_dof(vertex, c)] = image[c];
                }
            }
        }
        out
    }

    /// The fixed line of the mirror in the plane of the modes `a`, `b` (primal unknowns
    /// compared; whole vectors combined). `None` when the mirror does not map the plane
    /// onto itself (loads or supports that break it) or `a`, `b` span no plane.
    pub fn fixed_line(&self, model: &DiscreteModel, a: &[f64], b: &[f64]) -> Option<InPlane> {
        let np = model.n_primal;
        let dot = |u: &[f64], w: &[f64]| -> f64 {
            u[..np].iter().zip(&w[..np]).map(|(p, q)| p * q).sum()
        };
        // an orthonormal basis e1 = a/|a|, e2 = (b − (b·e1) e1)/|…| of the plane, as
        // combinations of a and b
        let na: f64 = dot(a, a).sqrt();
        let ab: f64 = dot(a, b) / na;
        let perp = (dot(b, b) - ab * ab).max(0.0).sqrt();
        if !(na > 0.0 && perp > 1e-6 * dot(b, b).sqrt()) {
            return None;
        }
        let e1 = [1.0 / na, 0.0];
        let e2 = [-ab / (na * perp), 1.0 / perp];
        let combine = |c: [f64; 2]| -> Vec<f64> {
            a[..np]
                .iter()
                .zip(&b[..np])
                .map(|(p, q)| c[0] * p + c[1] * q)
                .collect()
        };
        let (u1, u2) = (combine(e1), combine(e2));
        let (m1, m2) = (self.apply(model, &u1), self.apply(model, &u2));
        // the mirror in the plane: s_ij = e_i · σ e_j, a reflection when the plane is
        // mapped onto itself (σ is orthogonal: what it maps out of the plane is lost)
        let s = [
            [dot(&u1, &m1), dot(&u1, &m2)],
            [dot(&u2, &m1), dot(&u2, &m2)],
        ];
        let kept = s[0][0].powi(2) + s[1][0].powi(2) + s[0][1].powi(2) + s[1][1].powi(2);
        let reflection = (s[0][0] + s[1][1]).abs() < 1e-6 && (kept - 2.0).abs() < 1e-6;
        // fixed line of [[cos 2θ, sin 2θ], [sin 2θ, −cos 2θ]]: angle θ
        reflection.then(|| InPlane {
            e1,
            e2,
            theta: 0.5 * s[1][0].atan2(s[0][0]),
        })
    }
}

/// The plane of two modes `a`, `b` with an orthonormal basis `e1`, `e2` (each given by its
/// coefficients on `a` and `b`) and the angle `theta` (rad, from `e1` towards `e2`) of the
/// mirror's fixed line in it.
#[derive(Clone, Copy, Debug)]
pub struct InPlane {
    e1: [f64; 2],
    e2: [f64; 2],
    pub theta: f64,
}

impl InPlane {
    /// The coefficients `(α, β)` of `α a + β b = cos ψ e1 + sin ψ e2`.
    pub fn along(&self, psi: f64) -> [f64; 2] {
        let (c, s) = (psi.cos(), psi.sin());
        [
            c * self.e1[0] + s * self.e2[0],
            c * self.e1[1] + s * self.e2[1],
        ]
    }
}
