//! The extended system of a critical point on canonical families with known critical
//! curves, continued by the same engine that follows the paths: a fold `u − λ e^{μu} = 0`
//! (limit point at `u = 1/μ`, `λ = 1/(e μ)`) and a pitchfork `(μ k₁ − λ) u₁ + u₁³ = 0`,
//! `(μ k₂ − λ) u₂ + u₂³ = 0` (bifurcation of the trivial branch at `λ = μ k₁`).

use faer::sparse::SymbolicSparseColMat;
use spira::results::Stability;
use spira::solver::continuation::{Continuation, ContinuationSettings};
use spira::solver::extended::{CriticalStart, CriticalSystem, Family};
use spira::solver::problem::Problem;
use spira::solver::stability::InertiaError;
use std::f64::consts::E;

/// A diagonal problem of `n` unknowns with residual `r(x, λ; μ)`, Jacobian `j` and load
/// derivative `l` (each component of its own unknown).
struct Diagonal {
    mu: f64,
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    r: fn(f64, f64, f64, usize) -> f64,
    j: fn(f64, f64, f64, usize) -> f64,
    l: fn(f64, f64, f64, usize) -> f64,
}

impl Problem for Diagonal {
    fn unknowns(&self) -> usize {
        self.n
    }
    fn primal_unknowns(&self) -> usize {
        self.n
    }
    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }
    fn residual(&mut self, x: &[f64], lambda: f64, out: &mut [f64]) -> f64 {
        for i in 0..self.n {
            out[i] = (self.r)(x[i], lambda, self.mu, i);
        }
        0.0
    }
    fn jacobian(&mut self, x: &[f64], lambda: f64, out: &mut [f64], jac: &mut [f64]) -> f64 {
        for i in 0..self.n {
            jac[i] = (self.j)(x[i], lambda, self.mu, i);
        }
        self.residual(x, lambda, out)
    }
    fn load_derivative(&mut self, x: &[f64], lambda: f64, out: &mut [f64]) {
        for i in 0..self.n {
            out[i] = (self.l)(x[i], lambda, self.mu, i);
        }
    }
    fn unstable_directions(&mut self, _x: &[f64], _l: f64) -> Result<usize, InertiaError> {
        Ok(0)
    }
    fn lowest_eigenvalue(&mut self, _x: &[f64], _l: f64) -> Option<f64> {
        None
    }
    fn eigenvalue_nearest_zero(&mut self, _x: &[f64], _l: f64) -> Option<f64> {
        None
    }
    fn stability(&mut self, _x: &[f64], _l: f64, _e: bool) -> Result<Stability, InertiaError> {
        Ok(Stability {
            unstable_directions: 0,
            lowest_eigenvalue: None,
            lowest_wavenumber: None,
        })
    }
}

/// The family of [`Diagonal`] problems in `μ`.
struct Diagonals(fn(f64) -> Diagonal);

impl Family for Diagonals {
    type Member = Diagonal;
    fn member(&mut self, mu: f64) -> Result<Diagonal, String> {
        Ok((self.0)(mu))
    }
    fn step(&self, mu: f64) -> f64 {
        1e-6 * (1.0 + mu.abs())
    }
}

fn diagonal_pattern(n: usize) -> SymbolicSparseColMat<usize> {
    SymbolicSparseColMat::new_checked(n, n, (0..=n).collect(), None, (0..n).collect())
}

fn fold(mu: f64) -> Diagonal {
    Diagonal {
        mu,
        n: 1,
        pattern: diagonal_pattern(1),
        r: |u, l, m, _| u - l * (m * u).exp(),
        j: |u, l, m, _| 1.0 - l * m * (m * u).exp(),
        l: |u, _, m, _| -(m * u).exp(),
    }
}

const K: [f64; 2] = [1.0, 2.0];

fn pitchfork(mu: f64) -> Diagonal {
    Diagonal {
        mu,
        n: 2,
        pattern: diagonal_pattern(2),
        r: |u, l, m, i| (m * K[i] - l) * u + u.powi(3),
        j: |u, l, m, i| m * K[i] - l + 3.0 * u * u,
        l: |u, _, _, _| -u,
    }
}

fn settings() -> ContinuationSettings {
    ContinuationSettings {
        initial_step: 0.05,
        max_step: 0.1,
        track_stability: false,
        lowest_eigenvalue: false,
        ..Default::default()
    }
}

/// The fold of `u − λ e^{μu}` from μ = 1 to 2: `λ = 1/(e μ)`, `u = 1/μ` at every value.
#[test]
fn a_fold_is_continued_in_a_second_parameter_along_its_known_curve() {
    let start = CriticalStart {
        x: vec![1.0],
        lambda: 1.0 / E,
        mu: 1.0,
        modes: vec![vec![1.0]],
        bifurcation: false,
    };
    let system = CriticalSystem::new(Diagonals(fold), &start).expect("the system");
    let xe = system.extend(&start.x, start.lambda);
    let mut path = Continuation::new(system, xe, 1.0, settings()).expect("the start");
    for k in 1..=10 {
        let mu = 1.0 + 0.1 * k as f64;
        path.advance_to(mu).expect("a step");
        let (x, lambda) = path.problem().split(&path.state().x);
        assert!(
            (lambda - 1.0 / (E * mu)).abs() < 1e-9,
            "μ = {mu}: λ = {lambda}"
        );
        assert!((x[0] - 1.0 / mu).abs() < 1e-8, "μ = {mu}: u = {}", x[0]);
    }
}

/// The first pitchfork of the trivial branch from μ = 1 to 3: `λ = μ k₁`, the state
/// trivial and the multiplier of the border zero at every value.
#[test]
fn a_pitchfork_is_continued_by_the_branch_point_system() {
    let start = CriticalStart {
        x: vec![0.0, 0.0],
        lambda: 1.0,
        mu: 1.0,
        modes: vec![vec![1.0, 0.0]],
        bifurcation: true,
    };
    let system = CriticalSystem::new(Diagonals(pitchfork), &start).expect("the system");
    let xe = system.extend(&start.x, start.lambda);
    let mut path = Continuation::new(system, xe, 1.0, settings()).expect("the start");
    for k in 1..=10 {
        let mu = 1.0 + 0.2 * k as f64;
        path.advance_to(mu).expect("a step");
        let xe = path.state().x.clone();
        let (x, lambda) = path.problem().split(&xe);
        assert!((lambda - mu * K[0]).abs() < 1e-9, "μ = {mu}: λ = {lambda}");
        assert!(x.iter().all(|u| u.abs() < 1e-9), "μ = {mu}: {x:?}");
        assert!(xe[3].abs() < 1e-9, "μ = {mu}: β = {}", xe[3]);
    }
}
