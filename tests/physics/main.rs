//! The mechanics against numbers that do not come from spira: closed forms, finite
//! differences, convergence orders, the symmetric pair against the full model
//! (`cargo test --release --test physics`).

mod beam;
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
mod stability;
mod symmetry;

use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::system::System;

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
