//! The mechanics against numbers that do not come from spira: closed forms, finite
//! differences, convergence orders, the symmetric pair against the full model
//! (`cargo test --release --test physics`).

mod beam;
mod bending;
mod bulk;
mod cell;
mod critical_curves;
mod free_motion;
mod imperfection;
mod joints;
mod loads;
mod mirror;
mod precision;
mod robustness;
mod rods;
mod sliding;
mod sliding_cell;
mod stability;
mod symmetry;

use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::system::System;

/// The thesis helices (§4.1): a0 = 0.06 m, b0 = 0.025 m, B = 1, C = 2 N m².
pub const A0: f64 = 0.06;
pub const B0: f64 = 0.025;
pub const STIFFNESS: spira::model::stiffness::Stiffness = spira::model::stiffness::Stiffness {
    b1: 1.0,
    b2: 1.0,
    b3: 2.0,
};

/// The largest difference between the columns `columns` of the KKT matrix of `sys` at `x`
/// and central differences (step 1e-6) of its residual, and the largest difference itself:
/// `(worst, scale)`.
pub fn kkt_against_differences(
    sys: &System,
    model: &DiscreteModel,
    x: &[f64],
    columns: impl IntoIterator<Item = usize>,
) -> (f64, f64) {
    let mut values = sys.new_values();
    let mut r0 = vec![0.0; sys.n];
    sys.evaluate(model, x, &mut r0, &mut values);
    let m = sys.matrix(&values);
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    let h = 1e-6;
    let (mut rp, mut rm) = (vec![0.0; sys.n], vec![0.0; sys.n]);
    let (mut worst, mut scale): (f64, f64) = (0.0, 0.0);
    for j in columns {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[j] += h;
        xm[j] -= h;
        sys.residual(model, &xp, &mut rp);
        sys.residual(model, &xm, &mut rm);
        let mut column = vec![0.0; sys.n];
        for p in cp[j]..cp[j + 1] {
            column[ri[p]] += m.val()[p];
        }
        for i in 0..sys.n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            worst = worst.max((fd - column[i]).abs());
            scale = scale.max(fd.abs());
        }
    }
    (worst, scale)
}

/// Composite Simpson over equal steps of the values `f` (an even number of intervals).
pub fn simpson(f: &[f64], step: f64) -> f64 {
    let n = f.len() - 1;
    assert!(n % 2 == 0);
    let inner: f64 = (1..n)
        .map(|k| if k % 2 == 1 { 4.0 * f[k] } else { 2.0 * f[k] })
        .sum();
    step / 3.0 * (f[0] + inner + f[n])
}

/// Along `points` of a path whose tips move by equal steps of their height: the energy
/// stored (J), the supports' work Σ_rods ∫ Fz dh by composite Simpson (J), and their
/// relative difference.
pub fn energy_and_tip_work(points: &[spira::results::LoadPoint]) -> (f64, f64, f64) {
    let fz: Vec<f64> = points
        .iter()
        .map(|p| p.reactions.iter().map(|r| r.tip.force[2]).sum())
        .collect();
    let dh = points[1].height - points[0].height;
    let work = simpson(&fz, dh);
    let energy = points[points.len() - 1].energy - points[0].energy;
    (energy, work, (energy - work).abs() / energy)
}

/// The point in `(lo, hi)` where the predicate `unstable` changes, by bisection to `tol`.
pub fn bisect_change(mut unstable: impl FnMut(f64) -> bool, lo: f64, hi: f64, tol: f64) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    let at_lo = unstable(lo);
    assert_ne!(at_lo, unstable(hi), "no change in ({lo}, {hi})");
    while hi - lo > tol {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) == at_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The tributary arc length of every primal unknown (m): the metric of the stability's
/// eigenproblem, each node's quaternion weighted by its share of the rod, positions and
/// contacts' arc lengths zero.
pub fn rotation_metric(model: &spira::discretisation::discrete_model::DiscreteModel) -> Vec<f64> {
    let mut metric = vec![0.0; model.n_primal];
    let degree = model.order.degree();
    for rod in &model.rods {
        for e in 0..rod.mesh.elements() {
            let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
            for a in 0..=degree {
                let end = a == 0 || a == degree;
                let w = h / (if end { 2.0 } else { 1.0 } * degree as f64);
                for q in 0..4 {
                    metric[rod.q_dof(e * degree + a, q)] += w;
                }
            }
        }
    }
    metric
}
