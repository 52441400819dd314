//! Critical points continued in a second parameter (docs/theory.md, "Critical curves"): the
//! minimally extended system of a family of problems `R(x, λ; μ) = 0`,
//!
//! ```text
//! R(x, λ; μ) + B β = 0,   g(x, λ; μ) = 0,   [Bᵀ (x − x_ref) = 0],
//! ```
//!
//! in the unknowns `(x, λ[, β])`, continued in `μ` by the engine of
//! [`super::continuation`] as any other [`Problem`]. The test function `g` comes from a
//! bordered solve of the Jacobian `K = ∂R/∂x` (the KKT matrix) with the `k` borders `B`
//! (the critical modes: `k = 2` at a double point),
//!
//! ```text
//! [K  B] [V]   [0]
//! [Bᵀ 0] [G] = [I],    g = tr G / k,
//! ```
//!
//! which vanishes exactly where `K` has a `k`-dimensional null space. Its derivatives use
//! the symmetry of `K` (the Hessian of a Lagrangian, whose third derivatives are symmetric):
//! `g_x·δ = −(1/k) Σ V_lᵀ (D_δ K) V_l = −(1/k) Σ δ·(D_{V_l} K) V_l`, a central difference of
//! `K` in the direction `V_l` applied to `V_l`; `g_λ`, `g_μ` and `R_μ` are central
//! differences too, `R_μ` and `g_μ` of the problems the family builds at `μ ± h`.
//!
//! A fold needs nothing more. At a bifurcation `∂R/∂λ` lies in the range of `K`, so
//! `[K R_λ; g_x g_λ]` is singular; the point is then continued along the branch it
//! breaks off (its symmetry keeps it a bifurcation) with the multipliers `β` of the borders
//! and the rows that hold the state's component along them (`x_ref`, the last converged
//! state), which make the Jacobian regular there.

use super::problem::Problem;
use super::stability::InertiaError;
use crate::results::Stability;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use std::collections::VecDeque;

/// A family of problems of one layout (the same unknowns and Jacobian pattern) in a second
/// parameter `μ`.
pub trait Family {
    type Member: Problem;

    /// The problem at `μ`, or why there is none (a value the family refuses).
    fn member(&mut self, mu: f64) -> Result<Self::Member, String>;

    /// The step of the central differences in `μ` at `μ`.
    fn step(&self, mu: f64) -> f64;
}

/// How a critical point of the family is continued.
#[derive(Clone, Debug)]
pub struct CriticalStart {
    /// The state at the critical point (all unknowns of a member).
    pub x: Vec<f64>,
    pub lambda: f64,
    pub mu: f64,
    /// Its modes (one, or two at a double point), over all unknowns of a member or over
    /// its primal unknowns (then padded with zero multipliers).
    pub modes: Vec<Vec<f64>>,
    /// Whether it is a bifurcation (else a fold).
    pub bifurcation: bool,
}

/// Members kept for the central differences (`μ`, `μ ± h`, and one to spare).
const CACHE: usize = 4;

/// The extended system of a critical point of a [`Family`], as a [`Problem`] in `μ`.
pub struct CriticalSystem<F: Family> {
    family: F,
    members: VecDeque<(u64, F::Member)>,
    /// Unknowns and primal unknowns of a member.
    n: usize,
    np: usize,
    /// Borders (all unknowns of a member).
    borders: Vec<Vec<f64>>,
    bifurcation: bool,
    x_ref: Vec<f64>,
    /// Pattern of the extended Jacobian, and where each of its entries comes from.
    pattern: SymbolicSparseColMat<usize>,
    sources: Vec<Source>,
    bordered: Bordered,
    /// The first member the family refused, said once a step fails for it.
    refusal: Option<String>,
    /// Scale of the test function (the member's eigenvalue scale).
    scale: f64,
}

/// Where an entry of the extended Jacobian comes from.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// Entry `e` of the member's Jacobian.
    K(usize),
    /// `∂g/∂x_j`.
    Gx(usize),
    /// `∂R_i/∂λ`.
    Rl(usize),
    /// `∂g/∂λ`.
    Gl,
    /// Component `i` of border `l`.
    B(usize, usize),
}

impl<F: Family> CriticalSystem<F> {
    /// The extended system of `start` in `family`; `None` when the family has no member at
    /// the start's `μ` or the start does not fit its unknowns.
    pub fn new(mut family: F, start: &CriticalStart) -> Result<CriticalSystem<F>, String> {
        let member = family.member(start.mu)?;
        let (n, np) = (member.unknowns(), member.primal_unknowns());
        if start.x.len() != n || start.modes.is_empty() {
            return Err(format!(
                "the critical state has {} unknowns and {} modes, its problem {n} unknowns",
                start.x.len(),
                start.modes.len()
            ));
        }
        let borders = orthonormal(
            start
                .modes
                .iter()
                .map(|m| {
                    let mut b = m.clone();
                    b.resize(n, 0.0);
                    b
                })
                .collect(),
            np,
        );
        let k = borders.len();
        let nb = if start.bifurcation { k } else { 0 };
        let (pattern, sources) = extended_pattern(member.pattern(), n, np, k, nb);
        let bordered = Bordered::new(member.pattern(), n, k);
        let scale = member.eigenvalue_scale();
        let mut members = VecDeque::new();
        members.push_back((start.mu.to_bits(), member));
        Ok(CriticalSystem {
            family,
            members,
            n,
            np,
            borders,
            bifurcation: start.bifurcation,
            x_ref: start.x.clone(),
            pattern,
            sources,
            bordered,
            refusal: None,
            scale,
        })
    }

    /// The extended unknowns of a member's state `x` at `λ` (the multipliers `β` zero).
    pub fn extend(&self, x: &[f64], lambda: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.unknowns());
        out.extend_from_slice(&x[..self.np]);
        out.push(lambda);
        out.extend_from_slice(&x[self.np..]);
        out.resize(self.unknowns(), 0.0);
        out
    }

    /// A member's state and `λ` from extended unknowns.
    pub fn split(&self, xe: &[f64]) -> (Vec<f64>, f64) {
        let mut x = xe[..self.np].to_vec();
        x.extend_from_slice(&xe[self.np + 1..self.n + 1]);
        (x, xe[self.np])
    }

    /// The member at `μ` (built once, kept while it is used).
    pub fn member_at(&mut self, mu: f64) -> Option<&mut F::Member> {
        let key = mu.to_bits();
        if !self.members.iter().any(|(k, _)| *k == key) {
            match self.family.member(mu) {
                Ok(m) if m.unknowns() == self.n && same_pattern(m.pattern(), &self.bordered) => {
                    if self.members.len() == CACHE {
                        self.members.pop_front();
                    }
                    self.members.push_back((key, m));
                }
                Ok(m) => {
                    self.refusal.get_or_insert(format!(
                        "at {mu} the problem has {} unknowns (or another pattern), at the start {}: the layout of the state must not change along the curve",
                        m.unknowns(),
                        self.n
                    ));
                    return None;
                }
                Err(why) => {
                    self.refusal.get_or_insert(why);
                    return None;
                }
            }
        }
        self.members
            .iter_mut()
            .find(|(k, _)| *k == key)
            .map(|(_, m)| m)
    }

    /// Why the family had no member where a step needed one, if it happened.
    pub fn refusal(&self) -> Option<&str> {
        self.refusal.as_deref()
    }

    /// The number of borders (1, or 2 at a double point).
    pub fn borders(&self) -> usize {
        self.borders.len()
    }

    /// `g`, `V` at `(x, λ; μ)`: the member's Jacobian factorised with the borders. `None`
    /// where the member is refused or the bordered matrix is singular.
    fn test_function(&mut self, x: &[f64], lambda: f64, mu: f64) -> Option<(f64, Vec<Vec<f64>>)> {
        let n = self.n;
        let mut kv = self.bordered.k_values.clone();
        let mut r = vec![0.0; n];
        self.member_at(mu)?.jacobian(x, lambda, &mut r, &mut kv);
        self.bordered.k_values = kv;
        self.bordered.solve(&self.borders)
    }

    /// `−(1/k) Σ V_lᵀ (∂K/∂λ) V_l` (zero when the load enters linearly).
    fn g_lambda(&mut self, x: &[f64], lambda: f64, mu: f64, v: &[Vec<f64>]) -> f64 {
        if self
            .member_at(mu)
            .is_none_or(|m| m.load_derivative_is_constant())
        {
            return 0.0;
        }
        let h = 1e-6 * (1.0 + lambda.abs());
        let kp = self.k_at(x, lambda + h, mu);
        let km = self.k_at(x, lambda - h, mu);
        let (Some(kp), Some(km)) = (kp, km) else {
            return 0.0;
        };
        self.quadratic_difference(&kp, &km, v) / (2.0 * h)
    }

    /// `−(1/k) Σ V_lᵀ (K⁺ − K⁻) V_l`.
    fn quadratic_difference(&self, kp: &[f64], km: &[f64], v: &[Vec<f64>]) -> f64 {
        let p = self.bordered.member_pattern.as_ref();
        let d: Vec<f64> = kp.iter().zip(km).map(|(a, b)| a - b).collect();
        let dm = SparseColMatRef::new(p, &d);
        let k = v.len() as f64;
        -v.iter().map(|vl| quadratic(dm, vl)).sum::<f64>() / k
    }

    /// The member's Jacobian values at `(x, λ; μ)`.
    fn k_at(&mut self, x: &[f64], lambda: f64, mu: f64) -> Option<Vec<f64>> {
        let mut kv = vec![0.0; self.bordered.k_values.len()];
        let mut r = vec![0.0; self.n];
        self.member_at(mu)?.jacobian(x, lambda, &mut r, &mut kv);
        Some(kv)
    }

    /// `g_x = −(1/k) Σ (D_{V_l} K) V_l` by central differences of `K` along each `V_l`.
    fn g_x(&mut self, x: &[f64], lambda: f64, mu: f64, v: &[Vec<f64>]) -> Option<Vec<f64>> {
        let mut gx = vec![0.0; self.n];
        let k = v.len() as f64;
        for vl in v {
            let norm = vl.iter().map(|a| a * a).sum::<f64>().sqrt().max(1e-300);
            let h = 1e-5 / norm;
            let shifted =
                |s: f64| -> Vec<f64> { x.iter().zip(vl).map(|(a, b)| a + s * b).collect() };
            let kp = self.k_at(&shifted(h), lambda, mu)?;
            let km = self.k_at(&shifted(-h), lambda, mu)?;
            let d: Vec<f64> = kp
                .iter()
                .zip(&km)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let dm = SparseColMatRef::new(self.bordered.member_pattern.as_ref(), &d);
            let dv = multiply(dm, vl);
            for (g, a) in gx.iter_mut().zip(dv) {
                *g -= a / k;
            }
        }
        Some(gx)
    }

    /// Fills the extended residual from the member's residual `r` at `(x, λ)`, `g` and the
    /// multipliers `β` of `xe`.
    fn fill_residual(&self, xe: &[f64], x: &[f64], r: &[f64], g: f64, out: &mut [f64]) {
        let (n, np) = (self.n, self.np);
        for i in 0..n {
            let mut v = r[i];
            if self.bifurcation {
                for (l, b) in self.borders.iter().enumerate() {
                    v += b[i] * xe[n + 1 + l];
                }
            }
            out[ext(i, np)] = v;
        }
        out[np] = g;
        if self.bifurcation {
            for (l, b) in self.borders.iter().enumerate() {
                out[n + 1 + l] = b
                    .iter()
                    .zip(x)
                    .zip(&self.x_ref)
                    .map(|((bi, xi), ri)| bi * (xi - ri))
                    .sum();
            }
        }
    }

    /// What a refused member or a singular bordered matrix leaves: a residual no Newton
    /// iteration accepts, so that the step is cut back.
    fn refuse(out: &mut [f64]) -> f64 {
        out.fill(1e300);
        0.0
    }
}

impl<F: Family> Problem for CriticalSystem<F> {
    fn unknowns(&self) -> usize {
        self.n
            + 1
            + if self.bifurcation {
                self.borders.len()
            } else {
                0
            }
    }

    fn primal_unknowns(&self) -> usize {
        self.np + 1
    }

    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    fn residual(&mut self, xe: &[f64], mu: f64, out: &mut [f64]) -> f64 {
        let (x, lambda) = self.split(xe);
        let Some((g, _)) = self.test_function(&x, lambda, mu) else {
            return Self::refuse(out);
        };
        let mut r = vec![0.0; self.n];
        let Some(member) = self.member_at(mu) else {
            return Self::refuse(out);
        };
        let energy = member.residual(&x, lambda, &mut r);
        self.fill_residual(xe, &x, &r, g, out);
        energy
    }

    fn jacobian(&mut self, xe: &[f64], mu: f64, out: &mut [f64], jac: &mut [f64]) -> f64 {
        let (x, lambda) = self.split(xe);
        let Some((g, v)) = self.test_function(&x, lambda, mu) else {
            jac.fill(0.0);
            return Self::refuse(out);
        };
        let kv = self.bordered.k_values.clone();
        let gx = self.g_x(&x, lambda, mu, &v);
        let gl = self.g_lambda(&x, lambda, mu, &v);
        let mut r = vec![0.0; self.n];
        let mut rl = vec![0.0; self.n];
        let (Some(gx), Some(member)) = (gx, self.member_at(mu)) else {
            jac.fill(0.0);
            return Self::refuse(out);
        };
        let energy = member.residual(&x, lambda, &mut r);
        member.load_derivative(&x, lambda, &mut rl);
        for (value, source) in jac.iter_mut().zip(&self.sources) {
            *value = match *source {
                Source::K(e) => kv[e],
                Source::Gx(j) => gx[j],
                Source::Rl(i) => rl[i],
                Source::Gl => gl,
                Source::B(l, i) => self.borders[l][i],
            };
        }
        self.fill_residual(xe, &x, &r, g, out);
        energy
    }

    fn residual_weights(&self, weights: &mut [f64]) {
        let (n, np) = (self.n, self.np);
        let mut w = vec![1.0; n];
        if let Some((_, m)) = self.members.back() {
            m.residual_weights(&mut w);
        }
        for i in 0..n {
            weights[ext(i, np)] = w[i];
        }
        weights[np] = 1.0 / self.scale;
        for wb in weights.iter_mut().skip(n + 1) {
            *wb = 1.0;
        }
    }

    fn load_derivative(&mut self, xe: &[f64], mu: f64, out: &mut [f64]) {
        out.fill(0.0);
        let (x, lambda) = self.split(xe);
        let h = self.family.step(mu);
        let Some((_, v)) = self.test_function(&x, lambda, mu) else {
            return;
        };
        let (n, np) = (self.n, self.np);
        let mut rp = vec![0.0; n];
        let mut rm = vec![0.0; n];
        let (Some(kp), Some(km)) = (self.k_at(&x, lambda, mu + h), self.k_at(&x, lambda, mu - h))
        else {
            return;
        };
        if let Some(m) = self.member_at(mu + h) {
            m.residual(&x, lambda, &mut rp);
        }
        if let Some(m) = self.member_at(mu - h) {
            m.residual(&x, lambda, &mut rm);
        }
        for i in 0..n {
            out[ext(i, np)] = (rp[i] - rm[i]) / (2.0 * h);
        }
        out[np] = self.quadratic_difference(&kp, &km, &v) / (2.0 * h);
    }

    fn unstable_directions(&mut self, _x: &[f64], _mu: f64) -> Result<usize, InertiaError> {
        // a critical point is neither stable nor unstable: the curve does not count
        Ok(0)
    }

    fn lowest_eigenvalue(&mut self, _x: &[f64], _mu: f64) -> Option<f64> {
        None
    }

    fn eigenvalue_nearest_zero(&mut self, _x: &[f64], _mu: f64) -> Option<f64> {
        None
    }

    fn stability(&mut self, _x: &[f64], _mu: f64, _e: bool) -> Result<Stability, InertiaError> {
        Ok(Stability {
            unstable_directions: 0,
            lowest_eigenvalue: None,
            lowest_wavenumber: None,
        })
    }

    fn in_domain(&self, xe: &[f64]) -> bool {
        let (x, _) = self.split(xe);
        self.members.back().is_none_or(|(_, m)| m.in_domain(&x))
    }

    /// At a converged point the borders become its null vectors (orthonormalised), which
    /// keeps the bordered matrix well conditioned as the point moves (as MATCONT does), and
    /// the state's component along them is held from there.
    fn restore(&mut self, xe: &[f64], mu: f64) {
        let (x, lambda) = self.split(xe);
        if let Some((_, v)) = self.test_function(&x, lambda, mu) {
            let fresh = orthonormal(v, self.np);
            if fresh.len() == self.borders.len() && fresh.iter().flatten().all(|a| a.is_finite()) {
                self.borders = fresh;
            }
        }
        if let Some(m) = self.member_at(mu) {
            m.restore(&x, lambda);
        }
        self.x_ref = x;
    }
}

/// Index in the extended unknowns of a member's unknown `i` (`λ` sits after the primal
/// unknowns, so that the arclength norm runs over it).
fn ext(i: usize, np: usize) -> usize {
    if i < np {
        i
    } else {
        i + 1
    }
}

/// `vᵀ A v`.
fn quadratic(a: SparseColMatRef<'_, usize, f64>, v: &[f64]) -> f64 {
    multiply(a, v).iter().zip(v).map(|(a, b)| a * b).sum()
}

/// `A v`.
fn multiply(a: SparseColMatRef<'_, usize, f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for (j, vj) in v.iter().enumerate().take(a.ncols()) {
        for (i, aij) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            out[i] += aij * vj;
        }
    }
    out
}

/// The primal parts (the first `np` components; the multipliers' zero) of the vectors,
/// orthonormalised (Gram–Schmidt); a vector dependent on those before it is dropped.
fn orthonormal(vectors: Vec<Vec<f64>>, np: usize) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for mut v in vectors {
        v[np..].fill(0.0);
        for u in &out {
            let c: f64 = (0..np).map(|i| u[i] * v[i]).sum();
            for (a, b) in v.iter_mut().zip(u) {
                *a -= c * b;
            }
        }
        let norm = (0..np).map(|i| v[i] * v[i]).sum::<f64>().sqrt();
        if norm > 1e-8 && norm.is_finite() {
            v.iter_mut().for_each(|a| *a /= norm);
            out.push(v);
        }
    }
    out
}

/// Whether `pattern` is the member pattern the bordered matrix was built on.
fn same_pattern(pattern: &SymbolicSparseColMat<usize>, bordered: &Bordered) -> bool {
    let a = pattern.as_ref();
    let b = bordered.member_pattern.as_ref();
    a.col_ptr() == b.col_ptr() && a.row_idx() == b.row_idx()
}

/// The pattern of the extended Jacobian (`n + 1 + nb` square) from the member's `K`, and
/// the source of each entry in its order.
fn extended_pattern(
    k: &SymbolicSparseColMat<usize>,
    n: usize,
    np: usize,
    borders: usize,
    nb: usize,
) -> (SymbolicSparseColMat<usize>, Vec<Source>) {
    let k = k.as_ref();
    let size = n + 1 + nb;
    let mut columns: Vec<Vec<(usize, Source)>> = vec![Vec::new(); size];
    let mut e = 0;
    for j in 0..n {
        let col = &mut columns[ext(j, np)];
        let mut g_placed = false;
        for i in k.row_idx_of_col(j) {
            if i >= np && !g_placed {
                col.push((np, Source::Gx(j)));
                g_placed = true;
            }
            col.push((ext(i, np), Source::K(e)));
            e += 1;
        }
        if !g_placed {
            col.push((np, Source::Gx(j)));
        }
        for l in 0..nb {
            col.push((n + 1 + l, Source::B(l, j)));
        }
    }
    for i in 0..n {
        columns[np].push((ext(i, np), Source::Rl(i)));
    }
    columns[np].push((np, Source::Gl));
    columns[np].sort_by_key(|(r, _)| *r);
    for l in 0..nb.min(borders) {
        for i in 0..n {
            columns[n + 1 + l].push((ext(i, np), Source::B(l, i)));
        }
    }
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    let mut sources = Vec::new();
    for col in columns {
        for (r, s) in col {
            row_idx.push(r);
            sources.push(s);
        }
        col_ptr.push(row_idx.len());
    }
    let pattern = SymbolicSparseColMat::new_checked(size, size, col_ptr, None, row_idx);
    (pattern, sources)
}

/// The member's `K` bordered by the borders, `[K B; Bᵀ 0]`, and its LU.
struct Bordered {
    member_pattern: SymbolicSparseColMat<usize>,
    pattern: SymbolicSparseColMat<usize>,
    /// The member's Jacobian values (in its pattern) of the last evaluation.
    k_values: Vec<f64>,
    n: usize,
    lu: super::linear::SparseLu,
}

impl Bordered {
    fn new(k: &SymbolicSparseColMat<usize>, n: usize, borders: usize) -> Bordered {
        let kr = k.as_ref();
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for j in 0..n {
            row_idx.extend(kr.row_idx_of_col(j));
            row_idx.extend((0..borders).map(|l| n + l));
            col_ptr.push(row_idx.len());
        }
        for _ in 0..borders {
            row_idx.extend(0..n);
            col_ptr.push(row_idx.len());
        }
        let size = n + borders;
        Bordered {
            member_pattern: k.clone(),
            pattern: SymbolicSparseColMat::new_checked(size, size, col_ptr, None, row_idx),
            k_values: vec![0.0; kr.row_idx().len()],
            n,
            lu: super::linear::SparseLu::default(),
        }
    }

    /// `g = tr G / k` and `V` from the bordered solve with the `k_values` held.
    fn solve(&mut self, borders: &[Vec<f64>]) -> Option<(f64, Vec<Vec<f64>>)> {
        let (n, k) = (self.n, borders.len());
        let kr = self.member_pattern.as_ref();
        let mut values = Vec::with_capacity(self.pattern.row_idx().len());
        for j in 0..n {
            let range = kr.col_ptr()[j]..kr.col_ptr()[j + 1];
            values.extend_from_slice(&self.k_values[range]);
            values.extend(borders.iter().map(|b| b[j]));
        }
        for b in borders {
            values.extend_from_slice(&b[..n]);
        }
        let m = SparseColMatRef::new(self.pattern.as_ref(), &values);
        self.lu.factorize(m).ok()?;
        let mut g = 0.0;
        let mut v = Vec::with_capacity(k);
        for l in 0..k {
            let mut rhs = vec![0.0; n + k];
            rhs[n + l] = 1.0;
            self.lu.solve(&mut rhs);
            g += rhs[n + l];
            rhs.truncate(n);
            v.push(rhs);
        }
        let g = g / k as f64;
        (g.is_finite() && v.iter().flatten().all(|a| a.is_finite())).then_some((g, v))
    }
}
