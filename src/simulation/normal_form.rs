//! The normal form of a perfect structure's bifurcation (Koiter): the branch that crosses
//! the path there, `λ ≈ λc + a ξ + b ξ²` in the amplitude `ξ` of the critical mode (its
//! largest centreline displacement over the rod length), measured on the branch itself —
//! points of it reached by a switch at a few small amplitudes either side, `a` and `b`
//! fitted to them.

use super::flaw::max_displacement;
use super::judge::all_cores;
use super::{Simulation, SolveError};
use crate::case::Case;
use nalgebra::{DMatrix, DVector};

/// The amplitudes, in multiples of the smallest, at which the branch is sampled (each on
/// both sides of the path).
const MULTIPLES: [f64; 3] = [1.0, 2.0, 3.0];

/// How a bifurcation responds to a flaw, by its normal form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BifurcationType {
    /// `a ≠ 0`: the branch crosses the path; a flaw of one sign makes the path turn, the
    /// parameter dropping as `δ^(1/2)`.
    Asymmetric,
    /// `a = 0`, the branch bending back (`b` against the path's direction): the path turns,
    /// the parameter dropping as `δ^(2/3)`.
    UnstableSymmetric,
    /// `a = 0`, the branch rising with the path: no limit point, no drop.
    StableSymmetric,
}

impl BifurcationType {
    pub fn name(self) -> &'static str {
        match self {
            BifurcationType::Asymmetric => "asymmetric",
            BifurcationType::UnstableSymmetric => "unstable-symmetric",
            BifurcationType::StableSymmetric => "stable-symmetric",
        }
    }

    /// Koiter's exponent of the drop of the limit parameter in the flaw's amplitude
    /// (`None`: the path does not turn).
    pub fn koiter_exponent(self) -> Option<f64> {
        match self {
            BifurcationType::Asymmetric => Some(0.5),
            BifurcationType::UnstableSymmetric => Some(2.0 / 3.0),
            BifurcationType::StableSymmetric => None,
        }
    }
}

/// The normal form of a perfect bifurcation, in the load parameter and the mode amplitude
/// `ξ` (largest centreline displacement over the rod length `L`).
#[derive(Clone, Debug, PartialEq)]
pub struct NormalForm {
    /// Index of the critical point on the perfect path.
    pub index: usize,
    /// `λc`.
    pub parameter: f64,
    /// Koiter's `a`: the slope `dλ/dξ` of the branch at the point.
    pub a: f64,
    /// Koiter's `b`: its curvature `½ d²λ/dξ²`.
    pub b: f64,
    pub kind: BifurcationType,
    /// The branch points measured, `(ξ, λ)`.
    pub samples: Vec<(f64, f64)>,
}

/// The normal form of bifurcation `index` of the perfect path of `case` (its imperfection
/// ignored), from its branch sampled at amplitudes `ξ = ±xi, ±2 xi, ±3 xi` (in rod lengths):
/// each reached from the critical point by a switch whose step fixes the component of the
/// state along the mode, `λ(ξ)` fitted by `λc + a ξ + b ξ² + c ξ³`. The point is asymmetric
/// where the slope's share of the change of `λ` at the smallest amplitude, `|a| xi / (|a| xi +
/// |b| xi²)`, exceeds one half.
pub fn normal_form(case: &Case, index: usize, xi: f64) -> Result<NormalForm, SolveError> {
    let mut samples = Vec::new();
    let mut parameter = 0.0;
    for m in MULTIPLES {
        for sign in [1.0, -1.0] {
            let mut sim = Simulation::perfect_until(case, index, &None, all_cores())?;
            let cp = sim.critical_points()[index].clone();
            parameter = cp.parameter;
            let on = sim.mode_on_model(&cp);
            let largest = max_displacement(&on.model, &on.mode);
            let length = on.model.length();
            sim.switch_branch(index, sign, m * xi * length / largest)?;
            let np = on.model.n_primal;
            let along =
                |v: &[f64]| -> f64 { (0..np).map(|i| (sim.state()[i] - on.state[i]) * v[i]).sum() };
            // at a double point the branch leaves along a direction of the plane of its
            // modes: its amplitude is the step's length in that plane
            let first = along(&on.mode);
            let amplitude = match on.second.as_deref().filter(|s| s.len() >= np) {
                Some(second) => first.hypot(along(second)) * sign,
                None => first,
            };
            samples.push((amplitude * largest / length, sim.parameter()));
        }
    }
    let (a, b) = fit(&samples, parameter);
    let rising = case.loading.target >= 0.0;
    let slope_share = (a.abs() * xi) / (a.abs() * xi + b.abs() * xi * xi);
    let kind = if slope_share > 0.5 {
        BifurcationType::Asymmetric
    } else if (b >= 0.0) == rising {
        BifurcationType::StableSymmetric
    } else {
        BifurcationType::UnstableSymmetric
    };
    Ok(NormalForm {
        index,
        parameter,
        a,
        b,
        kind,
        samples,
    })
}

/// Least-squares `a`, `b` of `λ − λc = a ξ + b ξ² + c ξ³` through the samples.
fn fit(samples: &[(f64, f64)], parameter: f64) -> (f64, f64) {
    let rows = samples.len();
    let m = DMatrix::from_fn(rows, 3, |i, j| samples[i].0.powi(j as i32 + 1));
    let y = DVector::from_fn(rows, |i, _| samples[i].1 - parameter);
    let normal = m.transpose() * &m;
    let rhs = m.transpose() * y;
    match normal.lu().solve(&rhs) {
        Some(c) => (c[0], c[1]),
        None => (0.0, 0.0),
    }
}

/// Koiter's law fitted to a sweep of flaws: `drop ≈ C |δ|^p` by least squares of
/// `log drop` against `log |δ|`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KoiterFit {
    /// `p`.
    pub exponent: f64,
    /// `C`.
    pub coefficient: f64,
    /// The samples fitted.
    pub samples: usize,
    /// `log10` of the largest over the smallest `|δ|`: the decades spanned.
    pub decades: f64,
}

/// The fit of `drop ≈ C |δ|^p` through the samples `(δ, drop)` whose drop is positive and
/// finite; `None` with fewer than two such samples or a single amplitude.
pub fn koiter_fit(samples: &[(f64, f64)]) -> Option<KoiterFit> {
    let logs: Vec<(f64, f64)> = samples
        .iter()
        .filter(|(d, drop)| d.is_finite() && *d != 0.0 && drop.is_finite() && *drop > 0.0)
        .map(|(d, drop)| (d.abs().ln(), drop.ln()))
        .collect();
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(x, y), (a, b)| (x + a / n, y + b / n));
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    if logs.len() < 2 || sxx <= 0.0 {
        return None;
    }
    let exponent = sxy / sxx;
    let (lo, hi) = logs.iter().fold((f64::MAX, f64::MIN), |(lo, hi), (x, _)| {
        (lo.min(*x), hi.max(*x))
    });
    Some(KoiterFit {
        exponent,
        coefficient: (my - exponent * mx).exp(),
        samples: logs.len(),
        decades: (hi - lo) / std::f64::consts::LN_10,
    })
}
