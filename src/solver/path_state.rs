//! The state of a continuation at a converged point: a value that can be cloned, kept and
//! put back (a rejected step, the probes of a critical-point search, a change of problem).

use super::newton::NewtonReport;
use crate::results::Stability;

/// A converged point of a path and what the next step starts from.
#[derive(Clone, Debug, PartialEq)]
pub struct PathState {
    /// Converged unknowns: primal, then multipliers.
    pub x: Vec<f64>,
    /// Load parameter of `x`.
    pub lambda: f64,
    /// `dx/dλ` at `x`, when known.
    pub tangent: Option<Vec<f64>>,
    /// The converged point before this one, for secant predictors in arclength mode.
    pub previous: Option<(Vec<f64>, f64)>,
    /// Step length: in `λ` for natural steps, in arclength otherwise.
    pub step: f64,
    /// Steps are pseudo-arclength ones.
    pub arclength: bool,
    /// The Newton solve that produced `x`.
    pub solve: NewtonReport,
    /// Stability of `x`, when tracked and computable.
    pub stability: Option<Stability>,
}

impl PathState {
    /// A state at `(x, λ)` not yet solved, with first step `step`.
    pub fn start(x: Vec<f64>, lambda: f64, step: f64) -> PathState {
        PathState {
            x,
            lambda,
            tangent: None,
            previous: None,
            step,
            arclength: false,
            solve: NewtonReport {
                iterations: 0,
                residual: 0.0,
                energy: 0.0,
            },
            stability: None,
        }
    }
}
