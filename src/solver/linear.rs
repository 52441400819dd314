//! Sparse LU of the KKT matrix (faer), with the symbolic factorisation computed once
//! per sparsity pattern and reused by every Newton iteration; the least-squares
//! multipliers of a state known in its primal unknowns only.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{MatMut, Par, Side};

/// Why a linear solve failed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum LinearError {
    /// The matrix is singular (structurally, or numerically: the solve's relative residual
    /// was `relative_residual`).
    #[error("singular KKT matrix (relative residual of the linear solve {relative_residual:.1e}): redundant constraints or an unrestrained mode")]
    Singular { relative_residual: f64 },
    /// Out of memory in the factorisation.
    #[error("out of memory in the sparse factorisation")]
    OutOfMemory,
}

/// Sparse LU with a reusable symbolic factorisation.
pub struct SparseLu {
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    buffer: MemBuffer,
    /// Numeric factorisations done since creation.
    pub factorisations: usize,
}

impl Default for SparseLu {
    fn default() -> Self {
        SparseLu {
            symbolic: None,
            numeric: NumericLu::new(),
            buffer: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
            factorisations: 0,
        }
    }
}

impl SparseLu {
    /// Forgets the symbolic factorisation (the pattern changed).
    pub fn reset(&mut self) {
        *self = SparseLu {
            factorisations: self.factorisations,
            ..Default::default()
        };
    }

    /// Numeric factorisation of `a` (the symbolic one on first use).
    pub fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearError> {
        let par = Par::Seq;
        if self.symbolic.is_none() {
            // the supernodal factorisation is several times faster on these KKT patterns
            // than the simplicial one faer's heuristic picks
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let sym = factorize_symbolic_lu(a.symbolic(), params)
                .map_err(|_| LinearError::OutOfMemory)?;
            let req = sym
                .factorize_numeric_lu_scratch::<f64>(par, Default::default())
                .or(sym.solve_in_place_scratch::<f64>(1, par));
            self.buffer = MemBuffer::try_new(req).map_err(|_| LinearError::OutOfMemory)?;
            self.symbolic = Some(sym);
        }
        let sym = self.symbolic.as_ref().expect("symbolic factorisation");
        sym.factorize_numeric_lu(
            &mut self.numeric,
            a,
            par,
            MemStack::new(&mut self.buffer),
            Default::default(),
        )
        .map_err(|_| LinearError::Singular {
            relative_residual: f64::INFINITY,
        })?;
        self.factorisations += 1;
        Ok(())
    }

    /// Solves `A x = b` in place with the last factorisation.
    pub fn solve(&mut self, b: &mut [f64]) {
        let sym = self.symbolic.as_ref().expect("factorize before solve");
        let n = b.len();
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(sym, &self.numeric);
        lu.solve_in_place_with_conj(
            faer::Conj::No,
            MatMut::from_column_major_slice_mut(b, n, 1),
            Par::Seq,
            MemStack::new(&mut self.buffer),
        );
    }
}

/// `‖A x − b‖∞ / max(‖b‖∞, tiny)`: the check that tells a singular matrix from a good solve.
/// `ax` is scratch of the length of `b`.
pub fn relative_residual(
    a: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    b: &[f64],
    ax: &mut [f64],
) -> f64 {
    ax.iter_mut().for_each(|v| *v = 0.0);
    let col_ptr = a.symbolic().col_ptr();
    let row_idx = a.symbolic().row_idx();
    let val = a.val();
    for j in 0..b.len() {
        for p in col_ptr[j]..col_ptr[j + 1] {
            ax[row_idx[p]] += val[p] * x[j];
        }
    }
    let bn = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    // a NaN anywhere (f64::max would skip it) means the solve failed
    let rn = ax
        .iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0f64, |m, d| {
            if d.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(d)
            }
        });
    if rn.is_finite() && x.iter().all(|v| v.is_finite()) {
        rn / bn
    } else {
        f64::INFINITY
    }
}

/// The change `Δλ` of the multipliers (the unknowns from `n_primal` on) that leaves the
/// primal rows of the residual least (in the 2-norm) at fixed primal unknowns: the normal
/// equations `J Jᵀ Δλ = −J r` of `min ‖r + Jᵀ Δλ‖`, with `J` the constraint block of the
/// KKT values `kkt` (pattern `pattern`) and `r` the primal rows of `residual`. It puts the
/// multipliers of a state whose primal part is known (the pair's state on the whole
/// assembly, whose supports and joints hold unknown forces) where Newton's method need
/// not find them through a nearly singular Jacobian. `None` when `J Jᵀ` is not positive
/// definite (dependent constraints).
pub fn least_squares_multipliers(
    pattern: &SymbolicSparseColMat<usize>,
    kkt: &[f64],
    residual: &[f64],
    n_primal: usize,
) -> Option<Vec<f64>> {
    let n_dual = pattern.ncols().checked_sub(n_primal)?;
    if n_dual == 0 {
        return Some(Vec::new());
    }
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    // the rows of J met in each primal column: J Jᵀ = Σ_j J[:, j] J[:, j]ᵀ, and J r
    let mut jjt = std::collections::BTreeMap::<(usize, usize), f64>::new();
    let mut rhs = vec![0.0; n_dual];
    let mut column = Vec::new();
    for j in 0..n_primal {
        column.clear();
        for p in cp[j]..cp[j + 1] {
            if ri[p] >= n_primal && kkt[p] != 0.0 {
                column.push((ri[p] - n_primal, kkt[p]));
            }
        }
        for &(a, va) in &column {
            rhs[a] -= va * residual[j];
            for &(b, vb) in &column {
                if b >= a {
                    *jjt.entry((b, a)).or_insert(0.0) += va * vb;
                }
            }
        }
    }
    let triplets: Vec<Triplet<usize, usize, f64>> = jjt
        .into_iter()
        .map(|((row, col), v)| Triplet::new(row, col, v))
        .collect();
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n_dual, n_dual, &triplets).ok()?;
    let llt = a.as_ref().sp_cholesky(Side::Lower).ok()?;
    llt.solve_in_place_with_conj(
        faer::Conj::No,
        MatMut::from_column_major_slice_mut(&mut rhs, n_dual, 1),
    );
    rhs.iter().all(|v| v.is_finite()).then_some(rhs)
}
