//! Sparse LU of the KKT matrix (faer), with the symbolic factorisation computed once
//! per sparsity pattern and reused by every Newton iteration.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SparseColMatRef;
use faer::{MatMut, Par};

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
