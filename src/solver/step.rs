//! One step of a path: the predictor (tangent, or secant in the arclength metric), the
//! corrector, and the test that the corrector stayed on the path it was predicted on.

use super::continuation::{Continuation, Trial};
use super::linear::LinearError;
use super::newton::{NewtonError, StepEquation};
use super::problem::Problem;

/// The largest move of the corrector from the predicted state, relative to the predictor's
/// length, that a step may take; a smooth path's is of the order of the step times its
/// curvature.
const MAX_CORRECTION: f64 = 0.5;

impl<P: Problem> Continuation<P> {
    /// One step of length `h` towards `dir · λ` ([`Continuation::try_step`]) that kept to
    /// its path: a corrector that moved the state more than [`MAX_CORRECTION`] of the
    /// predictor's length has left the path it predicted (onto another branch, or across a
    /// fold), and the step fails as a Newton failure would, to be retried shorter — unless
    /// it is as short as a step may be.
    pub(super) fn try_step_on_path(&mut self, h: f64, dir: f64) -> Result<Trial, NewtonError> {
        let shortest = h <= self.settings.min_step * 1.000001;
        self.try_step(h, dir).and_then(|t| {
            if t.correction > MAX_CORRECTION && !shortest {
                Err(NewtonError::LeftPath {
                    correction: t.correction,
                })
            } else {
                Ok(t)
            }
        })
    }

    /// `dx/dλ` at the current state, with linear solves checked against `threshold`. The
    /// factorisation at the converged state is kept for the next corrector.
    pub(super) fn compute_tangent(&mut self, threshold: f64) -> Option<Vec<f64>> {
        self.newton
            .tangent(
                &mut self.problem,
                &self.state.x,
                self.state.lambda,
                threshold,
            )
            .ok()
    }

    /// Unit tangent `(t_x, t_λ)` over the primal unknowns and `λ` in the arclength metric
    /// `ds² = ‖dx‖²/n_p + dλ²` (the root mean square of the primal unknowns, as AUTO
    /// measures a path: a step then moves `λ` by about as much whatever the size of the
    /// model — the whole assembly of n = 16 rods as its symmetric pair), `t_x` weighted
    /// by `1/n_p` for the step equation, and the full-length predictor direction, for an
    /// arclength step heading towards increasing `dir · λ`.
    fn arclength_direction(&mut self, dir: f64) -> Option<(Vec<f64>, f64, Vec<f64>)> {
        let np = self.problem.primal_unknowns();
        let (full, dl) = match &self.state.previous {
            Some((xp, lp)) => {
                let d: Vec<f64> = self.state.x.iter().zip(xp).map(|(a, b)| a - b).collect();
                (d, self.state.lambda - lp)
            }
            None => {
                if self.state.tangent.is_none() {
                    self.state.tangent =
                        self.compute_tangent(self.settings.newton.singular_threshold);
                }
                let t = self.state.tangent.clone()?;
                (t.iter().map(|v| v * dir).collect(), dir)
            }
        };
        let weight = 1.0 / np.max(1) as f64;
        let norm = (weight * (0..np).map(|i| full[i] * full[i]).sum::<f64>() + dl * dl).sqrt();
        if norm.is_nan() || norm <= 0.0 {
            return None;
        }
        let full: Vec<f64> = full.iter().map(|v| v / norm).collect();
        let tx = full[..np].iter().map(|v| v * weight).collect();
        Some((tx, dl / norm, full))
    }

    /// One step of length `h` (natural: in `λ` towards `dir`; arclength: along the path).
    fn try_step(&mut self, h: f64, dir: f64) -> Result<Trial, NewtonError> {
        let settings = self.settings.newton;
        if self.state.arclength {
            let Some((tx, tl, full)) = self.arclength_direction(dir) else {
                return Err(NewtonError::Linear {
                    iteration: 0,
                    source: LinearError::Singular {
                        relative_residual: f64::INFINITY,
                    },
                });
            };
            let x: Vec<f64> = self
                .state
                .x
                .iter()
                .zip(&full)
                .map(|(a, t)| a + h * t)
                .collect();
            let lambda = self.state.lambda + h * tl;
            let x0 = self.state.x.clone();
            let step = StepEquation {
                tx: Some(&tx),
                tl,
                x0: &x0,
                l0: self.state.lambda,
                ds: h,
            };
            let predicted = x.clone();
            let trial = self.correct(x, lambda, &step, &settings);
            trial.map(|t| self.with_correction(t, &x0, &predicted))
        } else {
            if self.state.tangent.is_none() {
                self.state.tangent = self.compute_tangent(settings.singular_threshold);
            }
            let d = dir * h;
            let mut x = self.state.x.clone();
            if let Some(t) = &self.state.tangent {
                for (xi, ti) in x.iter_mut().zip(t) {
                    *xi += ti * d;
                }
            }
            let x0 = self.state.x.clone();
            let step = StepEquation::natural(&x0, self.state.lambda, d);
            let predicted = x.clone();
            let trial = self.correct(x, self.state.lambda + d, &step, &settings);
            trial.map(|t| self.with_correction(t, &x0, &predicted))
        }
    }

    /// `trial` with its [`Trial::correction`]: the corrector's move from `predicted` over
    /// the predictor's length from `x0`, both over the primal unknowns.
    fn with_correction(&self, trial: Trial, x0: &[f64], predicted: &[f64]) -> Trial {
        let np = self.problem.primal_unknowns();
        let distance = |a: &[f64], b: &[f64]| {
            a[..np]
                .iter()
                .zip(&b[..np])
                .map(|(u, v)| (u - v) * (u - v))
                .sum::<f64>()
                .sqrt()
        };
        let predictor = distance(predicted, x0);
        let correction = if predictor > 0.0 {
            distance(&trial.x, predicted) / predictor
        } else {
            0.0
        };
        Trial {
            correction,
            ..trial
        }
    }
}
