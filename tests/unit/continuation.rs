//! The continuation engine on its own, on canonical problems with known answers: a fold
//! (`u − λ eᵘ = 0`, limit point at `λ = 1/e`, `u = 1`), a pitchfork with its known branch
//! (`(1 − λ) u + u³ = 0`, branches `u = ±√(λ − 1)`), and the discretised Bratu problem
//! (`−u'' = λ eᵘ` on (0, 1), first fold at `λ* = 3.513830719…`). The same continuation,
//! critical-point and branch-switching code follows the rods.

#![allow(clippy::needless_range_loop)] // the residuals index neighbours as the stencils do

use faer::sparse::SymbolicSparseColMat;
use spira::results::CriticalKind;
use spira::solver::continuation::{Continuation, ContinuationSettings, StopReason};
use spira::solver::problem::Problem;
use spira::solver::stability::{InertiaError, KktStability};

/// A pattern with the given rows in each column (sorted).
fn pattern(columns: &[Vec<usize>]) -> SymbolicSparseColMat<usize> {
    let n = columns.len();
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    for rows in columns {
        row_idx.extend_from_slice(rows);
        col_ptr.push(row_idx.len());
    }
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
}

/// Implements the stability hooks from the problem's own Jacobian, unconstrained, in the
/// identity metric.
macro_rules! stability_from_jacobian {
    () => {
        fn unstable_directions(&mut self, x: &[f64], lambda: f64) -> Result<usize, InertiaError> {
            let values = self.values_at(x, lambda);
            self.stability.unstable_directions(&self.pattern, &values)
        }
        fn lowest_eigenvalue(&mut self, x: &[f64], lambda: f64) -> Option<f64> {
            let values = self.values_at(x, lambda);
            self.stability.lowest_eigenvalue(&self.pattern, &values)
        }
        fn eigenvalue_nearest_zero(&mut self, x: &[f64], lambda: f64) -> Option<f64> {
            let values = self.values_at(x, lambda);
            self.stability
                .eigenvalue_nearest_zero(&self.pattern, &values)
        }
    };
}

// ---------------------------------------------------------------- the fold

/// `R(u, λ) = u − λ eᵘ`, the gradient of `E = u²/2 − λ eᵘ`: stable (`∂R/∂u > 0`) on the
/// lower branch, a fold at `λ = 1/e`, `u = 1`.
struct Fold {
    pattern: SymbolicSparseColMat<usize>,
    stability: KktStability,
}

impl Fold {
    fn new() -> Fold {
        Fold {
            pattern: pattern(&[vec![0]]),
            stability: KktStability::new(vec![1.0], 1.0),
        }
    }
    fn values_at(&self, x: &[f64], lambda: f64) -> Vec<f64> {
        vec![1.0 - lambda * x[0].exp()]
    }
}

impl Problem for Fold {
    fn unknowns(&self) -> usize {
        1
    }
    fn primal_unknowns(&self) -> usize {
        1
    }
    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }
    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        residual[0] = x[0] - lambda * x[0].exp();
        0.5 * x[0] * x[0] - lambda * x[0].exp()
    }
    fn jacobian(&mut self, x: &[f64], lambda: f64, r: &mut [f64], j: &mut [f64]) -> f64 {
        j.copy_from_slice(&self.values_at(x, lambda));
        self.residual(x, lambda, r)
    }
    fn load_derivative(&mut self, x: &[f64], _lambda: f64, out: &mut [f64]) {
        out[0] = -x[0].exp();
    }
    stability_from_jacobian!();
}

fn settings() -> ContinuationSettings {
    ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.05,
        ..Default::default()
    }
}

#[test]
fn a_fold_is_passed_by_arclength_and_located_at_one_over_e() {
    let mut path = Continuation::new(Fold::new(), vec![0.0], 0.0, settings()).unwrap();
    // the target lies beyond the fold: natural steps fail there, arclength steps go round
    // it and follow the upper branch back towards λ = 0, and the engine gives up
    let err = path.advance_to(0.5).unwrap_err();
    assert!(matches!(err.reason, StopReason::TurnedBack { .. }), "{err}");
    let cps = path.critical_points();
    assert_eq!(cps.len(), 1, "{cps:?}");
    let fold = &cps[0];
    assert_eq!(fold.kind, CriticalKind::LimitPoint);
    assert_eq!((fold.unstable_before, fold.unstable_after), (0, 1));
    // exact: λ = 1/e, u = 1 (the fold is quadratic in u, so u is located to √ of λ's error)
    let exact = (-1.0f64).exp();
    assert!(
        (fold.parameter - exact).abs() < 1e-10,
        "λ = {} vs 1/e = {exact}",
        fold.parameter
    );
    assert!((fold.state[0] - 1.0).abs() < 1e-4, "u = {}", fold.state[0]);
    // the path went on along the upper (unstable) branch, u > 1, solutions of u = λ eᵘ
    let s = path.state();
    assert!(s.x[0] > 1.0);
    assert!((s.x[0] - s.lambda * s.x[0].exp()).abs() < 1e-9);
    assert_eq!(s.stability.map(|st| st.unstable_directions), Some(1));
}

// ---------------------------------------------------------------- the pitchfork

/// `R = ((1 − λ) u₁ + u₁³, (2 − λ) u₂ + u₂³)`, the gradient of
/// `E = Σ ½ (kᵢ − λ) uᵢ² + ¼ uᵢ⁴` with `k = (1, 2)`: the trivial branch `u = 0` loses
/// stability at `λ = 1` (mode `u₁`) and `λ = 2` (mode `u₂`); the branch born at `λ = 1` is
/// `u₁ = ±√(λ − 1)`, `u₂ = 0`, stable until `λ = 2`.
struct Pitchfork {
    pattern: SymbolicSparseColMat<usize>,
    stability: KktStability,
}

const K: [f64; 2] = [1.0, 2.0];

impl Pitchfork {
    fn new() -> Pitchfork {
        Pitchfork {
            pattern: pattern(&[vec![0], vec![1]]),
            stability: KktStability::new(vec![1.0, 1.0], 1.0),
        }
    }
    fn values_at(&self, x: &[f64], lambda: f64) -> Vec<f64> {
        (0..2).map(|i| K[i] - lambda + 3.0 * x[i] * x[i]).collect()
    }
}

impl Problem for Pitchfork {
    fn unknowns(&self) -> usize {
        2
    }
    fn primal_unknowns(&self) -> usize {
        2
    }
    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }
    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        let mut energy = 0.0;
        for i in 0..2 {
            residual[i] = (K[i] - lambda) * x[i] + x[i].powi(3);
            energy += 0.5 * (K[i] - lambda) * x[i] * x[i] + 0.25 * x[i].powi(4);
        }
        energy
    }
    fn jacobian(&mut self, x: &[f64], lambda: f64, r: &mut [f64], j: &mut [f64]) -> f64 {
        j.copy_from_slice(&self.values_at(x, lambda));
        self.residual(x, lambda, r)
    }
    fn load_derivative(&mut self, x: &[f64], _lambda: f64, out: &mut [f64]) {
        out[0] = -x[0];
        out[1] = -x[1];
    }
    stability_from_jacobian!();
}

#[test]
fn on_the_trivial_branch_a_pitchfork_is_found_at_each_mode() {
    let mut path = Continuation::new(Pitchfork::new(), vec![0.0; 2], 0.0, settings()).unwrap();
    path.advance_to(2.5).unwrap();
    let cps = path.critical_points();
    assert_eq!(cps.len(), 2, "{cps:?}");
    for (k, cp) in cps.iter().enumerate() {
        assert_eq!(cp.kind, CriticalKind::Bifurcation);
        assert_eq!((cp.unstable_before, cp.unstable_after), (k, k + 1));
        // exact: λ = kᵢ, the count's rounding band (1e-9 of the Hessian scale) aside
        assert!((cp.parameter - K[k]).abs() < 1e-8, "{}", cp.parameter);
        // the mode is the unit vector of the mode that goes soft
        assert!((cp.mode[k].abs() - 1.0).abs() < 1e-9, "{:?}", cp.mode);
        assert!(cp.mode[1 - k].abs() < 1e-9, "{:?}", cp.mode);
    }
    // the trivial solution stays u = 0, now with two unstable directions
    assert_eq!(path.state().x, vec![0.0, 0.0]);
    assert_eq!(path.state().stability.unwrap().unstable_directions, 2);
}

#[test]
fn switching_at_the_first_pitchfork_follows_the_known_branch() {
    // states to 1e-9 where the Jacobian is 2(λ − 1) = 0.4 need residuals below 4e-10
    let mut settings = settings();
    settings.newton.tolerance = 1e-12;
    let mut path = Continuation::new(Pitchfork::new(), vec![0.0; 2], 0.0, settings).unwrap();
    path.advance_to(1.2).unwrap();
    assert_eq!(path.critical_points().len(), 1);
    path.switch_branch(0, 1.0, 0.05).unwrap();
    for target in [1.2, 1.5, 1.9] {
        path.advance_to(target).unwrap();
        let s = path.state();
        assert!((s.lambda - target).abs() < 1e-14);
        // u₁ = ±√(λ − 1), u₂ = 0, stable
        assert!(
            (s.x[0].abs() - (target - 1.0).sqrt()).abs() < 1e-9,
            "λ = {target}: u = {:?}",
            s.x
        );
        assert!(s.x[1].abs() < 1e-12);
        assert_eq!(s.stability.unwrap().unstable_directions, 0);
    }
    // on the bifurcated branch the second mode still goes soft at λ = 2: Hessian
    // diag(2(λ − 1), 2 − λ)
    path.advance_to(2.3).unwrap();
    let cps = path.critical_points();
    assert_eq!(cps.len(), 2);
    assert_eq!((cps[1].unstable_before, cps[1].unstable_after), (0, 1));
    assert!(
        (cps[1].parameter - 2.0).abs() < 1e-8,
        "{}",
        cps[1].parameter
    );
}

// ---------------------------------------------------------------- Bratu

/// `−u'' = λ eᵘ` on (0, 1), `u(0) = u(1) = 0`, by central differences on `n` interior
/// nodes (`h = 1/(n + 1)`), written as the gradient of
/// `E = Σ (u_{i+1} − u_i)²/(2h) − λ h Σ e^{u_i}`: `R_i = (2u_i − u_{i−1} − u_{i+1})/h − λ h e^{u_i}`.
struct Bratu {
    n: usize,
    h: f64,
    pattern: SymbolicSparseColMat<usize>,
    stability: KktStability,
}

impl Bratu {
    fn new(n: usize) -> Bratu {
        let columns: Vec<Vec<usize>> = (0..n)
            .map(|j| (j.saturating_sub(1)..(j + 2).min(n)).collect())
            .collect();
        Bratu {
            n,
            h: 1.0 / (n + 1) as f64,
            pattern: pattern(&columns),
            stability: KktStability::new(vec![1.0; n], 1.0),
        }
    }
    fn values_at(&self, x: &[f64], lambda: f64) -> Vec<f64> {
        let mut v = Vec::new();
        for j in 0..self.n {
            if j > 0 {
                v.push(-1.0 / self.h);
            }
            v.push(2.0 / self.h - lambda * self.h * x[j].exp());
            if j + 1 < self.n {
                v.push(-1.0 / self.h);
            }
        }
        v
    }
}

impl Problem for Bratu {
    fn unknowns(&self) -> usize {
        self.n
    }
    fn primal_unknowns(&self) -> usize {
        self.n
    }
    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }
    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        let h = self.h;
        let at = |i: isize| {
            if i < 0 || i as usize >= self.n {
                0.0
            } else {
                x[i as usize]
            }
        };
        let mut energy = 0.0;
        for i in 0..self.n {
            let (l, c, r) = (at(i as isize - 1), x[i], at(i as isize + 1));
            residual[i] = (2.0 * c - l - r) / h - lambda * h * c.exp();
            energy += (r - c).powi(2) / (2.0 * h) - lambda * h * c.exp();
        }
        energy + at(0).powi(2) / (2.0 * h)
    }
    fn jacobian(&mut self, x: &[f64], lambda: f64, r: &mut [f64], j: &mut [f64]) -> f64 {
        j.copy_from_slice(&self.values_at(x, lambda));
        self.residual(x, lambda, r)
    }
    fn load_derivative(&mut self, x: &[f64], _lambda: f64, out: &mut [f64]) {
        for (o, u) in out.iter_mut().zip(x) {
            *o = -self.h * u.exp();
        }
    }
    stability_from_jacobian!();
}

/// The first fold of the discretised Bratu problem on `n` interior nodes.
fn bratu_fold(n: usize) -> f64 {
    let settings = ContinuationSettings {
        initial_step: 0.1,
        max_step: 0.2,
        ..Default::default()
    };
    let mut path = Continuation::new(Bratu::new(n), vec![0.0; n], 0.0, settings).unwrap();
    let err = path.advance_to(4.0).unwrap_err();
    assert!(matches!(err.reason, StopReason::TurnedBack { .. }), "{err}");
    let cps = path.critical_points();
    assert_eq!(cps.len(), 1, "n = {n}: {cps:?}");
    assert_eq!(cps[0].kind, CriticalKind::LimitPoint);
    assert_eq!((cps[0].unstable_before, cps[0].unstable_after), (0, 1));
    // at the fold the solution is symmetric about x = 1/2 and peaks at u ≈ 1.1868
    let u = &cps[0].state;
    for i in 0..n {
        assert!((u[i] - u[n - 1 - i]).abs() < 1e-6);
    }
    cps[0].parameter
}

#[test]
fn the_first_fold_of_bratu_converges_to_3_513830719() {
    // λ* = 3.51383071912516 (the root of the continuum problem's fold condition,
    // 1 = (λ/8)^{1/2} sinh(θ/4) ... ; e.g. Boyd 1986, Mohsen 2014): central differences
    // converge as h², so Richardson's extrapolation of two meshes (h, h/2) is O(h⁴)
    let exact = 3.513_830_719_125_16;
    let (coarse, fine) = (bratu_fold(63), bratu_fold(127));
    assert!(coarse < fine && fine < exact, "{coarse} {fine}");
    let order = ((exact - coarse) / (exact - fine)).log2();
    assert!((order - 2.0).abs() < 0.05, "observed order {order}");
    let extrapolated = fine + (fine - coarse) / 3.0;
    assert!(
        (extrapolated - exact).abs() < 1e-7,
        "extrapolated {extrapolated} vs {exact}"
    );
}

#[test]
fn an_interrupted_solve_stops_at_its_last_converged_state() {
    use spira::solver::interrupt::{Interrupt, Interruption};
    let mut path = Continuation::new(Fold::new(), vec![0.0], 0.0, settings()).unwrap();
    path.advance_to(0.1).unwrap();
    let before = path.state().clone();
    let interrupt = Interrupt::new();
    path.set_interrupt(Some(interrupt.clone()));
    interrupt.raise();
    let err = path.advance_to(0.3).unwrap_err();
    assert_eq!(err.reason, StopReason::Interrupted(Interruption::Cancelled));
    assert_eq!(path.state(), &before);
    // a budget already spent stops the next solve with that reason
    interrupt.clear();
    path.set_interrupt(Some(
        interrupt.with_deadline(Some(std::time::Instant::now())),
    ));
    let err = path.advance_to(0.3).unwrap_err();
    assert_eq!(err.reason, StopReason::Interrupted(Interruption::Deadline));
    // lowered, the path goes on to the same solution as without interruption
    path.set_interrupt(None);
    path.advance_to(0.3).unwrap();
    let u = path.state().x[0];
    assert!((u - 0.3 * u.exp()).abs() < 1e-9 && u < 1.0);
}
