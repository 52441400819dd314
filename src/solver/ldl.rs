//! Up-looking simplicial `LDLᴴ` of matrices of one fixed pattern, with the elimination
//! reach of every row computed once.
//!
//! faer's simplicial factorisation recomputes each row's reach through the elimination
//! tree, and divides by a pivot for every entry of the factor, at every factorisation.
//! The KKT matrices of a symmetric pair and its Bloch blocks are factorised thousands of
//! times with the same pattern and a factor of about fourteen entries per column, so
//! that overhead is most of the work. Here the reach of row `k` (the columns `j` with
//! `L_kj ≠ 0`, in increasing order, which is a topological order of the elimination) and
//! the slot of each `L_kj` are stored once, and pivots are inverted once. The factor is
//! written in faer's simplicial layout (each column's pivot `d_j` first, then its
//! strictly lower entries by increasing row), so faer's triangular solves and the
//! inertia count read it as they read faer's own.

use faer::c64;

/// The entries of the matrices whose inertia is counted: real (symmetric) or complex
/// (Hermitian, the Bloch blocks of wavenumbers `0 < p < m/2`, factorised as `LDLᴴ`).
pub trait Scalar:
    faer::traits::ComplexField<Real = f64>
    + Copy
    + PartialEq
    + std::ops::AddAssign
    + std::ops::SubAssign
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
{
    fn from_real(x: f64) -> Self;
    fn conjugate(self) -> Self;
    fn real_part(self) -> f64;
    /// `|x|²`.
    fn abs2(self) -> f64;
    /// `x / d` for a real `d`.
    fn div_real(self, d: f64) -> Self;
}

impl Scalar for f64 {
    fn from_real(x: f64) -> f64 {
        x
    }
    fn conjugate(self) -> f64 {
        self
    }
    fn real_part(self) -> f64 {
        self
    }
    fn abs2(self) -> f64 {
        self * self
    }
    fn div_real(self, d: f64) -> f64 {
        self / d
    }
}

impl Scalar for c64 {
    fn from_real(x: f64) -> c64 {
        c64::new(x, 0.0)
    }
    fn conjugate(self) -> c64 {
        self.conj()
    }
    fn real_part(self) -> f64 {
        self.re
    }
    fn abs2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    fn div_real(self, d: f64) -> c64 {
        c64::new(self.re / d, self.im / d)
    }
}

/// The reach of every row of a simplicial factor, in faer's layout of `L`.
#[derive(Debug)]
pub struct RowReach {
    /// Start of each column of `L` (its pivot's slot).
    col_start: Vec<u32>,
    /// Row `k`'s reach: `(j, slot of L_kj)` at `reach[reach_ptr[k]..reach_ptr[k + 1]]`.
    reach_ptr: Vec<usize>,
    reach: Vec<(u32, u32)>,
    /// Row index of every slot of `L`.
    row_idx: Vec<u32>,
}

/// A zero or non-finite pivot at row `index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ZeroPivot {
    pub index: usize,
}

impl RowReach {
    /// The reach of the factor whose columns start at `col_ptr` (pivot first) with row
    /// indices `row_idx` (faer's `SymbolicSimplicialCholesky`); `None` when the factor
    /// has more entries than a `u32` counts.
    pub fn new(col_ptr: &[usize], row_idx: &[usize]) -> Option<RowReach> {
        let n = col_ptr.len().checked_sub(1)?;
        let nnz = *col_ptr.last()?;
        if nnz > u32::MAX as usize || n > u32::MAX as usize {
            return None;
        }
        let mut counts = vec![0usize; n + 1];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j] + 1..col_ptr[j + 1]] {
                counts[i + 1] += 1;
            }
        }
        for k in 0..n {
            counts[k + 1] += counts[k];
        }
        let reach_ptr = counts.clone();
        let mut next = counts;
        let mut reach = vec![(0u32, 0u32); nnz - n];
        // columns in increasing order: every row's reach comes out sorted
        for j in 0..n {
            for q in col_ptr[j] + 1..col_ptr[j + 1] {
                let i = row_idx[q];
                reach[next[i]] = (j as u32, q as u32);
                next[i] += 1;
            }
        }
        Some(RowReach {
            col_start: col_ptr[..n].iter().map(|&p| p as u32).collect(),
            reach_ptr,
            reach,
            row_idx: row_idx.iter().map(|&i| i as u32).collect(),
        })
    }

    /// Factorises `A = L D Lᴴ`, `A` given by its upper triangle in `a_col_ptr`,
    /// `a_row_idx`, `a` (the pattern the reach was built for, ordering applied), into `l`
    /// (faer's layout: `d_j` at each column's start). `work` (length n) must be zero and
    /// is left zero; `inverse_pivot` (length n) is scratch.
    pub fn factorize<T: Scalar>(
        &self,
        a_col_ptr: &[usize],
        a_row_idx: &[usize],
        a: &[T],
        l: &mut [T],
        work: &mut [T],
        inverse_pivot: &mut [f64],
    ) -> Result<(), ZeroPivot> {
        let zero = T::from_real(0.0);
        let n = self.col_start.len();
        for k in 0..n {
            // row k of A (the conjugate of column k's upper part) into the dense work
            for p in a_col_ptr[k]..a_col_ptr[k + 1] {
                work[a_row_idx[p]] += a[p].conjugate();
            }
            let mut d = work[k].real_part();
            work[k] = zero;
            for &(j, slot) in &self.reach[self.reach_ptr[k]..self.reach_ptr[k + 1]] {
                let (j, slot) = (j as usize, slot as usize);
                let xj = work[j];
                work[j] = zero;
                let lkj = xj * T::from_real(inverse_pivot[j]);
                let start = self.col_start[j] as usize + 1;
                for (&i, &lij) in self.row_idx[start..slot].iter().zip(&l[start..slot]) {
                    work[i as usize] -= lij.conjugate() * xj;
                }
                d -= (lkj * xj.conjugate()).real_part();
                l[slot] = lkj;
            }
            if d == 0.0 || !d.is_finite() {
                // leave the work zero for the next factorisation
                work.iter_mut().for_each(|w| *w = zero);
                return Err(ZeroPivot { index: k });
            }
            l[self.col_start[k] as usize] = T::from_real(d);
            inverse_pivot[k] = 1.0 / d;
        }
        Ok(())
    }

    /// Solves `L D Lᴴ x = b` in place (`x` holds `b`) with the factor `l` and the inverted
    /// pivots of [`RowReach::factorize`]: the operations of faer's simplicial solve of one
    /// right-hand side, in its order (forward by columns, then backward by rows of `Lᴴ`
    /// with the pivot applied first), without inverting every pivot again.
    pub fn solve_in_place<T: Scalar>(&self, l: &[T], inverse_pivot: &[f64], x: &mut [T]) {
        let n = self.col_start.len();
        // the strictly lower entries of column j
        let below = |j: usize| {
            let start = self.col_start[j] as usize + 1;
            let end = self
                .col_start
                .get(j + 1)
                .map_or(self.row_idx.len(), |&e| e as usize);
            (&self.row_idx[start..end], &l[start..end])
        };
        for j in 0..n {
            let xj = x[j];
            let (rows, values) = below(j);
            for (&i, &lij) in rows.iter().zip(values) {
                x[i as usize] -= lij * xj;
            }
        }
        for j in (0..n).rev() {
            let (rows, values) = below(j);
            let mut acc = T::from_real(0.0);
            for (&i, &lij) in rows.iter().zip(values).rev() {
                acc += lij.conjugate() * x[i as usize];
            }
            x[j] = x[j] * T::from_real(inverse_pivot[j]) - acc;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense Hermitian matrix's upper triangle as columns, every entry stored.
    fn upper<T: Scalar>(a: &[Vec<T>]) -> (Vec<usize>, Vec<usize>, Vec<T>) {
        let n = a.len();
        let (mut cp, mut ri, mut v) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for (i, row) in a.iter().enumerate().take(j + 1) {
                ri.push(i);
                v.push(row[j]);
            }
            cp.push(ri.len());
        }
        (cp, ri, v)
    }

    /// The dense pattern of `L` (pivot first, then every row below).
    fn dense_factor(n: usize) -> (Vec<usize>, Vec<usize>) {
        let (mut cp, mut ri) = (vec![0], Vec::new());
        for j in 0..n {
            ri.extend(j..n);
            cp.push(ri.len());
        }
        (cp, ri)
    }

    /// An indefinite Hermitian matrix: diagonal entries negative where `negative(i)`, small
    /// complex couplings.
    fn indefinite_hermitian(n: usize, negative: impl Fn(usize) -> bool) -> Vec<Vec<c64>> {
        let scale = n as f64;
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let (x, y) = (i as f64, j as f64);
                        if i == j {
                            c64::new(if negative(i) { -3.0 - x } else { 4.0 + x }, 0.0)
                        } else {
                            let s = if i < j { 1.0 } else { -1.0 };
                            c64::new(0.3 * (x + y) / scale, s * 0.2 * (x - y).abs() / scale)
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// `a` factorised with a dense pattern of `L`: the reach, the factor, the inverted
    /// pivots, the work (left zero) and the pattern of `L`.
    #[allow(clippy::type_complexity)]
    fn factorised(
        a: &[Vec<c64>],
    ) -> (
        RowReach,
        Vec<c64>,
        Vec<f64>,
        Vec<c64>,
        (Vec<usize>, Vec<usize>),
    ) {
        let n = a.len();
        let (acp, ari, av) = upper(a);
        let (lcp, lri) = dense_factor(n);
        let reach = RowReach::new(&lcp, &lri).expect("small factor");
        let mut l = vec![c64::new(0.0, 0.0); lri.len()];
        let mut work = vec![c64::new(0.0, 0.0); n];
        let mut inv = vec![0.0; n];
        reach
            .factorize(&acp, &ari, &av, &mut l, &mut work, &mut inv)
            .expect("nonsingular");
        (reach, l, inv, work, (lcp, lri))
    }

    /// `L D Lᴴ` rebuilt from the factor reproduces an indefinite Hermitian matrix.
    #[test]
    fn factor_reproduces_an_indefinite_hermitian_matrix() {
        let n = 5;
        let a = indefinite_hermitian(n, |i| i % 2 == 1);
        let (_, l, _, work, (lcp, lri)) = factorised(&a);
        // dense L (unit diagonal) and D
        let mut ld = vec![vec![c64::new(0.0, 0.0); n]; n];
        let mut d = vec![0.0; n];
        for j in 0..n {
            d[j] = l[lcp[j]].re;
            ld[j][j] = c64::new(1.0, 0.0);
            for q in lcp[j] + 1..lcp[j + 1] {
                ld[lri[q]][j] = l[q];
            }
        }
        for i in 0..n {
            for j in 0..n {
                let mut s = c64::new(0.0, 0.0);
                for k in 0..n {
                    s += ld[i][k] * ld[j][k].conj() * d[k];
                }
                assert!(
                    (s - a[i][j]).norm() < 1e-13,
                    "({i},{j}): {s} against {}",
                    a[i][j]
                );
            }
        }
        assert!(work.iter().all(|w| *w == c64::new(0.0, 0.0)));
        // Sylvester: as many negative pivots as negative diagonal entries here
        assert_eq!(d.iter().filter(|&&x| x < 0.0).count(), 2);
    }

    /// The solve with the factor gives `x` with `A x = b` for an indefinite Hermitian `A`.
    #[test]
    fn solve_inverts_an_indefinite_hermitian_matrix() {
        let n = 6;
        let a = indefinite_hermitian(n, |i| i % 3 == 0);
        let (reach, l, inv, _, _) = factorised(&a);
        let b: Vec<c64> = (0..n)
            .map(|i| c64::new(1.0 + i as f64, 0.5 - i as f64))
            .collect();
        let mut x = b.clone();
        reach.solve_in_place(&l, &inv, &mut x);
        for i in 0..n {
            let mut r = -b[i];
            for j in 0..n {
                r += a[i][j] * x[j];
            }
            assert!(r.norm() < 1e-13, "row {i}: residual {r}");
        }
    }

    /// A zero pivot is reported at its row, and the work is left clean.
    #[test]
    fn zero_pivot_is_reported() {
        let a = vec![vec![1.0, 1.0], vec![1.0, 1.0]];
        let (acp, ari, av) = upper(&a);
        let (lcp, lri) = dense_factor(2);
        let reach = RowReach::new(&lcp, &lri).expect("small factor");
        let (mut l, mut work, mut inv) = (vec![0.0; 3], vec![0.0; 2], vec![0.0; 2]);
        assert_eq!(
            reach.factorize(&acp, &ari, &av, &mut l, &mut work, &mut inv),
            Err(ZeroPivot { index: 1 })
        );
        assert!(work.iter().all(|&w| w == 0.0));
    }
}
