//! The linear algebra of the extended system: the bordered matrix `[K B; Bᵀ 0]` and its
//! solves, the pattern of the extended Jacobian and where each of its entries comes from,
//! and the map of a member's pattern onto the start's.

use super::super::linear::SparseLu;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// Where an entry of the extended Jacobian comes from.
#[derive(Clone, Copy, Debug)]
pub(super) enum Source {
    /// Entry `e` of the member's Jacobian.
    K(usize),
    /// `∂g/∂x_j`.
    Gx(usize),
    /// `∂R_i/∂λ`.
    Rl(usize),
    /// `∂g/∂λ`.
    Gl,
    /// Component `i` of border `l` (the column of `β_l`).
    B(usize, usize),
    /// `∂h_l/∂x_j`.
    Hx(usize, usize),
    /// `∂h_l/∂λ`.
    Hl(usize),
}

/// Index in the extended unknowns of a member's unknown `i` (`λ` sits after the primal
/// unknowns, so that the arclength norm runs over it).
pub(super) fn ext(i: usize, np: usize) -> usize {
    if i < np {
        i
    } else {
        i + 1
    }
}

/// `A v`.
pub(super) fn multiply(a: SparseColMatRef<'_, usize, f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for (j, vj) in v.iter().enumerate().take(a.ncols()) {
        for (i, aij) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            out[i] += aij * vj;
        }
    }
    out
}

/// `u·v`.
pub(super) fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(a, b)| a * b).sum()
}

/// The primal parts (the first `np` components; the multipliers' zero) of the vectors,
/// orthonormalised (Gram–Schmidt); a vector dependent on those before it is dropped.
pub(super) fn orthonormal(vectors: Vec<Vec<f64>>, np: usize) -> Vec<Vec<f64>> {
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

/// The place in `start` of every entry of `pattern`: `Some(None)` for the same pattern,
/// `None` when `pattern` has an entry `start` has not (a coefficient zero at the start,
/// left out of its pattern, may be left out elsewhere and not the other way round).
pub(super) fn pattern_map(
    pattern: &SymbolicSparseColMat<usize>,
    start: &SymbolicSparseColMat<usize>,
) -> Option<Option<Vec<usize>>> {
    let (a, b) = (pattern.as_ref(), start.as_ref());
    if a.ncols() != b.ncols() || a.nrows() != b.nrows() {
        return None;
    }
    if a.col_ptr() == b.col_ptr() && a.row_idx() == b.row_idx() {
        return Some(None);
    }
    let mut map = Vec::with_capacity(a.row_idx().len());
    for j in 0..a.ncols() {
        let rows = &b.row_idx()[b.col_ptr()[j]..b.col_ptr()[j + 1]];
        for i in a.row_idx_of_col(j) {
            let at = rows.binary_search(&i).ok()?;
            map.push(b.col_ptr()[j] + at);
        }
    }
    Some(Some(map))
}

/// The pattern of the extended Jacobian (`n + 1 + nb` square) from the member's `K`, and
/// the source of each entry in its order: the member's unknowns (`λ` after its primal
/// ones), then the `nb` multipliers `β`; rows likewise, `g` at `np`, the `h_l` last.
pub(super) fn extended_pattern(
    k: &SymbolicSparseColMat<usize>,
    n: usize,
    np: usize,
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
            col.push((n + 1 + l, Source::Hx(l, j)));
        }
    }
    for i in 0..n {
        columns[np].push((ext(i, np), Source::Rl(i)));
    }
    columns[np].push((np, Source::Gl));
    columns[np].sort_by_key(|(r, _)| *r);
    for l in 0..nb {
        columns[np].push((n + 1 + l, Source::Hl(l)));
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
pub(super) struct Bordered {
    pub member_pattern: SymbolicSparseColMat<usize>,
    pattern: SymbolicSparseColMat<usize>,
    n: usize,
    lu: SparseLu,
}

impl Bordered {
    pub fn new(k: &SymbolicSparseColMat<usize>, n: usize, borders: usize) -> Bordered {
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
            n,
            lu: SparseLu::default(),
        }
    }

    /// Entries of the member's pattern.
    pub fn entries(&self) -> usize {
        self.member_pattern.row_idx().len()
    }

    /// Factorises `[K B; Bᵀ 0]` for the member's Jacobian values `k`; then `g = tr G / k`
    /// and `V`. `None` where it is singular.
    pub fn solve(&mut self, k: &[f64], borders: &[Vec<f64>]) -> Option<(f64, Vec<Vec<f64>>)> {
        let (n, nb) = (self.n, borders.len());
        let kr = self.member_pattern.as_ref();
        let mut values = Vec::with_capacity(self.pattern.row_idx().len());
        for j in 0..n {
            values.extend_from_slice(&k[kr.col_ptr()[j]..kr.col_ptr()[j + 1]]);
            values.extend(borders.iter().map(|b| b[j]));
        }
        for b in borders {
            values.extend_from_slice(&b[..n]);
        }
        let m = SparseColMatRef::new(self.pattern.as_ref(), &values);
        self.lu.factorize(m).ok()?;
        let mut g = 0.0;
        let mut v = Vec::with_capacity(nb);
        for l in 0..nb {
            let mut rhs = vec![0.0; n + nb];
            rhs[n + l] = 1.0;
            self.lu.solve(&mut rhs);
            g += rhs[n + l];
            rhs.truncate(n);
            v.push(rhs);
        }
        let g = g / nb as f64;
        (g.is_finite() && v.iter().flatten().all(|a| a.is_finite())).then_some((g, v))
    }

    /// `Z` of `[K B; Bᵀ 0][Z; ζ] = [r; 0]` with the last factorisation (`nb` borders).
    pub fn solve_for(&mut self, r: &[f64], nb: usize) -> Vec<f64> {
        let mut rhs = r.to_vec();
        rhs.resize(self.n + nb, 0.0);
        self.lu.solve(&mut rhs);
        rhs.truncate(self.n);
        rhs
    }
}
