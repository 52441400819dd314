//! Unit quaternions as rotations (docs/theory.md §1).
//!
//! Convention of the thesis: `q = (q1, q2, q3, q4)` with vector part `(q1, q2, q3)`
//! and scalar part `q4`. Hamilton product, active rotation `v ↦ q v q̄`, so that
//! `R(q) = (q4² − q·q) I + 2 q qᵀ + 2 q4 [q]×` and the directors are the columns of `R`.

use nalgebra::{Matrix3, Vector3, Vector4};

/// Quaternion stored as `[q1, q2, q3, q4]` (vector part first, scalar last).
pub type Quat = Vector4<f64>;

/// Hamilton product `a ∘ b`.
pub fn mul(a: &Quat, b: &Quat) -> Quat {
    let (av, aw) = (Vector3::new(a[0], a[1], a[2]), a[3]);
    let (bv, bw) = (Vector3::new(b[0], b[1], b[2]), b[3]);
    let v = bv * aw + av * bw + av.cross(&bv);
    Quat::new(v[0], v[1], v[2], aw * bw - av.dot(&bv))
}

/// Conjugate `q̄ = (−q1, −q2, −q3, q4)`.
pub fn conj(q: &Quat) -> Quat {
    Quat::new(-q[0], -q[1], -q[2], q[3])
}

/// Rotation matrix of a (not necessarily unit) quaternion, divided by `|q|²` so that
/// it is a proper rotation for any `q ≠ 0`. Columns are the directors `d1, d2, d3`.
pub fn rotation(q: &Quat) -> Matrix3<f64> {
    let (q1, q2, q3, q4) = (q[0], q[1], q[2], q[3]);
    let d = q.norm_squared();
    Matrix3::new(
        q4 * q4 + q1 * q1 - q2 * q2 - q3 * q3,
        2.0 * (q1 * q2 - q3 * q4),
        2.0 * (q1 * q3 + q2 * q4),
        2.0 * (q1 * q2 + q3 * q4),
        q4 * q4 - q1 * q1 + q2 * q2 - q3 * q3,
        2.0 * (q2 * q3 - q1 * q4),
        2.0 * (q1 * q3 - q2 * q4),
        2.0 * (q2 * q3 + q1 * q4),
        q4 * q4 - q1 * q1 - q2 * q2 + q3 * q3,
    ) / d
}

/// Unit quaternion of a rotation matrix by Shepperd's method (largest-pivot branch,
/// so it is accurate for every rotation). The sign is that with `q4 ≥ 0` on the
/// `q4` branch; callers that need a continuous field fix the sign themselves.
pub fn from_rotation(r: &Matrix3<f64>) -> Quat {
    let tr = r.trace();
    let cands = [tr, r[(0, 0)], r[(1, 1)], r[(2, 2)]];
    let mut k = 0;
    for i in 1..4 {
        if cands[i] > cands[k] {
            k = i;
        }
    }
    let q = match k {
        0 => {
            let w = (1.0 + tr).sqrt() * 0.5;
            let f = 0.25 / w;
            Quat::new(
                (r[(2, 1)] - r[(1, 2)]) * f,
                (r[(0, 2)] - r[(2, 0)]) * f,
                (r[(1, 0)] - r[(0, 1)]) * f,
                w,
            )
        }
        1 => {
            let x = (1.0 + 2.0 * r[(0, 0)] - tr).sqrt() * 0.5;
            let f = 0.25 / x;
            Quat::new(
                x,
                (r[(0, 1)] + r[(1, 0)]) * f,
                (r[(0, 2)] + r[(2, 0)]) * f,
                (r[(2, 1)] - r[(1, 2)]) * f,
            )
        }
        2 => {
            let y = (1.0 + 2.0 * r[(1, 1)] - tr).sqrt() * 0.5;
            let f = 0.25 / y;
            Quat::new(
                (r[(0, 1)] + r[(1, 0)]) * f,
                y,
                (r[(1, 2)] + r[(2, 1)]) * f,
                (r[(0, 2)] - r[(2, 0)]) * f,
            )
        }
        _ => {
            let z = (1.0 + 2.0 * r[(2, 2)] - tr).sqrt() * 0.5;
            let f = 0.25 / z;
            Quat::new(
                (r[(0, 2)] + r[(2, 0)]) * f,
                (r[(1, 2)] + r[(2, 1)]) * f,
                z,
                (r[(1, 0)] - r[(0, 1)]) * f,
            )
        }
    };
    q / q.norm()
}

/// Rotation by angle `theta` (rad) about the global z axis.
pub fn about_z(theta: f64) -> Quat {
    Quat::new(0.0, 0.0, (0.5 * theta).sin(), (0.5 * theta).cos())
}

/// Body Darboux vector `(κ1, κ2, Ω) = 2 Im(q̄ ∘ q') / |q|²` (docs/theory.md §1), valid for
/// any non-zero `q` (the division removes the norm).
pub fn darboux(q: &Quat, dq: &Quat) -> Vector3<f64> {
    let p = mul(&conj(q), dq);
    Vector3::new(p[0], p[1], p[2]) * (2.0 / q.norm_squared())
}
