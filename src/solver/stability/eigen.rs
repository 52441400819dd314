//! The eigenvalues of the constrained pencil `(H, M)` on the factorisations of an
//! [`InertiaCounter`]: inverse iteration with the Lagrangian Rayleigh quotient, the search of
//! the lowest eigenvalue by shifts that inertia counts keep below the spectrum, the
//! eigenvalue nearest zero (with deflation, for the second mode of a double critical point),
//! and the warm starts that carry a search along a path.

use super::inertia::InertiaCounter;
use crate::solver::ldl::Scalar;

impl<T: Scalar> InertiaCounter<T> {
    /// Lowest eigenvalue of the constrained pencil `(H, M)` (`M = diag(metric)` on the
    /// primal unknowns), by shift-and-invert iteration whose shifts are kept below the
    /// spectrum by inertia counts. `kkt` are the KKT values at the state.
    ///
    /// Along a path the last lowest eigenvalues are extrapolated: when the count confirms a
    /// shift just below the extrapolation to be below the spectrum, iteration from it
    /// converges in two or three solves and the eigenvalue found within `CERTIFIED` above
    /// the shift is the lowest (one factorisation in all). Otherwise, from a shift `lo`
    /// below the spectrum (just below the last lowest eigenvalue when the count confirms
    /// it, otherwise 0, −1, −4, …) a few iterations give a Rayleigh quotient
    /// `μ ≥ λ1`. If the count puts no eigenvalue below `σ = μ − 10⁻⁴|μ|`, the shift `σ`
    /// lies within 10⁻⁴ of `λ1` and iteration from it converges in a few steps; otherwise an
    /// eigenvalue below `σ` was missed (clustered eigenvalues, or a warm start without a
    /// component along the lowest mode), and the bracket `[lo, σ]` is bisected by counts to
    /// a new `lo` before iterating again. Clustered spectra thus cost a few factorisations
    /// instead of hundreds of slowly converging iterations. Shifts keep at least a few times
    /// the count's rounding band below the eigenvalue they certify, and a bracket narrower
    /// than that ends the bisection: counts within it scatter (an eigenvalue near zero of a
    /// stiff spectrum), and the eigenvalue nearest its lower end is the lowest.
    ///
    /// A rough estimate of the same values (by [`InertiaCounter::rough_lowest`]) saves the
    /// search its first steps.
    pub fn lowest_eigenvalue(
        &mut self,
        kkt: &[T],
        metric: &[f64],
        rough: Option<RoughLowest>,
    ) -> Option<f64> {
        // along a path: one factorisation at a shift just below the extrapolated lowest
        // eigenvalue, which the count confirms to be below the spectrum
        let mut start = None;
        let floor = self.count_resolution(kkt, metric);
        if let Some(sigma) = self.predicted_shift(floor) {
            if self.count(kkt, sigma, metric)? == 0 {
                let mu = self.inverse_iteration(kkt, metric, LOWEST)?;
                if self.converged && mu - sigma <= (CERTIFIED * mu.abs()).max(2.0 * floor) {
                    self.record_lowest(mu);
                    return Some(mu);
                }
                start = Some((sigma, mu));
            }
        }
        let rough = rough.map(|r| (r.shift, r.estimate));
        let (mut lo, mut mu) = match start.or(rough) {
            Some(s) => s,
            None => {
                let lo = self.shift_below_spectrum(kkt, metric)?;
                (lo, self.inverse_iteration(kkt, metric, ROUGH)?)
            }
        };
        let mut hi = f64::INFINITY;
        // relative distance below `mu` of the next shift: closer once `mu` is accurate
        let mut gap = 1e-4;
        for _ in 0..64 {
            let sigma = mu - (gap * mu.abs()).max(floor);
            if sigma > lo && sigma < hi {
                let below = self.count(kkt, sigma, metric)?;
                if below == 0 {
                    lo = sigma;
                    let l = self.inverse_iteration(kkt, metric, LOWEST);
                    let lowest = l.map_or(mu, |l| l.min(mu));
                    if self.converged || gap <= 1e-8 {
                        self.record_lowest(lowest);
                        return Some(lowest);
                    }
                    // still converging (the next eigenvalue is within the gap): shift closer
                    mu = lowest;
                    gap *= 1e-2;
                    continue;
                }
                hi = sigma;
            } else if sigma <= lo {
                // the bracket is already tighter than the gap: iterate from `lo`
                self.inertia(kkt, lo, metric).ok()?;
                let lowest = self
                    .inverse_iteration(kkt, metric, LOWEST)
                    .map_or(mu, |l| l.min(mu));
                self.record_lowest(lowest);
                return Some(lowest);
            }
            // an eigenvalue below `hi` that the iteration has not reached: bisect the
            // bracket by counts to a shift below the spectrum that is closer to it
            let mut factorised_at_lo = false;
            let mut collapsed = false;
            loop {
                let mid = 0.5 * (lo + hi);
                // counts closer than their resolution tell nothing
                if hi - lo <= floor {
                    collapsed = true;
                    break;
                }
                if self.count(kkt, mid, metric)? == 0 {
                    lo = mid;
                    factorised_at_lo = true;
                    break;
                }
                hi = mid;
            }
            if !factorised_at_lo {
                self.inertia(kkt, lo, metric).ok()?;
            }
            self.perturb_iterate(metric);
            if collapsed {
                // the bracket is within the count's resolution: the eigenvalue nearest
                // `lo` is the lowest
                let lowest = self
                    .inverse_iteration(kkt, metric, LOWEST)
                    .map_or(mu, |l| l.min(mu));
                self.record_lowest(lowest);
                return Some(lowest);
            }
            mu = self.inverse_iteration(kkt, metric, ROUGH)?.min(mu);
        }
        self.record_lowest(mu);
        Some(mu)
    }

    /// A rough upper estimate of the lowest eigenvalue without a search: a few inverse
    /// iterations from a shift below the spectrum (0 when nothing is below it). It tells
    /// which of several matrices is likely to hold the lowest eigenvalue, and a search of
    /// the lowest eigenvalue of the same values goes on from it (and from the iterate, kept
    /// as the warm start).
    pub fn rough_lowest(&mut self, kkt: &[T], metric: &[f64]) -> Option<RoughLowest> {
        let shift = self.shift_below_spectrum(kkt, metric)?;
        let estimate = self.inverse_iteration(kkt, metric, ROUGH)?;
        Some(RoughLowest { estimate, shift })
    }

    /// A shift just below the lowest eigenvalue that the last ones extrapolate to
    /// (quadratically from three), by twice the extrapolation's error estimate (the third
    /// difference of the last four, or the difference of the quadratic and the linear
    /// extrapolation) and `CERTIFIED / 4` of the eigenvalue; `None` before two are known.
    fn predicted_shift(&self, floor: f64) -> Option<f64> {
        let (predicted, margin) = extrapolate(&self.lowest_history)?;
        Some(predicted - margin.max(floor))
    }

    /// The distance (J/m) below an eigenvalue at which a count is certain not to count it:
    /// `COUNT_MARGIN` times the rounding band `τ = 1e-9 ρ/m̄` of the pivots (`ρ` the mean
    /// diagonal of the Hessian, `m̄` the mean metric weight; counts within about `1.4 τ` of an
    /// eigenvalue of the n = 8 cell scatter between 0 and 1).
    fn count_resolution(&self, kkt: &[T], metric: &[f64]) -> f64 {
        let (sum, weights) = metric
            .iter()
            .filter(|&&m| m > 0.0)
            .fold((0.0, 0usize), |(s, c), &m| (s + m, c + 1));
        let mean_metric = if weights > 0 {
            sum / weights as f64
        } else {
            1.0
        };
        COUNT_MARGIN * 1e-9 * self.hessian_scale(kkt) / mean_metric
    }

    /// Exchanges the warm start (last mode, lowest eigenvalues, mode nearest zero) with
    /// `warm`.
    pub(super) fn swap_warm_start(&mut self, warm: &mut WarmStart<T>) {
        std::mem::swap(&mut self.last_mode, &mut warm.mode);
        std::mem::swap(&mut self.lowest_history, &mut warm.lowest);
        std::mem::swap(&mut self.nearest_zero_mode, &mut warm.nearest_zero);
    }

    /// Appends `lowest` to the history that places the next shift.
    fn record_lowest(&mut self, lowest: f64) {
        if self.lowest_history.len() == 4 {
            self.lowest_history.remove(0);
        }
        self.lowest_history.push(lowest);
    }

    /// Eigenvalues of the constrained pencil below `sigma` (factorises at `sigma`).
    fn count(&mut self, kkt: &[T], sigma: f64, metric: &[f64]) -> Option<isize> {
        let inertia = self.inertia(kkt, sigma, metric).ok()?;
        Some(self.unstable_directions(inertia).max(0))
    }

    /// A shift below the spectrum, factorised: just below the last lowest eigenvalue when
    /// the inertia count confirms it (along a path it moves little), otherwise 0 if
    /// nothing is below 0, else −1, −4, −16, …
    fn shift_below_spectrum(&mut self, kkt: &[T], metric: &[f64]) -> Option<f64> {
        if let Some(&last) = self.lowest_history.last() {
            let sigma = last - 0.1 * last.abs().max(1e-12);
            if self.count(kkt, sigma, metric) == Some(0) {
                return Some(sigma);
            }
        }
        let mut sigma = 0.0;
        let mut guess = 1.0;
        while self.count(kkt, sigma, metric)? > 0 {
            if guess > 1e30 {
                return None;
            }
            sigma = -guess;
            guess *= 4.0;
        }
        Some(sigma)
    }

    /// Mixes a little of the cold start vector into the warm start, so that a start
    /// without a component along the lowest mode (exact in symmetric problems) gains one.
    fn perturb_iterate(&mut self, metric: &[f64]) {
        let n = self.iterate.len();
        if self.last_mode.len() != n {
            return;
        }
        let norm = (0..n)
            .map(|i| metric[i] * self.last_mode[i].abs2())
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        let cold = cold_start(metric);
        let cold_norm = (0..n)
            .map(|i| metric[i] * cold[i].powi(2))
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        for i in 0..n {
            self.last_mode[i] =
                self.last_mode[i].div_real(norm) + T::from_real(1e-2 * cold[i] / cold_norm);
        }
    }

    /// The eigenvalue of the constrained pencil nearest zero (the one that crosses zero at
    /// a critical point).
    pub fn eigenvalue_nearest_zero(&mut self, kkt: &[T], metric: &[f64]) -> Option<f64> {
        self.inertia(kkt, 0.0, metric).ok()?;
        // the search keeps a warm start of its own: the mode nearest zero, not the lowest
        std::mem::swap(&mut self.last_mode, &mut self.nearest_zero_mode);
        let nearest = self.inverse_iteration(kkt, metric, NEAREST_ZERO);
        std::mem::swap(&mut self.last_mode, &mut self.nearest_zero_mode);
        nearest
    }

    /// The eigenvalue nearest zero among the modes orthogonal (in the metric) to `first`,
    /// with its mode: the second mode of a double critical point (two eigenvalues crossing
    /// zero together, as a symmetric assembly's sway does on the full model).
    pub fn nearest_zero_orthogonal_to(
        &mut self,
        kkt: &[T],
        metric: &[f64],
        first: &[T],
    ) -> Option<(f64, Vec<T>)> {
        let n_primal = self.iterate.len();
        let first = first.get(..n_primal)?;
        let plain = (0..n_primal)
            .map(|i| weighted_abs2(metric[i], first[i]))
            .sum::<f64>();
        let norm = self.held_norm2(plain, first).sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        self.inertia(kkt, 0.0, metric).ok()?;
        self.deflation = first.iter().map(|&v| v.div_real(norm)).collect();
        // from the cold start: the warm starts are the first mode's
        let warm = std::mem::take(&mut self.last_mode);
        let nearest = self.inverse_iteration(kkt, metric, NEAREST_ZERO);
        let mode = std::mem::replace(&mut self.last_mode, warm);
        self.deflation.clear();
        nearest.map(|mu| (mu, mode))
    }

    /// Inverse iteration with the last factorisation (of `K − σM`): converges to the
    /// eigenvalue nearest `σ`; returns its Rayleigh quotient with the unshifted Hessian.
    fn inverse_iteration(&mut self, kkt: &[T], metric: &[f64], accuracy: Accuracy) -> Option<f64> {
        let n_primal = self.iterate.len();
        // start from the last mode: along a path it changes little
        let mut u = std::mem::take(&mut self.iterate);
        if self.last_mode.len() == n_primal {
            u.copy_from_slice(&self.last_mode);
        } else {
            for (ui, c) in u.iter_mut().zip(cold_start(metric)) {
                *ui = T::from_real(c);
            }
        }
        let mut estimate = f64::NAN;
        self.converged = false;
        // the Hessian block of K for Rayleigh quotients
        let mut hv = std::mem::take(&mut self.product);
        let mut found = true;
        for _ in 0..accuracy.iterations {
            let Some(rq) = self.iteration_step(kkt, metric, &mut u, &mut hv, accuracy.refinements)
            else {
                found = false;
                break;
            };
            let done = (rq - estimate).abs() <= accuracy.tolerance * rq.abs().max(1e-12);
            estimate = rq;
            if done {
                self.converged = true;
                break;
            }
        }
        // converged on the regularised solves: one step refined against the unregularised
        // matrix puts the iterate on the constraints, and its quotient on the eigenvalue
        if found && self.converged && accuracy.final_refinements > 0 {
            match self.iteration_step(kkt, metric, &mut u, &mut hv, accuracy.final_refinements) {
                Some(rq) => estimate = rq,
                None => found = false,
            }
        }
        if found {
            self.last_mode.clone_from(&u);
        } else {
            self.last_mode.clear();
        }
        self.iterate = u;
        self.product = hv;
        (found && estimate.is_finite()).then_some(estimate)
    }

    /// One step of inverse iteration from the iterate `u` (unit norm in the metric, replaced
    /// by the next): the solve with the last factorisation, refined `refinements` times,
    /// and the Lagrangian Rayleigh quotient of the next iterate (`None` for a solve without
    /// a finite non-zero norm); `hv` receives `H u`.
    fn iteration_step(
        &mut self,
        kkt: &[T],
        metric: &[f64],
        u: &mut [T],
        hv: &mut [T],
        refinements: usize,
    ) -> Option<f64> {
        let n_primal = u.len();
        let zero = T::from_real(0.0);
        let mut rhs = std::mem::take(&mut self.rhs);
        rhs.iter_mut().for_each(|b| *b = zero);
        self.metric_times(metric, u, &mut rhs[..n_primal]);
        self.rhs = rhs;
        self.solve_refined(n_primal, refinements);
        self.deflate(metric, n_primal);
        let v = &self.solution;
        let plain = (0..n_primal)
            .map(|i| weighted_abs2(metric[i], v[i]))
            .sum::<f64>();
        let norm = self.held_norm2(plain, &v[..n_primal]).sqrt();
        if norm.is_nan() || norm <= 0.0 || !norm.is_finite() {
            return None;
        }
        for i in 0..n_primal {
            u[i] = v[i].div_real(norm);
        }
        Some(lagrangian_rayleigh_quotient(
            &self.structure.k_entry,
            kkt,
            u,
            v,
            norm,
            hv,
        ))
    }

    /// Removes from the primal part of the last solution its component (in the metric)
    /// along the deflated mode, if there is one.
    fn deflate(&mut self, metric: &[f64], n_primal: usize) {
        if !self.deflation.is_empty() {
            let zero = T::from_real(0.0);
            let f = &self.deflation;
            let mut c = zero;
            for i in 0..n_primal {
                c += T::from_real(metric[i]) * self.solution[i] * f[i].conjugate();
            }
            let c = self.held_inner(c, f, &self.solution[..n_primal]);
            for i in 0..n_primal {
                self.solution[i] -= c * f[i];
            }
        }
    }
}

/// Rayleigh quotient of the Lagrangian, `(uᴴ H u + 2 Re yᴴ J u) / uᴴ M u` with `H` the
/// primal block of the KKT values `kkt` (entries at `k_entry`), `u` the iterate (primal
/// unknowns, unit norm in the metric) and `y` the multipliers of the solve `v` (all
/// unknowns) scaled with `u` (by `1/norm`); `hv` receives `H u`.
///
/// It is stationary at a constrained eigenpair for every variation of `u`, so the solve's
/// small constraint residual (the regularisation's δ) enters it only to second order.
/// Refined solves need it too: near a critical point the refinement converges slowly (the
/// regularisation's shift of the eigenvalue is comparable to the eigenvalue itself), and
/// with the plain quotient the eigenvalue nearest zero scattered by 3e-5 J/m, placing the
/// n = 8 sliding tips' double point 1.6e-6 apart on the pair and on the full model (with
/// it: 1e-11).
fn lagrangian_rayleigh_quotient<T: Scalar>(
    k_entry: &[(usize, usize)],
    kkt: &[T],
    u: &[T],
    v: &[T],
    norm: f64,
    hv: &mut [T],
) -> f64 {
    let n_primal = u.len();
    let zero = T::from_real(0.0);
    hv.iter_mut().for_each(|h| *h = zero);
    let mut lagrange = 0.0;
    for (p, &(row, col)) in k_entry.iter().enumerate() {
        if col < n_primal {
            if row < n_primal {
                hv[row] += kkt[p] * u[col];
            } else {
                lagrange += (v[row].div_real(norm).conjugate() * kkt[p] * u[col]).real_part();
            }
        }
    }
    (0..n_primal)
        .map(|i| (u[i].conjugate() * hv[i]).real_part())
        .sum::<f64>()
        + 2.0 * lagrange
}

/// `m |v|²`, multiplied as `(m v) v̄` (for real entries, the order the real searches have
/// always used, so that their results stay as they were to the last bit).
fn weighted_abs2<T: Scalar>(m: f64, v: T) -> f64 {
    (T::from_real(m) * v * v.conjugate()).real_part()
}

/// The next lowest eigenvalue that the last ones `h` (oldest first) extrapolate to
/// (quadratically from three), and a margin for it: twice the extrapolation's error
/// estimate (the third difference of the last four, or the difference of the quadratic and
/// the linear extrapolation) and `CERTIFIED / 4` of the eigenvalue; `None` before two are
/// known.
fn extrapolate(h: &[f64]) -> Option<(f64, f64)> {
    let (predicted, error) = match h.len() {
        0 | 1 => return None,
        2 => (2.0 * h[1] - h[0], (h[1] - h[0]).abs()),
        k => {
            let [a, b, c] = [h[k - 3], h[k - 2], h[k - 1]];
            let quadratic = 3.0 * c - 3.0 * b + a;
            let error = if k >= 4 {
                (c - 3.0 * b + 3.0 * a - h[k - 4]).abs()
            } else {
                (quadratic - (2.0 * c - b)).abs()
            };
            (quadratic, error)
        }
    };
    let margin = 2.0 * error + 0.25 * CERTIFIED * predicted.abs().max(1e-12);
    (predicted.is_finite() && margin.is_finite()).then_some((predicted, margin))
}

/// The start vector of inverse iteration without a warm start: the metric, varied so as
/// not to be orthogonal to a symmetric mode.
fn cold_start(metric: &[f64]) -> Vec<f64> {
    metric
        .iter()
        .enumerate()
        .map(|(i, m)| m * (1.0 + (i % 7) as f64 * 0.1))
        .collect()
}

/// A rough estimate of the lowest eigenvalue of one matrix ([`InertiaCounter::rough_lowest`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughLowest {
    /// A Rayleigh quotient: an upper estimate of the lowest eigenvalue (J/m).
    pub estimate: f64,
    /// A shift below the spectrum, confirmed by a count.
    shift: f64,
}

/// Where inverse iteration starts: the last mode found and the last lowest eigenvalue.
#[derive(Clone, Debug)]
pub struct WarmStart<T: Scalar = f64> {
    mode: Vec<T>,
    lowest: Vec<f64>,
    nearest_zero: Vec<T>,
}

impl<T: Scalar> Default for WarmStart<T> {
    fn default() -> Self {
        WarmStart {
            mode: Vec::new(),
            lowest: Vec::new(),
            nearest_zero: Vec::new(),
        }
    }
}

impl<T: Scalar> WarmStart<T> {
    /// Whether a lowest eigenvalue has been found with it before.
    pub fn has_history(&self) -> bool {
        !self.lowest.is_empty()
    }

    /// An upper estimate of the next lowest eigenvalue: the extrapolation of the last
    /// ones plus its margin; `None` before two are known.
    pub fn upper_estimate(&self) -> Option<f64> {
        let (predicted, margin) = extrapolate(&self.lowest)?;
        Some(predicted + margin)
    }
}

/// How far inverse iteration goes: the relative change of the Rayleigh quotient at which
/// it stops, and the steps of iterative refinement of each regularised solve against the
/// unregularised matrix (each divides the constraint residual by about `δ/ρ`; the
/// Lagrangian Rayleigh quotient is insensitive to it to first order, so the eigenvalue
/// searches iterate without, the modes of critical points keep two), and those of one last
/// step once converged (the lowest eigenvalue: from 2e-8 to 1e-9 of a dense constrained
/// solve on the n = 8 cell's blocks).
#[derive(Clone, Copy, Debug)]
struct Accuracy {
    tolerance: f64,
    refinements: usize,
    /// Refinements of one last step once converged (0: none).
    final_refinements: usize,
    /// At most this many iterations.
    iterations: usize,
}

/// A lowest eigenvalue found from a shift `σ` confirmed below the spectrum is accepted
/// without a further count when it lies within this relative distance above `σ` (no
/// eigenvalue is below it by more).
const CERTIFIED: f64 = 2e-3;

/// Multiple of the count's rounding band `τ` that a shift keeps below an eigenvalue to be
/// counted below it with certainty (see `InertiaCounter::count_resolution`).
const COUNT_MARGIN: f64 = 4.0;

/// A first estimate, an upper bound of the lowest eigenvalue that places the next shift.
const ROUGH: Accuracy = Accuracy {
    tolerance: 1e-4,
    refinements: 0,
    final_refinements: 0,
    iterations: 8,
};

/// The lowest eigenvalue is reported (1e-8 relative agreement of the Bloch blocks and the
/// full model needs the tighter setting where eigenvalues cluster).
const LOWEST: Accuracy = Accuracy {
    tolerance: 1e-11,
    refinements: 0,
    final_refinements: 1,
    iterations: 16,
};

/// The eigenvalue nearest zero only steers the secant that places a critical point.
const NEAREST_ZERO: Accuracy = Accuracy {
    tolerance: 1e-9,
    refinements: 2,
    final_refinements: 0,
    iterations: 80,
};
