//! Critical points of a path (docs/theory.md §5): located where the count of unstable directions
//! changes across an accepted step — bracketed by the counts, then placed by a secant on the
//! eigenvalue nearest zero —, and classified as folds or bifurcations (they are left along
//! their mode by branch switching, [`super::switching`]).

use super::continuation::{Continuation, Critical, MAX_CRITICAL_POINTS};
use super::newton::{NewtonSettings, StepEquation};
use super::problem::Problem;
use crate::results::{CriticalKind, Stability};

/// The first span of the secant that refines a located point, as a fraction of the step.
const SECANT_SPAN: f64 = 0.02;

/// Critical points of one step closer than this fraction of the step are one point of the
/// count's whole jump (a double point).
const MERGE_SPAN: f64 = 1e-3;

/// The segment of an accepted step from `(x0, λ0)` to `(x1, λ1)` on which the critical point
/// lies, and the step equation that puts a probe at a fraction `f` of it.
struct Segment<'a> {
    x0: &'a [f64],
    l0: f64,
    /// `x1 − x0` (all unknowns) and `λ1 − λ0`.
    dx: Vec<f64>,
    dl: f64,
    /// Length of the step over the primal unknowns and `λ`.
    norm: f64,
    /// The step's tangent over the primal unknowns, for an arclength step.
    tx: Option<Vec<f64>>,
    tl: f64,
}

impl<'a> Segment<'a> {
    fn new(x0: &'a [f64], l0: f64, x1: &[f64], l1: f64, np: usize, arclength: bool) -> Self {
        let dx: Vec<f64> = x1.iter().zip(x0).map(|(a, b)| a - b).collect();
        let dl = l1 - l0;
        let norm = ((0..np).map(|i| dx[i] * dx[i]).sum::<f64>() + dl.powi(2)).sqrt();
        let (tx, tl) = if arclength {
            (Some((0..np).map(|i| dx[i] / norm).collect()), dl / norm)
        } else {
            (None, 1.0)
        };
        Segment {
            x0,
            l0,
            dx,
            dl,
            norm,
            tx,
            tl,
        }
    }

    /// The predictor at fraction `f` of the step.
    fn at(&self, f: f64) -> (Vec<f64>, f64) {
        let x = self
            .x0
            .iter()
            .zip(&self.dx)
            .map(|(a, b)| a + f * b)
            .collect();
        (x, self.l0 + f * self.dl)
    }

    /// The step equation of a probe at fraction `f`, predictor at `lambda`.
    fn equation(&self, f: f64, lambda: f64) -> StepEquation<'_> {
        StepEquation {
            tx: self.tx.as_deref(),
            tl: self.tl,
            x0: self.x0,
            l0: self.l0,
            ds: if self.tx.is_some() {
                f * self.norm
            } else {
                lambda - self.l0
            },
        }
    }
}

/// A solved probe of the segment.
struct Probe {
    x: Vec<f64>,
    lambda: f64,
}

/// Above this cosine of the mode and the load derivative (see
/// `Continuation::load_along_mode`) a critical point is a fold, below it a bifurcation
/// (measured: 0.99 at the folds of tests/unit/continuation.rs, 1e-17 to 2e-12 at the thesis
/// n = 2, Olson and sliding-tip bifurcations).
const FOLD_COSINE: f64 = 1e-6;

impl<P: Problem> Continuation<P> {
    /// The equilibrium at fraction `f` of the segment, solved from a fresh factorisation.
    fn probe(&mut self, segment: &Segment, f: f64, settings: &NewtonSettings) -> Option<Probe> {
        let (xp, lp) = segment.at(f);
        self.newton.discard_factorisation();
        let step = segment.equation(f, lp);
        let t = self.correct(xp, lp, &step, settings).ok()?;
        Some(Probe {
            x: t.x,
            lambda: t.lambda,
        })
    }

    /// Locates the critical point crossed by the accepted step from `(x0, λ0)` to the
    /// current state: bisection on the change of the unstable count, then a secant on the
    /// eigenvalue nearest zero; records it with its kind and mode, and returns to the
    /// accepted state.
    pub(super) fn locate_critical(
        &mut self,
        x0: &[f64],
        l0: f64,
        arclength: bool,
        before: Stability,
        after: Stability,
    ) {
        let saved = self.state.clone();
        let np = self.problem.primal_unknowns();
        let segment = Segment::new(x0, l0, &saved.x, saved.lambda, np, arclength);
        // exact (LU) solves: the regularised LDLᵀ's refinement converges slowly near the
        // singular Jacobian, and the state it leaves breaks the symmetry of a bifurcation
        // by more than the mode's test of the load's work on it can tell from a fold
        self.newton.set_exact(true);
        // near the critical point the Jacobian is nearly singular: linear solves there have
        // relative residuals up to cond·ε, so the probes accept them (Newton's own residual
        // test still decides convergence)
        let probe_settings = NewtonSettings {
            singular_threshold: self.settings.newton.singular_threshold.max(1e-2),
            ..self.settings.newton
        };
        let block = self.problem.focus_on_crossing(x0, &saved.x);
        let bracket = self.bracket_by_count(&segment, &probe_settings, before.unstable_directions);
        // two points crossed by one step: the count just above the first is not the
        // count at the step's end, and the rest of the step holds the others — unless the
        // end's count is reached within a thousandth of the step (a double point that the
        // discretisation splits by a hair, or counts unsettled beside it): one point
        let rest = bracket
            .above
            .clone()
            .filter(|_| self.problem.counts_points())
            .filter(|&(_, _, count, _)| count != after.unstable_directions)
            .filter(|&(_, _, _, f)| {
                let beyond = (f + MERGE_SPAN).min(1.0);
                beyond < 1.0
                    && self
                        .probe(&segment, beyond, &probe_settings)
                        .and_then(|p| self.problem.unstable_directions(&p.x, p.lambda).ok())
                        .is_some_and(|c| c != after.unstable_directions)
            });
        let count_after = rest
            .as_ref()
            .map_or(after.unstable_directions, |&(_, _, count, _)| count);
        let mut best = bracket.best;
        if let Some(below) = bracket.below {
            if let Some(refined) = self.refine_by_secant(&segment, &probe_settings, below) {
                best = refined;
            }
        }
        let (xc, lc) = best;
        self.state.x = xc.clone();
        self.state.lambda = lc;
        self.problem.restore(&xc, lc);
        let mode = self.critical_mode(&xc, lc);
        // a crossing in a block other than the first (a symmetric pair's wavenumber p ≠ 0)
        // breaks the symmetry that the load keeps: a bifurcation, the pair's Jacobian not
        // singular there
        let kind = if block != 0 {
            CriticalKind::Bifurcation
        } else {
            match mode.as_deref().and_then(|m| self.load_along_mode(m)) {
                Some(cosine) if cosine > FOLD_COSINE => CriticalKind::LimitPoint,
                Some(_) => CriticalKind::Bifurcation,
                None => self.classify(x0, l0, saved.tangent.clone(), &probe_settings),
            }
        };
        // a point is a fold only if the path turns in its parameter there: a step that
        // passes it monotonically (a natural step, or an arclength one with the point
        // strictly between its ends) crossed a bifurcation, whatever the mode's test of the
        // load's work said (on a coarse mesh it may read a symmetric pitchfork as a fold)
        let monotone = !arclength || (lc - l0) * (saved.lambda - lc) > 0.0;
        let kind = match kind {
            CriticalKind::LimitPoint if monotone => CriticalKind::Bifurcation,
            kind => kind,
        };
        self.problem.clear_focus();
        if let Some(mode) = mode {
            self.critical.push(Critical {
                kind,
                block,
                parameter: lc,
                unstable_before: before.unstable_directions,
                unstable_after: count_after,
                state: xc,
                mode,
            });
        }
        // back to the accepted state
        self.state = saved;
        self.state.tangent = None;
        self.problem.restore(&self.state.x, self.state.lambda);
        self.newton.discard_factorisation();
        self.newton.set_exact(false);
        if let Some((x_above, l_above, count, _)) = rest {
            if self.critical.len() < MAX_CRITICAL_POINTS {
                let between = Stability {
                    unstable_directions: count,
                    ..before
                };
                self.locate_critical(&x_above, l_above, arclength, between, after);
            }
        }
    }

    /// Bisection of the segment on the unstable count: the fraction below the change (with
    /// its state) and the best state above it.
    fn bracket_by_count(
        &mut self,
        segment: &Segment,
        settings: &NewtonSettings,
        count_before: usize,
    ) -> Bracket {
        let (mut lo, mut hi) = (0.0, 1.0); // fractions of the step
        let mut bracket = Bracket {
            best: (self.state.x.clone(), self.state.lambda),
            below: None,
            above: None,
        };
        let mut offset = 0.5;
        while hi - lo > self.settings.critical_tolerance.max(1e-14) {
            let mid = lo + offset * (hi - lo);
            let Some(p) = self.probe(segment, mid, settings) else {
                // a probe exactly on the critical point may not converge: probe beside it
                if offset == 0.5 {
                    offset = 0.37;
                    continue;
                }
                break;
            };
            offset = 0.5;
            match self.problem.unstable_directions(&p.x, p.lambda) {
                Ok(c) if c == count_before => {
                    lo = mid;
                    bracket.below = Some((p.x, p.lambda, mid));
                }
                Ok(c) => {
                    hi = mid;
                    bracket.above = Some((p.x.clone(), p.lambda, c, mid));
                    bracket.best = (p.x, p.lambda);
                }
                Err(_) => {
                    // a zero pivot: we are on the critical point
                    bracket.best = (p.x, p.lambda);
                    break;
                }
            }
        }
        bracket
    }

    /// The counts resolve the crossing only to the rounding of the LDLᵀ near a zero
    /// eigenvalue; a secant on the eigenvalue nearest zero (a Rayleigh quotient, accurate to
    /// the square of its vector's error), which crosses zero there, finishes the location.
    fn refine_by_secant(
        &mut self,
        segment: &Segment,
        settings: &NewtonSettings,
        below: (Vec<f64>, f64, f64),
    ) -> Option<(Vec<f64>, f64)> {
        let (xl, ll, fl) = below;
        let probe = |this: &mut Self, f: f64| -> Option<(f64, Probe)> {
            let p = this.probe(segment, f, settings)?;
            let mu = this.problem.eigenvalue_nearest_zero(&p.x, p.lambda)?;
            Some((mu, p))
        };
        let mu_l = self.problem.eigenvalue_nearest_zero(&xl, ll);
        let fb = (fl - SECANT_SPAN).max(0.0);
        let (Some(mu_a), Some((mu_b, _))) = (mu_l, probe(self, fb)) else {
            return None;
        };
        // the probe whose eigenvalue is nearest zero, if nearer than the bracket's; a secant
        // thrown beyond twice its first span from the bracket (where the eigenvalue found is
        // another one than the crossing's) ends the refinement
        let mut best = None;
        let mut nearest = mu_a.abs();
        let (mut fa, mut ma, mut fb, mut mb) = (fl, mu_a, fb, mu_b);
        for _ in 0..6 {
            if (ma - mb).abs() <= f64::EPSILON * ma.abs() || fa == fb {
                break;
            }
            let f = (fa - ma * (fa - fb) / (ma - mb)).clamp(0.0, 1.0);
            if (f - fl).abs() > 2.0 * SECANT_SPAN {
                break;
            }
            let Some((mu, p)) = probe(self, f) else {
                break;
            };
            if mu.abs() <= nearest {
                nearest = mu.abs();
                best = Some((p.x, p.lambda));
            }
            let converged = (f - fa).abs() <= 1e-13;
            (fb, mb, fa, ma) = (fa, ma, f, mu);
            if converged {
                break;
            }
        }
        best
    }

    /// The critical mode at `(x, λ)`: inverse iteration on the Jacobian there.
    fn critical_mode(&mut self, x: &[f64], lambda: f64) -> Option<Vec<f64>> {
        self.newton.null_vector(&mut self.problem, x, lambda)
    }

    /// `|φ·∂R/∂λ| / (|φ| |∂R/∂λ|)` at the critical state (the current one) for its null
    /// vector `φ`, both made pure numbers by the residual's weights `w` (`w ∂R/∂λ`, `φ/w`:
    /// their dot product is unchanged): zero at a bifurcation, where the load does not work
    /// on the mode (the Fredholm condition that lets the path go through), order one at a
    /// fold. `None` where it cannot be formed.
    fn load_along_mode(&mut self, mode: &[f64]) -> Option<f64> {
        let n = self.problem.unknowns();
        if mode.len() != n {
            return None;
        }
        let mut weights = vec![1.0; n];
        self.problem.residual_weights(&mut weights);
        let mut load = vec![0.0; n];
        let (x, lambda) = (self.state.x.clone(), self.state.lambda);
        self.problem.load_derivative(&x, lambda, &mut load);
        let (mut dot, mut nm, mut nl) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let (m, l) = (mode[i] / weights[i], load[i] * weights[i]);
            dot += m * l;
            nm += m * m;
            nl += l * l;
        }
        let cosine = dot.abs() / (nm.sqrt() * nl.sqrt());
        cosine.is_finite().then_some(cosine)
    }

    /// A fold makes `dx/dλ` blow up, a bifurcation leaves it bounded: the tangent at the
    /// critical state (the current one) against that at the start of the step (`tangent0`,
    /// or computed at `(x0, λ0)`).
    fn classify(
        &mut self,
        x0: &[f64],
        l0: f64,
        tangent0: Option<Vec<f64>>,
        settings: &NewtonSettings,
    ) -> CriticalKind {
        let np = self.problem.primal_unknowns();
        let (xc, lc) = (self.state.x.clone(), self.state.lambda);
        let t_near = self.compute_tangent(settings.singular_threshold);
        let t_start = tangent0.or_else(|| {
            self.state.x = x0.to_vec();
            self.state.lambda = l0;
            self.problem.restore(x0, l0);
            self.compute_tangent(settings.singular_threshold)
        });
        self.state.x = xc;
        self.state.lambda = lc;
        self.problem.restore(&self.state.x, lc);
        match (&t_near, &t_start) {
            (Some(a), Some(b)) => {
                let na = (0..np).map(|i| a[i] * a[i]).sum::<f64>().sqrt();
                let nb = (0..np).map(|i| b[i] * b[i]).sum::<f64>().sqrt();
                if na > 1e3 * nb.max(1e-300) {
                    CriticalKind::LimitPoint
                } else {
                    CriticalKind::Bifurcation
                }
            }
            (None, _) => CriticalKind::LimitPoint,
            _ => CriticalKind::Bifurcation,
        }
    }
}

/// What the bisection found: the best state at or above the change of count, and the last
/// state below it (with its fraction of the step).
struct Bracket {
    best: (Vec<f64>, f64),
    below: Option<(Vec<f64>, f64, f64)>,
    /// The last state above the change, with its count and its fraction of the step, when
    /// a probe found one.
    above: Option<(Vec<f64>, f64, usize, f64)>,
}
