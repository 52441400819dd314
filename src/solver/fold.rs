//! A path that may not turn back in its parameter (a prescribed motion, which a limit point
//! would carry back past where it started) ends at the first limit point it meets.

use super::continuation::{Before, Continuation, StopReason};
use super::problem::Problem;
use crate::results::{CriticalKind, Stability};

impl<P: Problem> Continuation<P> {
    /// After an accepted step from `before` heading towards `dir · λ` increasing: when the
    /// path stops at folds and the step passed one — a limit point located in the step
    /// beyond its end, or an end behind its start — the path is put back on the fold (or,
    /// where none was located, on the step's start) and the reason to stop is returned.
    pub(super) fn stop_at_fold(&mut self, before: Before, dir: f64) -> Option<StopReason> {
        if !self.stop_at_folds || !self.state.arclength {
            return None;
        }
        let turned_back = (self.state.lambda - before.lambda) * dir < 0.0;
        let fold = self.critical[before.located..]
            .iter()
            .rposition(|c| c.kind == CriticalKind::LimitPoint)
            .map(|i| before.located + i);
        let ahead = |lambda: f64| (lambda - self.state.lambda) * dir > 0.0;
        match fold {
            Some(i) if turned_back || ahead(self.critical[i].parameter) => {
                let (x, lambda) = (self.critical[i].state.clone(), self.critical[i].parameter);
                let past = before.stability;
                self.end_at(x, lambda, past);
                Some(StopReason::Fold { parameter: lambda })
            }
            _ if turned_back => {
                self.end_at(before.x, before.lambda, before.stability);
                Some(StopReason::Fold {
                    parameter: before.lambda,
                })
            }
            _ => None,
        }
    }

    /// Makes `(x, λ)` the path's converged state, with its own energy and residual, its
    /// stability counted there (or, where the count fails on the critical point itself,
    /// `fallback`).
    fn end_at(&mut self, x: Vec<f64>, lambda: f64, fallback: Option<Stability>) {
        let mut residual = vec![0.0; x.len()];
        let energy = self.problem.residual(&x, lambda, &mut residual);
        self.state.solve.energy = energy;
        self.state.solve.residual = residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        self.state.x = x;
        self.state.lambda = lambda;
        self.state.previous = None;
        self.state.tangent = None;
        self.problem.restore(&self.state.x, lambda);
        self.newton.discard_factorisation();
        self.update_stability(true);
        if self.state.stability.is_none() {
            self.state.stability = fallback;
        }
    }
}
