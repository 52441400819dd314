//! The numeric factorisation of `K_ρδ − σM` for the matrices of one [`KktStructure`], the
//! count of the signs of its pivots (the inertia), and the solves refined against the
//! unregularised matrix that Newton's method and inverse iteration use.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{supernodal::SupernodalLdltRef, LdltRef, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};
use std::sync::Arc;

use super::structure::{InertiaError, KktStructure};
use crate::solver::ldl::Scalar;

/// Counts of the signs of the pivots of `K_ρδ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inertia {
    pub positive: usize,
    pub negative: usize,
}

/// The factorisations of the matrices of one [`KktStructure`] (`LDLᵀ`, `LDLᴴ` for complex
/// entries), their inertia and the eigenvalue searches on them (in `eigen.rs`), with the
/// workspace and warm starts of those searches.
pub struct InertiaCounter<T: Scalar = f64> {
    pub(super) structure: Arc<KktStructure>,
    values: Vec<T>,
    /// The KKT values `loaded` and their `JᴴJ`, in the augmented pattern.
    base: Vec<T>,
    gram: Vec<T>,
    loaded: Vec<T>,
    l_values: Vec<T>,
    /// Scratch of the simplicial factorisation: a dense column (kept zero) and the
    /// inverted pivots.
    work: Vec<T>,
    inverse_pivot: Vec<f64>,
    /// Penalty of the last factorisation: the mean magnitude of the Hessian's diagonal.
    pub rho: f64,
    /// The last mode found by inverse iteration (primal unknowns), to start the next search
    /// from; empty until one is found.
    pub(super) last_mode: Vec<T>,
    /// The last lowest eigenvalues found (oldest first, at most four), to place the next
    /// shift just below the lowest eigenvalue they extrapolate to.
    pub(super) lowest_history: Vec<f64>,
    /// The last mode nearest zero found (critical-point searches).
    pub(super) nearest_zero_mode: Vec<T>,
    /// Whether the last inverse iteration met its tolerance.
    pub(super) converged: bool,
    /// Scratch of inverse iteration: right-hand side, solution and refinement residual (all
    /// unknowns), iterate and Hessian product (primal unknowns).
    pub(super) rhs: Vec<T>,
    pub(super) solution: Vec<T>,
    refinement: Vec<T>,
    /// A solve's right-hand side in the stored ordering.
    permuted: Vec<T>,
    /// A mode (primal unknowns, unit norm in the metric) that inverse iteration keeps its
    /// iterates orthogonal to; empty for none.
    pub(super) deflation: Vec<T>,
    pub(super) iterate: Vec<T>,
    pub(super) product: Vec<T>,
    /// Modes held out of the metric ([`InertiaCounter::hold_modes`]).
    pub(super) held: HeldModes<T>,
    buffer: MemBuffer,
}

/// Neutral modes `t_j` of the constrained Hessian (rigid motions) that a gauge row holds at
/// a point, taken out of the eigenproblem's metric: `M' = M − W Wᵀ`, `W = M T̃` with `T̃`
/// the modes made orthonormal in `M`.
///
/// The eigenproblem of a state with a neutral mode `t` (`Ht` orthogonal to the constraints'
/// tangent space) is posed on the modes `M`-orthogonal to `t`, the other eigenvectors.
/// A gauge row `c·u = 0` at a point poses it on another space, `c·u = 0`; the map
/// `u ↦ u − t (tᵀMu)/(tᵀMt)` carries that space onto the first with the energy unchanged and
/// the metric `M` becoming `M'`. So the point-held pencil `(H, M')` has the eigenvalues of
/// the `M`-orthogonal one, where `(H, M)` shifts them (by 1e-4 of the lowest eigenvalue of
/// a tube cell held against turning about its axis). `M'` is `M` less a matrix of rank
/// `k`: `K − σM'` is the factorised `B = K_ρδ − σM` plus `σ W Wᵀ`, whose inertia is
/// `In(B) + In(S) − In(−I/σ)` with `S = −I/σ − Wᵀ B⁻¹ W` (Haynsworth), and whose solves
/// are `B`'s corrected by Woodbury's identity — `k` more solves per factorisation.
pub(super) struct HeldModes<T> {
    /// The columns of `W` (primal unknowns).
    pub(super) w: Vec<Vec<f64>>,
    /// The shift of the last factorisation (the correction is off at 0).
    sigma: f64,
    /// `B⁻¹ W` (all unknowns) and the `LDLᴴ` of `S` (`k × k`, row-major: `L` below the
    /// diagonal, `D` on it), at the last factorisation.
    z: Vec<Vec<T>>,
    s: Vec<T>,
}

impl<T> Default for HeldModes<T> {
    fn default() -> Self {
        HeldModes {
            w: Vec::new(),
            sigma: 0.0,
            z: Vec::new(),
            s: Vec::new(),
        }
    }
}

impl<T: Scalar> InertiaCounter<T> {
    /// A counter for a KKT matrix of pattern `k` (see [`KktStructure::new`]).
    pub fn new(
        k: &SymbolicSparseColMat<usize>,
        metric: &[f64],
        length: f64,
    ) -> Result<InertiaCounter<T>, InertiaError> {
        InertiaCounter::with_structure(Arc::new(KktStructure::new(k, metric, length)?))
    }

    /// A counter for the matrices of `structure`: the numeric factor and the workspace of
    /// the searches.
    pub fn with_structure(structure: Arc<KktStructure>) -> Result<InertiaCounter<T>, InertiaError> {
        let par = Par::Seq;
        let symbolic = &structure.symbolic;
        let req = symbolic
            .factorize_numeric_ldlt_scratch::<T>(par, Default::default())
            .or(symbolic.solve_in_place_scratch::<T>(1, par));
        let buffer = MemBuffer::try_new(req).map_err(|_| InertiaError::OutOfMemory)?;
        let (n, n_primal) = (structure.pattern.ncols(), structure.primal_diagonal.len());
        let stored = structure.pattern.row_idx().len();
        Ok(InertiaCounter {
            values: vec![T::from_real(0.0); stored],
            base: vec![T::from_real(0.0); stored],
            gram: vec![T::from_real(0.0); stored],
            loaded: Vec::new(),
            rho: 1.0,
            last_mode: Vec::new(),
            lowest_history: Vec::new(),
            nearest_zero_mode: Vec::new(),
            converged: false,
            rhs: vec![T::from_real(0.0); n],
            solution: vec![T::from_real(0.0); n],
            refinement: vec![T::from_real(0.0); n],
            permuted: vec![T::from_real(0.0); n],
            deflation: Vec::new(),
            iterate: vec![T::from_real(0.0); n_primal],
            product: vec![T::from_real(0.0); n_primal],
            l_values: vec![T::from_real(0.0); symbolic.len_val()],
            work: vec![T::from_real(0.0); n],
            held: HeldModes::default(),
            inverse_pivot: vec![0.0; n],
            structure,
            buffer,
        })
    }

    /// Mean magnitude of the diagonal of the Hessian block of the KKT values `kkt`.
    pub fn hessian_scale(&self, kkt: &[T]) -> f64 {
        let nz: Vec<f64> = self
            .structure
            .k_diagonal
            .iter()
            .map(|&p| kkt[p].real_part().abs())
            .filter(|&v| v > 0.0)
            .collect();
        if nz.is_empty() {
            1.0
        } else {
            nz.iter().sum::<f64>() / nz.len() as f64
        }
    }

    /// Factorises `K_ρδ − σ M` built from the KKT values `kkt` (in the system's pattern),
    /// with `M = diag(metric)` on the primal unknowns, and counts the signs of its pivots:
    /// the negative directions it reports are the eigenvalues of the constrained pencil
    /// `(H, M)` below `σ`.
    pub fn inertia(
        &mut self,
        kkt: &[T],
        sigma: f64,
        metric: &[f64],
    ) -> Result<Inertia, InertiaError> {
        let inertia = self.factorize_shifted(kkt, |i| sigma * metric[i])?;
        self.held_inertia(inertia, sigma)
    }

    /// Takes the neutral modes `modes` (primal unknowns; none to take none) out of the
    /// metric `metric` of the following factorisations and searches ([`HeldModes`]).
    pub fn hold_modes(&mut self, metric: &[f64], modes: &[Vec<f64>]) {
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for t in modes {
            // Gram–Schmidt in the metric
            let mut t = t.clone();
            for b in &basis {
                let c: f64 = (0..t.len()).map(|i| metric[i] * t[i] * b[i]).sum();
                t.iter_mut().zip(b).for_each(|(ti, bi)| *ti -= c * bi);
            }
            let norm = (0..t.len())
                .map(|i| metric[i] * t[i] * t[i])
                .sum::<f64>()
                .sqrt();
            if norm > 0.0 && norm.is_finite() {
                basis.push(t.iter().map(|ti| ti / norm).collect());
            }
        }
        self.held = HeldModes {
            w: basis
                .iter()
                .map(|t| t.iter().zip(metric).map(|(ti, m)| m * ti).collect())
                .collect(),
            ..HeldModes::default()
        };
    }

    /// The inertia of `K_ρδ − σM'` from that of the factorised `K_ρδ − σM`, `inertia`
    /// ([`HeldModes`]), keeping what the corrected solves need.
    fn held_inertia(&mut self, mut inertia: Inertia, sigma: f64) -> Result<Inertia, InertiaError> {
        let k = self.held.w.len();
        self.held.sigma = sigma;
        if k == 0 || sigma == 0.0 {
            return Ok(inertia);
        }
        let n = self.rhs.len();
        let mut z = std::mem::take(&mut self.held.z);
        z.resize_with(k, Vec::new);
        for (j, zj) in z.iter_mut().enumerate() {
            zj.clear();
            zj.extend(self.held.w[j].iter().map(|&w| T::from_real(w)));
            zj.resize(n, T::from_real(0.0));
            self.ldlt_solve(zj);
        }
        // S = −I/σ − Wᵀ B⁻¹ W, factorised LDLᴴ without pivoting (k is 1 to 3)
        let mut s = vec![T::from_real(0.0); k * k];
        for i in 0..k {
            for j in 0..k {
                let mut v = T::from_real(if i == j { -1.0 / sigma } else { 0.0 });
                for (p, &w) in self.held.w[i].iter().enumerate() {
                    v -= T::from_real(w) * z[j][p];
                }
                s[i * k + j] = v;
            }
        }
        for j in 0..k {
            for p in 0..j {
                let l = s[j * k + p];
                let d = s[p * k + p];
                s[j * k + j] -= l * l.conjugate() * d;
            }
            let d = s[j * k + j].real_part();
            if !d.is_finite() || d == 0.0 {
                return Err(InertiaError::ZeroPivot);
            }
            for i in j + 1..k {
                let mut v = s[i * k + j];
                for p in 0..j {
                    v -= s[i * k + p] * s[j * k + p].conjugate() * s[p * k + p];
                }
                s[i * k + j] = v.div_real(d);
            }
            s[j * k + j] = T::from_real(d);
        }
        let negative = (0..k).filter(|&j| s[j * k + j].real_part() < 0.0).count();
        // In(−I/σ): k negative for σ > 0, k positive for σ < 0
        let (neg_ref, pos_ref) = if sigma > 0.0 { (k, 0) } else { (0, k) };
        inertia.negative = (inertia.negative + negative)
            .checked_sub(neg_ref)
            .ok_or(InertiaError::ZeroPivot)?;
        inertia.positive = (inertia.positive + (k - negative))
            .checked_sub(pos_ref)
            .ok_or(InertiaError::ZeroPivot)?;
        self.held.z = z;
        self.held.s = s;
        Ok(inertia)
    }

    /// `B⁻¹ x` corrected for the held modes by Woodbury's identity:
    /// `(B + σWWᵀ)⁻¹ x = y + Z S⁻¹ Wᵀy`, `y = B⁻¹x`, `Z = B⁻¹W`.
    fn held_solve(&mut self, x: &mut [T]) {
        self.ldlt_solve(x);
        let held = &self.held;
        let k = held.w.len();
        if k == 0 || held.sigma == 0.0 {
            return;
        }
        let mut c: Vec<T> = held
            .w
            .iter()
            .map(|w| {
                w.iter()
                    .zip(x.iter())
                    .fold(T::from_real(0.0), |a, (&wi, &xi)| a + T::from_real(wi) * xi)
            })
            .collect();
        // S c' = c by its LDLᴴ
        let s = &held.s;
        for i in 0..k {
            for p in 0..i {
                let l = s[i * k + p];
                let cp = c[p];
                c[i] -= l * cp;
            }
        }
        for (i, ci) in c.iter_mut().enumerate() {
            *ci = ci.div_real(s[i * k + i].real_part());
        }
        for i in (0..k).rev() {
            for p in i + 1..k {
                let l = s[p * k + i].conjugate();
                let cp = c[p];
                c[i] -= l * cp;
            }
        }
        for (zj, &cj) in held.z.iter().zip(&c) {
            for (xi, &zi) in x.iter_mut().zip(zj) {
                *xi += zi * cj;
            }
        }
    }

    /// `M'u` (`u` primal) into `out` ([`HeldModes`]).
    pub(super) fn metric_times(&self, metric: &[f64], u: &[T], out: &mut [T]) {
        for i in 0..u.len() {
            out[i] = T::from_real(metric[i]) * u[i];
        }
        for w in &self.held.w {
            let c = held_dot(w, u);
            for (o, &wi) in out.iter_mut().zip(w) {
                *o -= T::from_real(wi) * c;
            }
        }
    }

    /// `uᴴM'u` from `uᴴMu` = `plain` ([`HeldModes`]).
    pub(super) fn held_norm2(&self, plain: f64, u: &[T]) -> f64 {
        plain
            - self
                .held
                .w
                .iter()
                .map(|w| held_dot(w, u).abs2())
                .sum::<f64>()
    }

    /// `fᴴM'v` from `fᴴMv` = `plain` ([`HeldModes`]).
    pub(super) fn held_inner(&self, plain: T, f: &[T], v: &[T]) -> T {
        self.held.w.iter().fold(plain, |a, w| {
            a - held_dot(w, v) * held_dot(w, f).conjugate()
        })
    }

    /// Factorises `K_ρδ − S` with `S = diag(shift(i))` on the primal unknowns and returns
    /// its inertia (see [`InertiaCounter::inertia`]).
    fn factorize_shifted(
        &mut self,
        kkt: &[T],
        shift: impl Fn(usize) -> f64,
    ) -> Result<Inertia, InertiaError> {
        if self.loaded.as_slice() != kkt {
            self.load(kkt);
        }
        // the shifted Hessian's diagonal, and the penalty scaled to it
        let shifted = |base: &[T], i: usize, s: usize| base[s] - T::from_real(shift(i));
        let (mut diag, mut count) = (0.0, 0);
        for (i, &s) in self.structure.primal_diagonal.iter().enumerate() {
            let v = shifted(&self.base, i, s).real_part().abs();
            if v > 0.0 {
                diag += v;
                count += 1;
            }
        }
        let rho = if count > 0 { diag / count as f64 } else { 1.0 };
        self.rho = rho;
        // K_ρδ − σM in one pass over the stored entries, then its diagonal
        let r = T::from_real(rho);
        for ((v, &b), &g) in self.values.iter_mut().zip(&self.base).zip(&self.gram) {
            *v = b + r * g;
        }
        for (i, &s) in self.structure.primal_diagonal.iter().enumerate() {
            self.values[s] = shifted(&self.base, i, s) + r * self.gram[s];
        }
        for (i, &s) in self.structure.dual_diagonal.iter().enumerate() {
            self.values[s] = T::from_real(-self.delta(i));
        }
        self.factorize_values()?;
        self.pivot_inertia()
    }

    /// The numeric `LDLᵀ` of the stored values, simplicial or supernodal as the structure
    /// says.
    fn factorize_values(&mut self) -> Result<(), InertiaError> {
        let st = &*self.structure;
        if let Some(reach) = &st.reach {
            reach
                .factorize(
                    st.pattern.col_ptr(),
                    st.pattern.row_idx(),
                    &self.values,
                    &mut self.l_values,
                    &mut self.work,
                    &mut self.inverse_pivot,
                )
                .map_err(|_| InertiaError::ZeroPivot)?;
        } else {
            let a = SparseColMatRef::new(st.pattern.as_ref(), &self.values);
            st.symbolic
                .factorize_numeric_ldlt(
                    &mut self.l_values,
                    a,
                    Side::Upper,
                    LdltRegularization::default(),
                    Par::Seq,
                    MemStack::new(&mut self.buffer),
                    Default::default(),
                )
                .map_err(|_| InertiaError::ZeroPivot)?;
        }
        Ok(())
    }

    /// The inertia of the last factorisation: the signs of the pivots of `D`, an error for a
    /// zero or non-finite one.
    fn pivot_inertia(&self) -> Result<Inertia, InertiaError> {
        let mut inertia = Inertia {
            positive: 0,
            negative: 0,
        };
        let mut count = |d: f64| {
            if !d.is_finite() || d == 0.0 {
                return Err(InertiaError::ZeroPivot);
            }
            if d < 0.0 {
                inertia.negative += 1;
            } else {
                inertia.positive += 1;
            }
            Ok(())
        };
        match self.structure.symbolic.raw() {
            // simplicial, as `KktStructure::new` asks: `D` is stored on the diagonal of the
            // unit lower factor, first in each column
            SymbolicCholeskyRaw::Simplicial(s) => {
                for &start in &s.col_ptr()[..s.ncols()] {
                    count(self.l_values[start].real_part())?;
                }
            }
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let l = SupernodalLdltRef::new(sn, &self.l_values);
                for s in 0..sn.n_supernodes() {
                    let m = l.supernode(s).val();
                    for j in 0..m.ncols() {
                        count(m[(j, j)].real_part())?;
                    }
                }
            }
        }
        Ok(inertia)
    }

    /// The regularisation `δ c_i` of constraint row `i` at the last penalty `ρ`.
    fn delta(&self, i: usize) -> f64 {
        REGULARISATION * self.structure.row_scale[i] / self.rho
    }

    /// Scatters the KKT values `kkt` into `self.base` and their `JᴴC⁻¹J` into `self.gram`
    /// (in the augmented pattern), and keeps `kkt` to know when the next factorisation
    /// can start from them.
    fn load(&mut self, kkt: &[T]) {
        let zero = T::from_real(0.0);
        self.base.iter_mut().for_each(|v| *v = zero);
        self.gram.iter_mut().for_each(|v| *v = zero);
        for (p, &s) in self.structure.k_slots.iter().enumerate() {
            if s != usize::MAX {
                self.base[s] += kkt[p];
            }
        }
        let st = &*self.structure;
        for (i, range) in st.jtj_rows.windows(2).enumerate() {
            let w = T::from_real(1.0 / st.row_scale[i]);
            for &(a, b, s) in &st.jtj[range[0]..range[1]] {
                self.gram[s as usize] += kkt[a as usize].conjugate() * kkt[b as usize] * w;
            }
        }
        self.loaded.clear();
        self.loaded.extend_from_slice(kkt);
    }

    /// Negative directions of the constrained Hessian: negative pivots less constraints.
    pub fn unstable_directions(&self, inertia: Inertia) -> isize {
        inertia.negative as isize - self.structure.constraints as isize
    }
}

impl InertiaCounter<f64> {
    /// Factorises the KKT matrix `kkt` itself (regularised, unshifted) for
    /// [`InertiaCounter::solve_kkt`], and returns its inertia.
    pub fn factorize_kkt(&mut self, kkt: &[f64]) -> Result<Inertia, InertiaError> {
        self.factorize_shifted(kkt, |_| 0.0)
    }

    /// Solves `K z = b` for any `b` (constraint rows included) with the factorisation of
    /// [`InertiaCounter::factorize_kkt`]: the constraint part `g` of `b` enters the primal
    /// one as `ρ JᵀC⁻¹g`, so that the unregularised `K_ρ0` has the solution of `K`, and the
    /// solve is refined against `K_ρ0` to rounding (at most `refinements` corrections).
    pub fn solve_kkt(&mut self, b: &[f64], z: &mut [f64], refinements: usize) {
        let s = &*self.structure;
        let n_primal = s.primal_diagonal.len();
        self.rhs.copy_from_slice(b);
        for &(p, col, i, w) in &s.j_entries {
            let g = b[n_primal + i as usize];
            self.rhs[col as usize] += self.rho * self.loaded[p as usize] * g * w;
        }
        self.solve_refined(n_primal, refinements);
        z.copy_from_slice(&self.solution);
    }
}

impl<T: Scalar> InertiaCounter<T> {
    /// Solves `K(σ) z = b` with the last factorisation, for `b` in `self.rhs` whose
    /// constraint part is zero (or carried into the primal one, [`InertiaCounter::solve_kkt`]),
    /// into `self.solution`, refining up to `refinements` times (until the correction is at
    /// rounding) against the unregularised `K_ρ0(σ)` (which has the same solution as `K(σ)`
    /// for such `b`).
    pub(super) fn solve_refined(&mut self, n_primal: usize, refinements: usize) {
        let n = self.rhs.len();
        let mut z = std::mem::take(&mut self.solution);
        let mut r = std::mem::take(&mut self.refinement);
        z.copy_from_slice(&self.rhs);
        self.held_solve(&mut z);
        for _ in 0..refinements {
            // r = b − K_ρ0 z, K_ρ0 = stored values with the dual diagonal −δ removed
            r.copy_from_slice(&self.rhs);
            let s = &self.structure;
            let (cp, ri) = (s.pattern.col_ptr(), s.pattern.row_idx());
            for col in 0..n {
                let j = s.perm[col];
                for p in cp[col]..cp[col + 1] {
                    // the stored upper triangle and its mirror image (Hermitian)
                    let (i, v) = (s.perm[ri[p]], self.values[p]);
                    r[i] -= v * z[j];
                    if i != j {
                        r[j] -= v.conjugate() * z[i];
                    }
                }
            }
            for i in n_primal..n {
                r[i] -= T::from_real(self.delta(i - n_primal)) * z[i];
            }
            if self.held.sigma != 0.0 {
                // the held modes' part σ W Wᵀ z
                for w in &self.held.w {
                    let c = T::from_real(self.held.sigma) * held_dot(w, &z);
                    for (ri, &wi) in r.iter_mut().zip(w) {
                        *ri -= T::from_real(wi) * c;
                    }
                }
            }
            self.held_solve(&mut r);
            let mut correction: f64 = 0.0;
            let mut size: f64 = 0.0;
            for (zi, &ri) in z.iter_mut().zip(&r) {
                *zi += ri;
                correction = correction.max(ri.abs2());
                size = size.max(zi.abs2());
            }
            // converged to rounding: further steps change nothing
            if correction.sqrt() <= 1e-15 * size.sqrt() {
                break;
            }
        }
        self.solution = z;
        self.refinement = r;
    }

    /// Solves with the last factorisation in place, through the stored ordering.
    fn ldlt_solve(&mut self, x: &mut [T]) {
        let n = x.len();
        let perm = &self.structure.perm;
        let y = &mut self.permuted;
        for (yi, &from) in y.iter_mut().zip(perm) {
            *yi = x[from];
        }
        match &self.structure.reach {
            Some(reach) => reach.solve_in_place(&self.l_values, &self.inverse_pivot, y),
            None => LdltRef::new(&self.structure.symbolic, &self.l_values)
                .solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(y, n, 1),
                    Par::Seq,
                    MemStack::new(&mut self.buffer),
                ),
        }
        for (&yi, &to) in y.iter().zip(perm) {
            x[to] = yi;
        }
    }
}

/// `wᵀv` over `w`'s (primal) unknowns.
fn held_dot<T: Scalar>(w: &[f64], v: &[T]) -> T {
    w.iter()
        .zip(v)
        .fold(T::from_real(0.0), |a, (&wi, &vi)| a + T::from_real(wi) * vi)
}

/// `δρ`: the regularisation of the constraint rows relative to the Hessian (rows in their
/// norms `c_i`). Weaker, the solves' constraint residual grows (it enters the eigenvalues'
/// Lagrangian Rayleigh quotient to second order); stronger, rounding grows: the thesis
/// n = 1 lowest eigenvalue at ε = 0.5 is within 3e-12 of a dense solve at 1e-6, 4e-10 at
/// 1e-7, 6e-8 at 1e-8 and 3e-4 at 1e-10.
const REGULARISATION: f64 = 1e-8;
