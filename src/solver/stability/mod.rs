//! Stability of an equilibrium from the inertia of its KKT matrix, by a sparse `LDLᵀ`
//! (DESIGN.md §5, "Stability"), and the eigenvalues that place its critical points.
//!
//! An equilibrium is stable when the Hessian `H` of the Lagrangian is positive definite on
//! the tangent space `J v = 0` of the constraints. The KKT matrix `K = [[H, Jᵀ], [J, 0]]`
//! has inertia `(p, m + q, z)` where `q` is the number of negative directions of `Zᵀ H Z`
//! and `m` the number of (independent) constraints. `K` has zero diagonal entries, so it is
//! factorised in the augmented, regularised form
//!
//! `K_ρδ = [[H + ρ JᵀC⁻¹J, Jᵀ], [J, −δ C]]`,
//!
//! whose inertia equals `inertia(H + (ρ + 1/δ) JᵀC⁻¹J) + (0, m, 0)`; for a large penalty
//! `ρ + 1/δ` the first term counts `q` negative directions (Sylvester's law of inertia and
//! Debreu's lemma). The matrix is quasi-definite at stable states, so a symmetric `LDLᵀ`
//! without pivoting exists for any fill-reducing ordering.
//!
//! `C = diag(c_i)` makes the regularisation free of units: some constraints are on
//! rotations only (unit quaternions, rotational supports: dimensionless), the others on
//! positions (inextensibility, joints, positional supports: m), so `c_i = 1` for the
//! first and `c_i = ℓ²` for the second, `ℓ` the rod length. With `ρ` the Hessian's mean
//! diagonal and `δ = 10⁻⁸/ρ`, a change of units (lengths ×s, stiffnesses ×s²) scales
//! `K_ρδ` symmetrically and leaves counts and eigenvalues as they are (a penalty `δ I`
//! in metres would be 10⁶ times weaker in millimetres).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLdltRef, CholeskySymbolicParams, LdltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::{amd, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use super::ldl::RowReach;
pub use super::ldl::Scalar;
use std::sync::{Arc, OnceLock};

/// Counts of the signs of the pivots of `K_ρδ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inertia {
    pub positive: usize,
    pub negative: usize,
}

/// Why the inertia could not be computed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum InertiaError {
    #[error("zero pivot in the LDLᵀ of the KKT matrix (a singular or critical state)")]
    ZeroPivot,
    #[error("out of memory in the LDLᵀ factorisation")]
    OutOfMemory,
}

/// The augmented KKT pattern of one [`System`], its symbolic `LDLᵀ` and value maps: what
/// every matrix of that pattern shares (the Bloch blocks of one sector, real and complex,
/// on every thread), built once.
pub struct KktStructure {
    /// Number of constraint rows.
    pub constraints: usize,
    /// The fill-reducing ordering: unknown `perm[i]` of the KKT matrix is unknown `i` of
    /// the stored matrix.
    perm: Vec<usize>,
    /// The upper triangle of the permuted augmented pattern.
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// The rows' reach of a simplicial factor, for the numeric factorisations (faer's
    /// own for a supernodal one).
    reach: Option<RowReach>,
    /// For each stored entry of `K`, its slot in the augmented pattern (`usize::MAX` for
    /// an entry of the lower triangle, which is not stored).
    k_slots: Vec<usize>,
    /// For each stored entry of `K`, its (row, column).
    k_entry: Vec<(usize, usize)>,
    /// The entries of `J` among them: (index into K's values, column, constraint row),
    /// with the row's `1/c_i` (the constraint part of a right-hand side enters the primal
    /// one through them).
    j_entries: Vec<(u32, u32, u32, f64)>,
    /// Products `(k value a, k value b, slot)` making `JᴴC⁻¹J`: `conj(a) b / c_i` into
    /// `slot`, those of constraint row `i` at `jtj[jtj_rows[i]..jtj_rows[i + 1]]` (indices
    /// as `u32`: the loop that forms them is bound by memory traffic).
    jtj: Vec<(u32, u32, u32)>,
    jtj_rows: Vec<usize>,
    /// The regularisation's `C`: `c_i = ℓ²` for a constraint row `i` on positions, 1 for
    /// one on rotations only.
    row_scale: Vec<f64>,
    /// Slots of the dual diagonal.
    dual_diagonal: Vec<usize>,
    /// Slots of the primal diagonal.
    primal_diagonal: Vec<usize>,
    /// Indices of the primal diagonal in the KKT values.
    k_diagonal: Vec<usize>,
}

/// The factorisations of the matrices of one [`KktStructure`] (`LDLᵀ`, `LDLᴴ` for complex
/// entries), their inertia and the eigenvalue searches on them.
pub struct InertiaCounter<T: Scalar = f64> {
    structure: Arc<KktStructure>,
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
    last_mode: Vec<T>,
    /// The last lowest eigenvalues found (oldest first, at most four), to place the next
    /// shift just below the lowest eigenvalue they extrapolate to.
    lowest_history: Vec<f64>,
    /// The last mode nearest zero found (critical-point searches).
    nearest_zero_mode: Vec<T>,
    /// Whether the last inverse iteration met its tolerance.
    converged: bool,
    /// Scratch of inverse iteration: right-hand side, solution and refinement residual (all
    /// unknowns), iterate and Hessian product (primal unknowns).
    rhs: Vec<T>,
    solution: Vec<T>,
    refinement: Vec<T>,
    /// A solve's right-hand side in the stored ordering.
    permuted: Vec<T>,
    /// A mode (primal unknowns, unit norm in the metric) that inverse iteration keeps its
    /// iterates orthogonal to; empty for none.
    deflation: Vec<T>,
    iterate: Vec<T>,
    product: Vec<T>,
    buffer: MemBuffer,
}

fn slot(pattern: &SymbolicSparseColMat<usize>, row: usize, col: usize) -> usize {
    let cp = pattern.col_ptr();
    let rows = &pattern.row_idx()[cp[col]..cp[col + 1]];
    cp[col]
        + rows
            .binary_search(&row)
            .expect("entry in the augmented pattern")
}

impl KktStructure {
    /// Builds the augmented pattern and its symbolic factorisation for a KKT matrix of
    /// pattern `k` whose first `n_primal` unknowns are primal, with the eigenproblem's
    /// metric over them (positive on quaternion unknowns, zero on positions) and the length
    /// `ℓ` (m) that weighs positions in the row norms of the regularisation.
    pub fn new(
        k: &SymbolicSparseColMat<usize>,
        metric: &[f64],
        length: f64,
    ) -> Result<KktStructure, InertiaError> {
        let n_primal = metric.len();
        let n = k.ncols();
        let (cp, ri) = (k.col_ptr(), k.row_idx());
        // constraint rows of J: (column, index into K's values), from the lower-left block
        let mut rows: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n - n_primal];
        for col in 0..n_primal {
            for p in cp[col]..cp[col + 1] {
                if ri[p] >= n_primal {
                    rows[ri[p] - n_primal].push((col, p));
                }
            }
        }
        // the augmented pattern column by column: K's rows and those of every column that
        // shares a constraint row with it (JᵀJ), each once (a marker per column), sorted
        let mut rows_of_column: Vec<Vec<usize>> = vec![Vec::new(); n_primal];
        for (i, r) in rows.iter().enumerate() {
            for &(col, _) in r {
                rows_of_column[col].push(i);
            }
        }
        let mut marker = vec![usize::MAX; n];
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        let mut column = Vec::new();
        for col in 0..n {
            column.clear();
            let mut add = |row: usize, column: &mut Vec<usize>| {
                if marker[row] != col {
                    marker[row] = col;
                    column.push(row);
                }
            };
            for &row in &ri[cp[col]..cp[col + 1]] {
                add(row, &mut column);
            }
            if col < n_primal {
                for &i in &rows_of_column[col] {
                    for &(row, _) in &rows[i] {
                        add(row, &mut column);
                    }
                }
            }
            column.sort_unstable();
            row_idx.extend_from_slice(&column);
            col_ptr.push(row_idx.len());
        }
        let full = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        // the fill-reducing ordering, applied here once: the matrices are stored permuted
        // and as their upper triangle, the form the simplicial LDLᵀ factorises without a
        // copy (it would otherwise permute every matrix before factorising it). The
        // simplicial factorisation is the faster one on the patterns of a pair (its Bloch
        // blocks: thesis n = 8 cold 0.40 s → 0.36 s with it alone), the supernodal one on
        // large full models (n = 16 full model: 16.5e9 instructions against 25.1e9 for
        // the simplicial one)
        let threshold = if n <= SIMPLICIAL_MAX {
            SupernodalThreshold::FORCE_SIMPLICIAL
        } else {
            SupernodalThreshold::FORCE_SUPERNODAL
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: threshold,
            ..Default::default()
        };
        // the ordering alone (faer's symbolic factorisation with `SymmetricOrdering::Amd`
        // computes the same one, then a factorisation of the pattern it does not need)
        let mut perm = vec![0usize; n];
        let mut perm_inv = vec![0usize; n];
        let nnz = full.row_idx().len();
        let mut scratch = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<usize>(n, nnz))
            .map_err(|_| InertiaError::OutOfMemory)?;
        amd::order_maybe_unsorted(
            &mut perm,
            &mut perm_inv,
            full.as_ref(),
            amd::Control::default(),
            MemStack::new(&mut scratch),
        )
        .map_err(|_| InertiaError::OutOfMemory)?;
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); n];
        let (fcp, fri) = (full.col_ptr(), full.row_idx());
        for col in 0..n {
            for &row in &fri[fcp[col]..fcp[col + 1]] {
                let (r, c) = (perm_inv[row], perm_inv[col]);
                if r <= c {
                    columns[c].push(r);
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(fri.len() / 2 + n);
        col_ptr.push(0);
        for mut column in columns {
            column.sort_unstable();
            row_idx.extend_from_slice(&column);
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        // the slot of entry (row, col) of the unpermuted matrix, when it is in the stored
        // upper triangle of the permuted one
        let upper_slot = |row: usize, col: usize| {
            let (r, c) = (perm_inv[row], perm_inv[col]);
            (r <= c).then(|| slot(&pattern, r, c))
        };
        let mut k_slots = Vec::with_capacity(ri.len());
        let mut k_entry = Vec::with_capacity(ri.len());
        for col in 0..n {
            for p in cp[col]..cp[col + 1] {
                k_slots.push(upper_slot(ri[p], col).unwrap_or(usize::MAX));
                k_entry.push((ri[p], col));
            }
        }
        let index = |i: usize| u32::try_from(i).map_err(|_| InertiaError::OutOfMemory);
        let mut jtj = Vec::new();
        let mut jtj_rows = Vec::with_capacity(rows.len() + 1);
        jtj_rows.push(0);
        for r in &rows {
            for &(ca, pa) in r {
                for &(cb, pb) in r {
                    if let Some(s) = upper_slot(ca, cb) {
                        jtj.push((index(pa)?, index(pb)?, index(s)?));
                    }
                }
            }
            jtj_rows.push(jtj.len());
        }
        let row_scale: Vec<f64> = rows
            .iter()
            .map(|r| {
                if r.iter().any(|&(col, _)| metric[col] <= 0.0) {
                    length * length
                } else {
                    1.0
                }
            })
            .collect();
        let mut j_entries = Vec::new();
        for (p, &(row, col)) in k_entry.iter().enumerate() {
            if row >= n_primal && col < n_primal {
                let i = row - n_primal;
                j_entries.push((index(p)?, index(col)?, index(i)?, 1.0 / row_scale[i]));
            }
        }
        let diagonal = |i: usize| slot(&pattern, perm_inv[i], perm_inv[i]);
        let dual_diagonal = (n_primal..n).map(diagonal).collect();
        let primal_diagonal = (0..n_primal).map(diagonal).collect();
        let k_diagonal = (0..n_primal).map(|i| slot(k, i, i)).collect();
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            params,
        )
        .map_err(|_| InertiaError::OutOfMemory)?;
        let reach = match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => RowReach::new(s.col_ptr(), s.row_idx()),
            SymbolicCholeskyRaw::Supernodal(_) => None,
        };
        Ok(KktStructure {
            constraints: n - n_primal,
            perm,
            pattern,
            symbolic,
            reach,
            k_slots,
            j_entries,
            k_entry,
            jtj,
            jtj_rows,
            row_scale,
            dual_diagonal,
            primal_diagonal,
            k_diagonal,
        })
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
        self.factorize_shifted(kkt, |i| sigma * metric[i])
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
    fn solve_refined(&mut self, n_primal: usize, refinements: usize) {
        let n = self.rhs.len();
        let mut z = std::mem::take(&mut self.solution);
        let mut r = std::mem::take(&mut self.refinement);
        z.copy_from_slice(&self.rhs);
        self.ldlt_solve(&mut z);
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
            self.ldlt_solve(&mut r);
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
    /// instead of hundreds of slowly converging iterations.
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
        if let Some(sigma) = self.predicted_shift() {
            if self.count(kkt, sigma, metric)? == 0 {
                let mu = self.inverse_iteration(kkt, metric, LOWEST)?;
                if self.converged && mu - sigma <= CERTIFIED * mu.abs().max(1e-12) {
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
            let sigma = mu - gap * mu.abs().max(1e-12);
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
            loop {
                let mid = 0.5 * (lo + hi);
                if hi - lo <= 1e-12 * hi.abs().max(1e-12) {
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
    fn predicted_shift(&self) -> Option<f64> {
        let (predicted, margin) = extrapolate(&self.lowest_history)?;
        Some(predicted - margin)
    }

    /// Exchanges the warm start (last mode, lowest eigenvalues, mode nearest zero) with
    /// `warm`.
    fn swap_warm_start(&mut self, warm: &mut WarmStart<T>) {
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
        let norm = (0..n_primal)
            .map(|i| weighted_abs2(metric[i], first[i]))
            .sum::<f64>()
            .sqrt();
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
        let zero = T::from_real(0.0);
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
            self.rhs.iter_mut().for_each(|b| *b = zero);
            for i in 0..n_primal {
                self.rhs[i] = T::from_real(metric[i]) * u[i];
            }
            self.solve_refined(n_primal, accuracy.refinements);
            if !self.deflation.is_empty() {
                let f = &self.deflation;
                let mut c = zero;
                for i in 0..n_primal {
                    c += T::from_real(metric[i]) * self.solution[i] * f[i].conjugate();
                }
                for i in 0..n_primal {
                    self.solution[i] -= c * f[i];
                }
            }
            let v = &self.solution;
            let norm = (0..n_primal)
                .map(|i| weighted_abs2(metric[i], v[i]))
                .sum::<f64>()
                .sqrt();
            if norm.is_nan() || norm <= 0.0 || !norm.is_finite() {
                found = false;
                break;
            }
            for i in 0..n_primal {
                u[i] = v[i].div_real(norm);
            }
            // Rayleigh quotient of the Lagrangian, (uᴴ H u + 2 Re yᴴ J u) / uᴴ M u with H
            // the primal block of the KKT values and y the multipliers of the solve (scaled
            // with u): stationary at a constrained eigenpair for every variation of u, so
            // the solve's small constraint residual (the regularisation's δ) enters it
            // only to second order. Refined solves need it too: near a critical point the
            // refinement converges slowly (the regularisation's shift of the eigenvalue is
            // comparable to the eigenvalue itself), and with the plain quotient the eigenvalue
            // nearest zero scattered by 3e-5 J/m, placing the n = 8 sliding tips' double
            // point 1.6e-6 apart on the pair and on the full model (with it: 1e-11)
            hv.iter_mut().for_each(|h| *h = zero);
            let mut lagrange = 0.0;
            for (p, &(row, col)) in self.structure.k_entry.iter().enumerate() {
                if col < n_primal {
                    if row < n_primal {
                        hv[row] += kkt[p] * u[col];
                    } else {
                        lagrange +=
                            (v[row].div_real(norm).conjugate() * kkt[p] * u[col]).real_part();
                    }
                }
            }
            let rq: f64 = (0..n_primal)
                .map(|i| (u[i].conjugate() * hv[i]).real_part())
                .sum::<f64>()
                + 2.0 * lagrange;
            let done = (rq - estimate).abs() <= accuracy.tolerance * rq.abs().max(1e-12);
            estimate = rq;
            if done {
                self.converged = true;
                break;
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
/// searches need none, the modes of critical points keep two).
#[derive(Clone, Copy, Debug)]
struct Accuracy {
    tolerance: f64,
    refinements: usize,
    /// At most this many iterations.
    iterations: usize,
}

/// Largest KKT matrix (unknowns, multipliers included) factorised simplicially; larger
/// ones are factorised supernodally (see [`KktStructure::new`]).
const SIMPLICIAL_MAX: usize = 10_000;

/// A lowest eigenvalue found from a shift `σ` confirmed below the spectrum is accepted
/// without a further count when it lies within this relative distance above `σ` (no
/// eigenvalue is below it by more).
const CERTIFIED: f64 = 2e-3;

/// `δρ`: the regularisation of the constraint rows relative to the Hessian (rows in their
/// norms `c_i`). Weaker, the solves' constraint residual grows (it enters the eigenvalues'
/// Lagrangian Rayleigh quotient to second order); stronger, rounding grows: the thesis
/// n = 1 lowest eigenvalue at ε = 0.5 is within 3e-12 of a dense solve at 1e-6, 4e-10 at
/// 1e-7, 6e-8 at 1e-8 and 3e-4 at 1e-10.
const REGULARISATION: f64 = 1e-8;

/// A first estimate, an upper bound of the lowest eigenvalue that places the next shift.
const ROUGH: Accuracy = Accuracy {
    tolerance: 1e-4,
    refinements: 0,
    iterations: 8,
};

/// The lowest eigenvalue is reported (1e-8 relative agreement of the Bloch blocks and the
/// full model needs the tighter setting where eigenvalues cluster).
const LOWEST: Accuracy = Accuracy {
    tolerance: 1e-11,
    refinements: 0,
    iterations: 16,
};

/// The eigenvalue nearest zero only steers the secant that places a critical point.
const NEAREST_ZERO: Accuracy = Accuracy {
    tolerance: 1e-9,
    refinements: 2,
    iterations: 80,
};

/// The stability of the states of one KKT pattern: the inertia counter (built on first
/// use) and the metric of its eigenproblem, with the count's rounding band.
pub struct KktStability<T: Scalar = f64> {
    counter: Option<Box<InertiaCounter<T>>>,
    /// The pattern's structure, built on first use by this stability or by any that
    /// shares it ([`KktStability::sharing`]).
    structure: Arc<OnceLock<Result<Arc<KktStructure>, InertiaError>>>,
    /// Diagonal metric `M` of the eigenproblem over the primal unknowns.
    metric: Vec<f64>,
    /// Mean of the metric's non-zero weights.
    mean_metric: f64,
    /// Length `ℓ` that weighs position unknowns against rotations in the regularisation
    /// (m; the rod length).
    length: f64,
    /// A warm start handed over before the counter was built, for it.
    pending: WarmStart<T>,
}

impl<T: Scalar> KktStability<T> {
    /// For KKT matrices whose first `metric.len()` unknowns are primal, with the eigenvalue
    /// problem `H v = μ M v`, `M = diag(metric)` (zero on position unknowns), and `length`
    /// the model's length scale `ℓ` (the rod length, m).
    pub fn new(metric: Vec<f64>, length: f64) -> KktStability<T> {
        let mean_metric =
            metric.iter().sum::<f64>() / metric.iter().filter(|&&m| m > 0.0).count().max(1) as f64;
        KktStability {
            counter: None,
            structure: Arc::default(),
            metric,
            mean_metric,
            length,
            pending: WarmStart::default(),
        }
    }

    /// The stability of other matrices of the same pattern and metric (of real or
    /// complex entries), sharing this one's structure: the pattern's symbolic analysis is
    /// done once for all of them.
    pub fn sharing<U: Scalar>(&self) -> KktStability<U> {
        KktStability {
            counter: None,
            structure: Arc::clone(&self.structure),
            metric: self.metric.clone(),
            mean_metric: self.mean_metric,
            length: self.length,
            pending: WarmStart::default(),
        }
    }

    /// Counts the eigenvalues of the constrained Hessian below `−τ`, `τ = 1e-9 ρ / m̄` (`ρ`
    /// the mean diagonal of the Hessian, `m̄` the mean metric weight): the rounding level
    /// of the regularised LDLᵀ's pivots in eigenvalue units, which grows as the mesh is
    /// refined. Eigenvalues closer to zero than the count can resolve — a neutral direction
    /// such as a buckled isotropic rod turning about its axis, or the two halves of a
    /// double critical eigenvalue — count as stable, so a double eigenvalue crosses as one
    /// event; critical points are then placed by a secant on the eigenvalue itself.
    pub fn unstable_directions(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Result<usize, InertiaError> {
        let mean_metric = self.mean_metric;
        let (counter, metric) = self.counter_and_metric(pattern)?;
        let tau = 1e-9 * counter.hessian_scale(kkt) / mean_metric;
        let inertia = counter.inertia(kkt, -tau, metric)?;
        Ok(counter.unstable_directions(inertia).max(0) as usize)
    }

    /// The unstable directions (as [`KktStability::unstable_directions`] counts them) and
    /// the number of eigenvalues below `sigma`, by one factorisation where one answers
    /// both: no eigenvalue below `σ ≥ −τ` means none below `−τ`, and none below `−τ ≥ σ`
    /// none below `σ`.
    pub fn unstable_and_below(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        sigma: f64,
    ) -> Result<(usize, usize), InertiaError> {
        let tau = self.rounding_band(pattern, kkt)?;
        if sigma >= -tau {
            let below = self.count_below(pattern, kkt, sigma)?;
            if below == 0 {
                return Ok((0, 0));
            }
            Ok((self.unstable_directions(pattern, kkt)?, below))
        } else {
            let unstable = self.unstable_directions(pattern, kkt)?;
            if unstable == 0 {
                return Ok((0, 0));
            }
            Ok((unstable, self.count_below(pattern, kkt, sigma)?))
        }
    }

    /// `τ = 1e-9 ρ / m̄`: the rounding band of the count (see
    /// [`KktStability::unstable_directions`]) in eigenvalue units.
    pub fn rounding_band(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Result<f64, InertiaError> {
        let mean_metric = self.mean_metric;
        let counter = self.counter(pattern)?;
        Ok(1e-9 * counter.hessian_scale(kkt) / mean_metric)
    }

    /// Number of eigenvalues of the constrained Hessian below `sigma`.
    pub fn count_below(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        sigma: f64,
    ) -> Result<usize, InertiaError> {
        let (counter, metric) = self.counter_and_metric(pattern)?;
        let inertia = counter.inertia(kkt, sigma, metric)?;
        Ok(counter.unstable_directions(inertia).max(0) as usize)
    }

    fn counter(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<&mut InertiaCounter<T>, InertiaError> {
        Ok(self.counter_and_metric(pattern)?.0)
    }

    /// The inertia counter (built on first use) and the metric, borrowed together.
    /// The structure of matrices of `pattern` (built on first use).
    pub fn structure_for(
        &self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<Arc<KktStructure>, InertiaError> {
        self.structure
            .get_or_init(|| KktStructure::new(pattern, &self.metric, self.length).map(Arc::new))
            .clone()
    }

    fn counter_and_metric(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
    ) -> Result<(&mut InertiaCounter<T>, &[f64]), InertiaError> {
        if self.counter.is_none() {
            let structure = self.structure_for(pattern)?;
            let mut counter = Box::new(InertiaCounter::with_structure(structure)?);
            counter.swap_warm_start(&mut self.pending);
            self.counter = Some(counter);
        }
        let counter = self.counter.as_mut().expect("built above");
        Ok((counter, &self.metric))
    }
}

impl<T: Scalar> KktStability<T> {
    /// Exchanges the warm start of inverse iteration (the last mode and lowest eigenvalue)
    /// with `warm` (so that one factorisation pattern can serve several matrices, each with
    /// its own warm start).
    pub fn swap_warm_start(&mut self, warm: &mut WarmStart<T>) {
        match self.counter.as_mut() {
            Some(c) => c.swap_warm_start(warm),
            None => std::mem::swap(&mut self.pending, warm),
        }
    }

    /// The mode (primal unknowns, unit norm in the metric) of the last eigenvalue nearest
    /// zero found; empty before one is found.
    pub fn nearest_zero_mode(&self) -> &[T] {
        self.counter
            .as_ref()
            .map_or(&[], |c| c.nearest_zero_mode.as_slice())
    }

    /// Lowest eigenvalue of the constrained Hessian (J/m in the rods' metric).
    pub fn lowest_eigenvalue(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<f64> {
        self.lowest_eigenvalue_after(pattern, kkt, None)
    }

    /// As [`KktStability::lowest_eigenvalue`], going on from a rough estimate of the same
    /// values when there is one.
    pub fn lowest_eigenvalue_after(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        rough: Option<RoughLowest>,
    ) -> Option<f64> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.lowest_eigenvalue(kkt, metric, rough)
    }

    /// A rough upper estimate of the lowest eigenvalue (see
    /// [`InertiaCounter::rough_lowest`]).
    pub fn rough_lowest(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<RoughLowest> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.rough_lowest(kkt, metric)
    }

    /// The eigenvalue nearest zero orthogonal to `first` and its mode (see
    /// [`InertiaCounter::nearest_zero_orthogonal_to`]).
    pub fn nearest_zero_orthogonal_to(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
        first: &[T],
    ) -> Option<(f64, Vec<T>)> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.nearest_zero_orthogonal_to(kkt, metric, first)
    }

    /// The eigenvalue of the constrained Hessian nearest zero.
    pub fn eigenvalue_nearest_zero(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[T],
    ) -> Option<f64> {
        let (counter, metric) = self.counter_and_metric(pattern).ok()?;
        counter.eigenvalue_nearest_zero(kkt, metric)
    }
}
