//! Critical points continued in a second parameter (docs/theory.md, "Critical curves"): the
//! minimally extended system of a family of problems `R(x, λ; μ) = 0`,
//!
//! ```text
//! R(x, λ; μ) [+ B β] = 0,   g(x, λ; μ) = 0,   [h(x, λ; μ) = 0],
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
//! `[K R_λ; g_x g_λ]` is singular; the system then takes the multipliers `β` of the borders
//! and, for each border, the Fredholm condition that makes the point a bifurcation,
//! `h_l = V_lᵀ R_λ = 0` (the load does no work on the mode): `(R + B β, g, h) = 0` is
//! regular at a bifurcation, and along a curve of bifurcations kept by a symmetry `β`
//! stays zero, so its solutions are the bifurcations of `R` itself (the branch-point
//! system of MATCONT). `h_x = −(D_V K) Z + (∂K/∂λ) V` with `[K B; Bᵀ 0][Z; ζ] = [R_λ; 0]`.

mod parts;

use super::interrupt::Interrupt;
use super::problem::Problem;
use super::stability::InertiaError;
use crate::results::Stability;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use parts::{dot, ext, extended_pattern, multiply, orthonormal, pattern_map, Bordered, Source};
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
    /// its primal unknowns.
    pub modes: Vec<Vec<f64>>,
    /// Whether it is a bifurcation (else a fold).
    pub bifurcation: bool,
}

/// Members kept for the central differences (`μ`, `μ ± h`, and one to spare).
const CACHE: usize = 4;

/// Relative step of the central differences in `x` (along a unit mode) and in `λ`.
const STEP: f64 = 1e-5;

/// The extended system of a critical point of a [`Family`], as a [`Problem`] in `μ`.
pub struct CriticalSystem<F: Family> {
    family: F,
    members: VecDeque<Cached<F::Member>>,
    /// Unknowns and primal unknowns of a member.
    n: usize,
    np: usize,
    /// Borders (all unknowns of a member, their multiplier parts zero).
    borders: Vec<Vec<f64>>,
    bifurcation: bool,
    /// Pattern of the extended Jacobian, and where each of its entries comes from.
    pattern: SymbolicSparseColMat<usize>,
    sources: Vec<Source>,
    bordered: Bordered,
    /// The first member the family refused, said once a step fails for it.
    refusal: Option<String>,
    /// The refusal was a member of another layout (unknowns or matrix entries) than the
    /// start's: the family goes on there, as another system.
    layout_changed: bool,
    /// Raised at a refusal: the family has no member there, and none beyond (a value the
    /// case refuses, a layout that changes), so the curve stops instead of cutting its
    /// step down to nothing.
    stop: Option<Interrupt>,
    /// Scales of the test functions `g` (the member's eigenvalue scale) and `h` (`|R_λ|`
    /// at the start).
    g_scale: f64,
    h_scale: f64,
}

/// The test functions at a point and what their derivatives need.
struct Point {
    g: f64,
    v: Vec<Vec<f64>>,
    /// `Z` and the `h_l` (at a bifurcation).
    z: Vec<f64>,
    h: Vec<f64>,
}

/// The derivatives of `g` and `h` in `x` and `λ`.
struct Rows {
    gx: Vec<f64>,
    hx: Vec<Vec<f64>>,
    gl: f64,
    hl: Vec<f64>,
}

impl<F: Family> CriticalSystem<F> {
    /// The extended system of `start` in `family`, or why there is none.
    pub fn new(mut family: F, start: &CriticalStart) -> Result<CriticalSystem<F>, String> {
        let mut member = family.member(start.mu)?;
        let (n, np) = (member.unknowns(), member.primal_unknowns());
        if start.x.len() != n || start.modes.is_empty() {
            return Err(format!(
                "the critical state has {} unknowns and {} modes, its problem {n} unknowns",
                start.x.len(),
                start.modes.len()
            ));
        }
        let padded = start.modes.iter().map(|m| {
            let mut b = m.clone();
            b.resize(n, 0.0);
            b
        });
        let borders = orthonormal(padded.collect(), np);
        let nb = if start.bifurcation { borders.len() } else { 0 };
        let (pattern, sources) = extended_pattern(member.pattern(), n, np, nb);
        let bordered = Bordered::new(member.pattern(), n, borders.len());
        let mut rl = vec![0.0; n];
        member.load_derivative(&start.x, start.lambda, &mut rl);
        let h_scale = dot(&rl, &rl).sqrt();
        let mut members = VecDeque::new();
        let g_scale = member.eigenvalue_scale();
        members.push_back(Cached {
            key: start.mu.to_bits(),
            member,
            map: None,
        });
        Ok(CriticalSystem {
            family,
            members,
            n,
            np,
            borders,
            bifurcation: start.bifurcation,
            pattern,
            sources,
            bordered,
            refusal: None,
            layout_changed: false,
            stop: None,
            g_scale,
            h_scale: if h_scale > 0.0 { h_scale } else { 1.0 },
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
        self.cached(mu).map(|c| &mut c.member)
    }

    /// The member at `μ` with the map of its Jacobian's entries onto the start's pattern.
    fn cached(&mut self, mu: f64) -> Option<&mut Cached<F::Member>> {
        let key = mu.to_bits();
        if !self.members.iter().any(|c| c.key == key) {
            let member = match self.family.member(mu) {
                Ok(m) => m,
                Err(why) => {
                    self.refused(why);
                    return None;
                }
            };
            let map = pattern_map(member.pattern(), &self.bordered.member_pattern);
            if member.unknowns() != self.n || map.is_none() {
                self.layout_changed |= self.refusal.is_none();
                self.refused(format!(
                    "at {mu} the problem has {} unknowns (at the start {}) or entries of its matrix the start's has not: the layout of the state must not change along the curve",
                    member.unknowns(),
                    self.n
                ));
                return None;
            }
            if self.members.len() == CACHE {
                self.members.pop_front();
            }
            self.members.push_back(Cached {
                key,
                member,
                map: map.flatten(),
            });
        }
        self.members.iter_mut().find(|c| c.key == key)
    }

    /// `stop` is raised where the family refuses a member.
    pub fn set_stop(&mut self, stop: Option<Interrupt>) {
        self.stop = stop;
    }

    /// Notes the first refusal and raises the stop.
    fn refused(&mut self, why: String) {
        self.refusal.get_or_insert(why);
        if let Some(stop) = &self.stop {
            stop.raise();
        }
    }

    /// Why the family had no member where a step needed one, if it happened.
    pub fn refusal(&self) -> Option<&str> {
        self.refusal.as_deref()
    }

    /// Whether the first refusal was of a member whose layout differs from the start's (a
    /// mesh that gains a vertex, a crossing that enters the rods): the family has members
    /// beyond, but not of this system.
    pub fn layout_changed(&self) -> bool {
        self.layout_changed
    }

    /// The number of borders (1, or 2 at a double point).
    pub fn borders(&self) -> usize {
        self.borders.len()
    }

    /// Multipliers `β` (0 at a fold).
    fn nb(&self) -> usize {
        if self.bifurcation {
            self.borders.len()
        } else {
            0
        }
    }

    /// The member's Jacobian values at `(x, λ; μ)`, in the start's pattern.
    fn k_at(&mut self, x: &[f64], lambda: f64, mu: f64) -> Option<Vec<f64>> {
        let entries = self.bordered.entries();
        let mut r = vec![0.0; self.n];
        let c = self.cached(mu)?;
        let mut own = vec![0.0; c.member.pattern().row_idx().len()];
        c.member.jacobian(x, lambda, &mut r, &mut own);
        Some(match &c.map {
            None => own,
            Some(map) => {
                let mut kv = vec![0.0; entries];
                for (e, v) in map.iter().zip(own) {
                    kv[*e] = v;
                }
                kv
            }
        })
    }

    /// `R_λ` of the member at `(x, λ; μ)`.
    fn rl_at(&mut self, x: &[f64], lambda: f64, mu: f64) -> Option<Vec<f64>> {
        let mut rl = vec![0.0; self.n];
        self.member_at(mu)?.load_derivative(x, lambda, &mut rl);
        Some(rl)
    }

    /// The test functions at `(x, λ; μ)`, the bordered matrix factorised there. `None`
    /// where the member is refused or the bordered matrix is singular.
    fn point(&mut self, x: &[f64], lambda: f64, mu: f64) -> Option<Point> {
        let k = self.k_at(x, lambda, mu)?;
        let (g, v) = self.bordered.solve(&k, &self.borders)?;
        let nb = self.nb();
        if nb == 0 {
            return Some(Point {
                g,
                v,
                z: Vec::new(),
                h: Vec::new(),
            });
        }
        let rl = self.rl_at(x, lambda, mu)?;
        let z = self.bordered.solve_for(&rl, self.borders.len());
        let h = v.iter().map(|vl| dot(vl, &rl)).collect();
        Some(Point { g, v, z, h })
    }

    /// `(K⁺ − K⁻)/d` as a matrix in the start's pattern, times each of `vectors`.
    fn difference_times(
        &self,
        kp: &[f64],
        km: &[f64],
        d: f64,
        vectors: &[&[f64]],
    ) -> Vec<Vec<f64>> {
        let diff: Vec<f64> = kp.iter().zip(km).map(|(a, b)| (a - b) / d).collect();
        let m = SparseColMatRef::new(self.bordered.member_pattern.as_ref(), &diff);
        vectors.iter().map(|v| multiply(m, v)).collect()
    }

    /// `−(1/k) Σ V_lᵀ D V_l` and `−Zᵀ D V_l + V_l·s` for a derivative `D` of `K` (values
    /// `(K⁺ − K⁻)/d`) and `s` of `R_λ` in one parameter.
    fn parameter_terms(
        &self,
        p: &Point,
        kp: &[f64],
        km: &[f64],
        d: f64,
        s: &[f64],
    ) -> (f64, Vec<f64>) {
        let vs: Vec<&[f64]> = p.v.iter().map(Vec::as_slice).collect();
        let dv = self.difference_times(kp, km, d, &vs);
        let k = p.v.len() as f64;
        let g = -p.v.iter().zip(&dv).map(|(v, w)| dot(v, w)).sum::<f64>() / k;
        let h = (0..self.nb())
            .map(|l| -dot(&p.z, &dv[l]) + dot(&p.v[l], s))
            .collect();
        (g, h)
    }

    /// `g_x`, `h_x` by central differences of `K` along each `V_l` (the symmetry of the
    /// third derivatives), and `g_λ`, `h_λ` (zero where the load enters linearly).
    fn rows(&mut self, x: &[f64], lambda: f64, mu: f64, p: &Point) -> Option<Rows> {
        let (n, nb) = (self.n, self.nb());
        let k = p.v.len() as f64;
        let mut gx = vec![0.0; n];
        let mut hx = vec![vec![0.0; n]; nb];
        for (l, vl) in p.v.iter().enumerate() {
            let h = STEP / dot(vl, vl).sqrt().max(1e-300);
            let shifted =
                |s: f64| -> Vec<f64> { x.iter().zip(vl).map(|(a, b)| a + s * b).collect() };
            let kp = self.k_at(&shifted(h), lambda, mu)?;
            let km = self.k_at(&shifted(-h), lambda, mu)?;
            let dz = self.difference_times(&kp, &km, 2.0 * h, &[vl, &p.z]);
            for (g, a) in gx.iter_mut().zip(&dz[0]) {
                *g -= a / k;
            }
            if l < nb {
                for (hv, a) in hx[l].iter_mut().zip(&dz[1]) {
                    *hv -= a;
                }
            }
        }
        let constant = self.member_at(mu)?.load_derivative_is_constant();
        if constant {
            return Some(Rows {
                gx,
                hx,
                gl: 0.0,
                hl: vec![0.0; nb],
            });
        }
        let d = STEP * (1.0 + lambda.abs());
        let (kp, km) = (self.k_at(x, lambda + d, mu)?, self.k_at(x, lambda - d, mu)?);
        let mut s = vec![0.0; n];
        if nb > 0 {
            let (rp, rm) = (
                self.rl_at(x, lambda + d, mu)?,
                self.rl_at(x, lambda - d, mu)?,
            );
            s = rp
                .iter()
                .zip(&rm)
                .map(|(a, b)| (a - b) / (2.0 * d))
                .collect();
        }
        let (gl, hl) = self.parameter_terms(p, &kp, &km, 2.0 * d, &s);
        let vs: Vec<&[f64]> = p.v.iter().take(nb).map(Vec::as_slice).collect();
        let kv = self.difference_times(&kp, &km, 2.0 * d, &vs);
        for (row, add) in hx.iter_mut().zip(kv) {
            row.iter_mut().zip(add).for_each(|(a, b)| *a += b);
        }
        Some(Rows { gx, hx, gl, hl })
    }

    /// Fills the extended residual from the member's residual `r`, the multipliers `β` of
    /// `xe` and the test functions of `p`.
    fn fill_residual(&self, xe: &[f64], r: &[f64], p: &Point, out: &mut [f64]) {
        let (n, np, nb) = (self.n, self.np, self.nb());
        for i in 0..n {
            let along: f64 = (0..nb).map(|l| self.borders[l][i] * xe[n + 1 + l]).sum();
            out[ext(i, np)] = r[i] + along;
        }
        out[np] = p.g;
        for l in 0..nb {
            out[n + 1 + l] = p.h[l];
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
        self.n + 1 + self.nb()
    }

    fn primal_unknowns(&self) -> usize {
        self.np + 1
    }

    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    fn residual(&mut self, xe: &[f64], mu: f64, out: &mut [f64]) -> f64 {
        let (x, lambda) = self.split(xe);
        let Some(p) = self.point(&x, lambda, mu) else {
            return Self::refuse(out);
        };
        let mut r = vec![0.0; self.n];
        let Some(member) = self.member_at(mu) else {
            return Self::refuse(out);
        };
        let energy = member.residual(&x, lambda, &mut r);
        self.fill_residual(xe, &r, &p, out);
        energy
    }

    fn jacobian(&mut self, xe: &[f64], mu: f64, out: &mut [f64], jac: &mut [f64]) -> f64 {
        let (x, lambda) = self.split(xe);
        let p = self.point(&x, lambda, mu);
        let k = self.k_at(&x, lambda, mu);
        let rows = p.as_ref().and_then(|p| self.rows(&x, lambda, mu, p));
        let rl = self.rl_at(&x, lambda, mu);
        let mut r = vec![0.0; self.n];
        let (Some(p), Some(k), Some(rows), Some(rl), Some(member)) =
            (p, k, rows, rl, self.member_at(mu))
        else {
            jac.fill(0.0);
            return Self::refuse(out);
        };
        let energy = member.residual(&x, lambda, &mut r);
        for (value, source) in jac.iter_mut().zip(&self.sources) {
            *value = match *source {
                Source::K(e) => k[e],
                Source::Gx(j) => rows.gx[j],
                Source::Rl(i) => rl[i],
                Source::Gl => rows.gl,
                Source::B(l, i) => self.borders[l][i],
                Source::Hx(l, j) => rows.hx[l][j],
                Source::Hl(l) => rows.hl[l],
            };
        }
        self.fill_residual(xe, &r, &p, out);
        energy
    }

    fn residual_weights(&self, weights: &mut [f64]) {
        let (n, np) = (self.n, self.np);
        let mut w = vec![1.0; n];
        if let Some(c) = self.members.back() {
            c.member.residual_weights(&mut w);
        }
        for i in 0..n {
            weights[ext(i, np)] = w[i];
        }
        weights[np] = 1.0 / self.g_scale;
        for wh in weights.iter_mut().skip(n + 1) {
            *wh = 1.0 / self.h_scale;
        }
    }

    fn load_derivative(&mut self, xe: &[f64], mu: f64, out: &mut [f64]) {
        out.fill(0.0);
        let (x, lambda) = self.split(xe);
        let h = self.family.step(mu);
        let (n, np, nb) = (self.n, self.np, self.nb());
        let Some(p) = self.point(&x, lambda, mu) else {
            return;
        };
        let (Some(kp), Some(km)) = (self.k_at(&x, lambda, mu + h), self.k_at(&x, lambda, mu - h))
        else {
            return;
        };
        let mut rp = vec![0.0; n];
        let mut rm = vec![0.0; n];
        if let Some(m) = self.member_at(mu + h) {
            m.residual(&x, lambda, &mut rp);
        }
        if let Some(m) = self.member_at(mu - h) {
            m.residual(&x, lambda, &mut rm);
        }
        let mut s = vec![0.0; n];
        if nb > 0 {
            if let (Some(a), Some(b)) = (
                self.rl_at(&x, lambda, mu + h),
                self.rl_at(&x, lambda, mu - h),
            ) {
                s = a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect();
            }
        }
        for i in 0..n {
            out[ext(i, np)] = (rp[i] - rm[i]) / (2.0 * h);
        }
        let (g, hs) = self.parameter_terms(&p, &kp, &km, 2.0 * h, &s);
        out[np] = g;
        for (l, v) in hs.into_iter().enumerate() {
            out[n + 1 + l] = v;
        }
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

    fn out_of_domain(&self, xe: &[f64]) -> Option<&'static str> {
        let (x, _) = self.split(xe);
        self.members.back().and_then(|c| c.member.out_of_domain(&x))
    }

    /// At a converged point the borders become its null vectors (orthonormalised), which
    /// keeps the bordered matrix well conditioned as the point moves (as MATCONT does).
    fn restore(&mut self, xe: &[f64], mu: f64) {
        let (x, lambda) = self.split(xe);
        if let Some(p) = self.point(&x, lambda, mu) {
            let fresh = orthonormal(p.v, self.np);
            if fresh.len() == self.borders.len() && fresh.iter().flatten().all(|a| a.is_finite()) {
                self.borders = fresh;
            }
        }
        if let Some(m) = self.member_at(mu) {
            m.restore(&x, lambda);
        }
    }
}

/// A member of the family, its key (`μ`'s bits), and where its Jacobian's entries sit in
/// the start's pattern (`None`: the same pattern).
struct Cached<M> {
    key: u64,
    member: M,
    map: Option<Vec<usize>>,
}
