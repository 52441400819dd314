//! The symbolic analysis of a KKT pattern, shared by every matrix of it: the augmented
//! pattern of `K_ρδ` (the KKT pattern and the fill of `JᵀC⁻¹J`), its fill-reducing ordering,
//! the symbolic `LDLᵀ`, and the maps that place the values of `K` in it.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMat;
use faer::Side;

use crate::solver::ldl::RowReach;

/// Why the inertia could not be computed (in the symbolic analysis or a factorisation).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum InertiaError {
    #[error("zero pivot in the LDLᵀ of the KKT matrix (a singular or critical state)")]
    ZeroPivot,
    #[error("out of memory in the LDLᵀ factorisation")]
    OutOfMemory,
}

/// The augmented KKT pattern of one `System`, its symbolic `LDLᵀ` and value maps: what
/// every matrix of that pattern shares (the Bloch blocks of one sector, real and complex,
/// on every thread), built once.
pub struct KktStructure {
    /// Number of constraint rows.
    pub constraints: usize,
    /// The fill-reducing ordering: unknown `perm[i]` of the KKT matrix is unknown `i` of
    /// the stored matrix.
    pub(super) perm: Vec<usize>,
    /// The upper triangle of the permuted augmented pattern.
    pub(super) pattern: SymbolicSparseColMat<usize>,
    pub(super) symbolic: SymbolicCholesky<usize>,
    /// The rows' reach of a simplicial factor, for the numeric factorisations (faer's
    /// own for a supernodal one).
    pub(super) reach: Option<RowReach>,
    /// For each stored entry of `K`, its slot in the augmented pattern (`usize::MAX` for
    /// an entry of the lower triangle, which is not stored).
    pub(super) k_slots: Vec<usize>,
    /// For each stored entry of `K`, its (row, column).
    pub(super) k_entry: Vec<(usize, usize)>,
    /// The entries of `J` among them: (index into K's values, column, constraint row),
    /// with the row's `1/c_i` (the constraint part of a right-hand side enters the primal
    /// one through them).
    pub(super) j_entries: Vec<ConstraintEntry>,
    /// Products `(k value a, k value b, slot)` making `JᴴC⁻¹J`: `conj(a) b / c_i` into
    /// `slot`, those of constraint row `i` at `jtj[jtj_rows[i]..jtj_rows[i + 1]]` (indices
    /// as `u32`: the loop that forms them is bound by memory traffic).
    pub(super) jtj: Vec<GramProduct>,
    pub(super) jtj_rows: Vec<usize>,
    /// The regularisation's `C`: `c_i = ℓ²` for a constraint row `i` on positions, 1 for
    /// one on rotations only.
    pub(super) row_scale: Vec<f64>,
    /// Slots of the dual diagonal.
    pub(super) dual_diagonal: Vec<usize>,
    /// Slots of the primal diagonal.
    pub(super) primal_diagonal: Vec<usize>,
    /// Indices of the primal diagonal in the KKT values.
    pub(super) k_diagonal: Vec<usize>,
}

/// Largest KKT matrix (unknowns, multipliers included) factorised simplicially; larger
/// ones are factorised supernodally (see [`KktStructure::new`]).
const SIMPLICIAL_MAX: usize = 10_000;

/// The entries of one constraint row of `J`: (column, index into K's values).
type ConstraintRow = Vec<(usize, usize)>;

/// An entry of `J` among those of `K` (see [`KktStructure::j_entries`]).
type ConstraintEntry = (u32, u32, u32, f64);

/// A product that forms `JᴴC⁻¹J` (see [`KktStructure::jtj`]).
type GramProduct = (u32, u32, u32);

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
        let rows = constraint_rows(k, n_primal);
        let full = augmented_pattern(k, &rows, n_primal);
        // the fill-reducing ordering, applied here once: the matrices are stored permuted
        // and as their upper triangle, the form the simplicial LDLᵀ factorises without a
        // copy (it would otherwise permute every matrix before factorising it)
        let (perm, perm_inv) = fill_reducing_ordering(&full)?;
        let pattern = permuted_upper(&full, &perm_inv);
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
        let (jtj, jtj_rows) = jtj_products(&rows, upper_slot)?;
        let row_scale = row_scales(&rows, metric, length);
        let j_entries = constraint_entries(&k_entry, n_primal, &row_scale)?;
        let diagonal = |i: usize| slot(&pattern, perm_inv[i], perm_inv[i]);
        let dual_diagonal = (n_primal..n).map(diagonal).collect();
        let primal_diagonal = (0..n_primal).map(diagonal).collect();
        let k_diagonal = (0..n_primal).map(|i| slot(k, i, i)).collect();
        let (symbolic, reach) = symbolic_factor(&pattern)?;
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

/// The constraint rows of `J`, from the lower-left block of the KKT pattern `k` (its first
/// `n_primal` unknowns primal).
fn constraint_rows(k: &SymbolicSparseColMat<usize>, n_primal: usize) -> Vec<ConstraintRow> {
    let (cp, ri) = (k.col_ptr(), k.row_idx());
    let mut rows: Vec<ConstraintRow> = vec![Vec::new(); k.ncols() - n_primal];
    for col in 0..n_primal {
        for p in cp[col]..cp[col + 1] {
            if ri[p] >= n_primal {
                rows[ri[p] - n_primal].push((col, p));
            }
        }
    }
    rows
}

/// The augmented pattern (both triangles), column by column: K's rows and those of every
/// column that shares a constraint row with it (`JᵀJ`), each once (a marker per column),
/// sorted.
fn augmented_pattern(
    k: &SymbolicSparseColMat<usize>,
    rows: &[ConstraintRow],
    n_primal: usize,
) -> SymbolicSparseColMat<usize> {
    let n = k.ncols();
    let (cp, ri) = (k.col_ptr(), k.row_idx());
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
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
}

/// The approximate minimum degree ordering of `full` alone, as `(perm, perm_inv)` (faer's
/// symbolic factorisation with `SymmetricOrdering::Amd` computes the same one, then a
/// factorisation of the pattern it does not need).
fn fill_reducing_ordering(
    full: &SymbolicSparseColMat<usize>,
) -> Result<(Vec<usize>, Vec<usize>), InertiaError> {
    let n = full.ncols();
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
    Ok((perm, perm_inv))
}

/// The upper triangle of `full` permuted by `perm_inv` (entry `(i, j)` to
/// `(perm_inv[i], perm_inv[j])`), sorted.
fn permuted_upper(
    full: &SymbolicSparseColMat<usize>,
    perm_inv: &[usize],
) -> SymbolicSparseColMat<usize> {
    let n = full.ncols();
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
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
}

/// The products that form `JᴴC⁻¹J` ([`KktStructure::jtj`]) and where each constraint row's
/// start, given the stored slot of an entry of the unpermuted matrix (`None` when it is
/// not stored).
fn jtj_products(
    rows: &[ConstraintRow],
    upper_slot: impl Fn(usize, usize) -> Option<usize>,
) -> Result<(Vec<GramProduct>, Vec<usize>), InertiaError> {
    let mut jtj = Vec::new();
    let mut jtj_rows = Vec::with_capacity(rows.len() + 1);
    jtj_rows.push(0);
    for r in rows {
        for &(ca, pa) in r {
            for &(cb, pb) in r {
                if let Some(s) = upper_slot(ca, cb) {
                    jtj.push((index(pa)?, index(pb)?, index(s)?));
                }
            }
        }
        jtj_rows.push(jtj.len());
    }
    Ok((jtj, jtj_rows))
}

/// The regularisation's `c_i` of every constraint row: `ℓ²` (`length` in m) for a row on
/// positions (any unknown of zero metric), 1 for one on rotations only.
fn row_scales(rows: &[ConstraintRow], metric: &[f64], length: f64) -> Vec<f64> {
    rows.iter()
        .map(|r| {
            if r.iter().any(|&(col, _)| metric[col] <= 0.0) {
                length * length
            } else {
                1.0
            }
        })
        .collect()
}

/// The entries of `J` among the KKT entries `k_entry` ([`KktStructure::j_entries`]).
fn constraint_entries(
    k_entry: &[(usize, usize)],
    n_primal: usize,
    row_scale: &[f64],
) -> Result<Vec<ConstraintEntry>, InertiaError> {
    let mut j_entries = Vec::new();
    for (p, &(row, col)) in k_entry.iter().enumerate() {
        if row >= n_primal && col < n_primal {
            let i = row - n_primal;
            j_entries.push((index(p)?, index(col)?, index(i)?, 1.0 / row_scale[i]));
        }
    }
    Ok(j_entries)
}

/// The symbolic `LDLᵀ` of the permuted upper triangle `pattern` in its own ordering, and
/// the rows' reach of a simplicial one. The simplicial factorisation is the faster one on
/// the patterns of a pair (its Bloch blocks: thesis n = 8 cold 0.40 s → 0.36 s with it
/// alone), the supernodal one on large full models (n = 16 full model: 16.5e9
/// instructions against 25.1e9 for the simplicial one).
fn symbolic_factor(
    pattern: &SymbolicSparseColMat<usize>,
) -> Result<(SymbolicCholesky<usize>, Option<RowReach>), InertiaError> {
    let threshold = if pattern.ncols() <= SIMPLICIAL_MAX {
        SupernodalThreshold::FORCE_SIMPLICIAL
    } else {
        SupernodalThreshold::FORCE_SUPERNODAL
    };
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: threshold,
        ..Default::default()
    };
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
    Ok((symbolic, reach))
}

/// An index as `u32`, the width of the value maps.
fn index(i: usize) -> Result<u32, InertiaError> {
    u32::try_from(i).map_err(|_| InertiaError::OutOfMemory)
}

/// The position in `pattern`'s values of its entry `(row, col)`, which must be stored.
fn slot(pattern: &SymbolicSparseColMat<usize>, row: usize, col: usize) -> usize {
    let cp = pattern.col_ptr();
    let rows = &pattern.row_idx()[cp[col]..cp[col + 1]];
    cp[col]
        + rows
            .binary_search(&row)
            .expect("entry in the augmented pattern")
}
