//! The validated sparse symmetric pencil (A, B) of det(λA + B) = 0 ((8.89), see
//! docs/theory.md), stored in
//! compressed sparse columns (faer `SparseColMat`), both triangles, sorted and without
//! duplicate entries.

use crate::ModalError;
use crate::linalg::norms::vector_norm;
use crate::problem::{SYMMETRY_ULPS, symmetric_mean};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};

/// A sparse symmetric pencil: mass matrix A (positive semidefinite; not checked here) and
/// stiffness matrix B, both n×n, finite, and symmetric within [`SYMMETRY_ULPS`]·u·max|entry|;
/// stored symmetrised exactly, with the union of both triangles' patterns.
#[derive(Debug, Clone)]
pub struct SparsePencil {
    a: SparseColMat<usize, f64>,
    b: SparseColMat<usize, f64>,
}

/// A compressed column matrix in plain vectors (sorted rows, no duplicates).
#[derive(Debug, Clone, Default)]
pub(crate) struct Csc {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    pub val: Vec<f64>,
}

impl Csc {
    /// Columns from (row, col, value) entries with valid indices, summing duplicates: a counting
    /// sort by column, then a sort of each column by row.
    fn from_entries(n: usize, entries: impl Iterator<Item = (usize, usize, f64)> + Clone) -> Self {
        let mut count = vec![0usize; n + 1];
        for (_, c, _) in entries.clone() {
            count[c + 1] += 1;
        }
        for j in 0..n {
            count[j + 1] += count[j];
        }
        let total = count[n];
        let mut next = count.clone();
        let mut rows = vec![0usize; total];
        let mut vals = vec![0.0; total];
        for (r, c, v) in entries {
            rows[next[c]] = r;
            vals[next[c]] = v;
            next[c] += 1;
        }
        let mut out = Csc {
            n,
            col_ptr: Vec::with_capacity(n + 1),
            row_idx: Vec::with_capacity(total),
            val: Vec::with_capacity(total),
        };
        out.col_ptr.push(0);
        let mut pairs: Vec<(usize, f64)> = Vec::new();
        for j in 0..n {
            pairs.clear();
            pairs.extend((count[j]..count[j + 1]).map(|k| (rows[k], vals[k])));
            pairs.sort_by_key(|p| p.0);
            for &(r, v) in &pairs {
                if out.row_idx.len() > out.col_ptr[j] && out.row_idx.last() == Some(&r) {
                    if let Some(last) = out.val.last_mut() {
                        *last += v;
                    }
                } else {
                    out.row_idx.push(r);
                    out.val.push(v);
                }
            }
            out.col_ptr.push(out.row_idx.len());
        }
        out
    }

    /// The transpose (counting sort by row keeps each new column sorted).
    fn transpose(&self) -> Self {
        let n = self.n;
        Csc::from_entries(
            n,
            (0..n).flat_map(move |j| {
                (self.col_ptr[j]..self.col_ptr[j + 1]).map(move |k| (j, self.row_idx[k], self.val[k]))
            }),
        )
    }

    /// α·X + β·Y on the union pattern (both sorted).
    pub fn combine(alpha: f64, x: &Csc, beta: f64, y: &Csc) -> Csc {
        Self::merge(x, y, |u, v| alpha * u + beta * v)
    }

    /// f(x_ij, y_ij) on the union pattern (both sorted), an entry missing from one taken as 0.
    fn merge(x: &Csc, y: &Csc, f: impl Fn(f64, f64) -> f64) -> Csc {
        let n = x.n;
        let mut out = Csc {
            n,
            col_ptr: Vec::with_capacity(n + 1),
            row_idx: Vec::with_capacity(x.row_idx.len().max(y.row_idx.len())),
            val: Vec::with_capacity(x.row_idx.len().max(y.row_idx.len())),
        };
        out.col_ptr.push(0);
        for j in 0..n {
            let (mut p, pe) = (x.col_ptr[j], x.col_ptr[j + 1]);
            let (mut q, qe) = (y.col_ptr[j], y.col_ptr[j + 1]);
            while p < pe || q < qe {
                let rp = if p < pe { x.row_idx[p] } else { usize::MAX };
                let rq = if q < qe { y.row_idx[q] } else { usize::MAX };
                let (r, v) = if rp == rq {
                    let v = f(x.val[p], y.val[q]);
                    p += 1;
                    q += 1;
                    (rp, v)
                } else if rp < rq {
                    p += 1;
                    (rp, f(x.val[p - 1], 0.0))
                } else {
                    q += 1;
                    (rq, f(0.0, y.val[q - 1]))
                };
                out.row_idx.push(r);
                out.val.push(v);
            }
            out.col_ptr.push(out.row_idx.len());
        }
        out
    }

    /// The faer matrix of these columns (valid by construction: sorted, in range).
    pub fn to_faer(&self) -> SparseColMat<usize, f64> {
        // SAFETY: col_ptr is non-decreasing from 0 to nnz, every column's rows are strictly
        // increasing and < n (built by from_entries/combine from validated indices).
        let symbolic = unsafe {
            SymbolicSparseColMat::new_unchecked(self.n, self.n, self.col_ptr.clone(), None, self.row_idx.clone())
        };
        SparseColMat::new(symbolic, self.val.clone())
    }

    fn from_faer(m: SparseColMatRef<'_, usize, f64>) -> Self {
        let n = m.ncols();
        let (symbolic, val) = m.parts();
        let entries = (0..n).flat_map(move |j| {
            let range = symbolic.col_range(j);
            range.map(move |k| (symbolic.row_idx()[k], j, val[k]))
        });
        Csc::from_entries(n, entries)
    }
}

/// Checks shape, indices and finiteness of one matrix's entries.
fn check_entries(
    what: &'static str,
    n: usize,
    entries: impl Iterator<Item = (usize, usize, f64)>,
) -> Result<f64, ModalError> {
    let mut max_abs = 0.0_f64;
    for (r, c, v) in entries {
        if r >= n || c >= n {
            return Err(ModalError::IndexOutOfRange {
                what,
                row: r,
                col: c,
                dim: n,
            });
        }
        if !v.is_finite() {
            return Err(ModalError::NonFinite {
                what,
                row: r,
                col: c,
                value: v,
            });
        }
        max_abs = max_abs.max(v.abs());
    }
    Ok(max_abs)
}

/// Checks symmetry of a canonical matrix within SYMMETRY_ULPS·u·max|entry| and returns ½(M + Mᵀ)
/// (each entry by [`symmetric_mean`], as the dense [`crate::PencilProblem`] takes it).
fn symmetrised(what: &'static str, m: Csc, max_abs: f64) -> Result<Csc, ModalError> {
    let t = m.transpose();
    let tolerance = SYMMETRY_ULPS * f64::EPSILON * max_abs;
    let difference = Csc::combine(1.0, &m, -1.0, &t);
    for j in 0..m.n {
        for k in difference.col_ptr[j]..difference.col_ptr[j + 1] {
            let d = difference.val[k].abs();
            if d > tolerance {
                return Err(ModalError::NotSymmetric {
                    what,
                    row: difference.row_idx[k],
                    col: j,
                    difference: d,
                    tolerance,
                });
            }
        }
    }
    Ok(Csc::merge(&m, &t, symmetric_mean))
}

impl SparsePencil {
    /// Validates two faer sparse matrices (full symmetric storage, both triangles): square, equal
    /// sizes, finite, symmetric within [`SYMMETRY_ULPS`]·u·max|entry|.
    pub fn new(a: SparseColMatRef<'_, usize, f64>, b: SparseColMatRef<'_, usize, f64>) -> Result<Self, ModalError> {
        let n = a.nrows();
        for (what, m) in [("A", a), ("B", b)] {
            if m.nrows() != n || m.ncols() != n {
                return Err(ModalError::BadShape {
                    what,
                    rows: m.nrows(),
                    cols: m.ncols(),
                    expected: n,
                });
            }
        }
        let (ca, cb) = (Csc::from_faer(a), Csc::from_faer(b));
        Self::from_csc(ca, cb)
    }

    /// Validates A and B given as n×n triplets (row, col, value), both triangles; duplicates are
    /// summed (finite-element assembly). Indices must be < n.
    pub fn from_triplets(
        n: usize,
        a: &[Triplet<usize, usize, f64>],
        b: &[Triplet<usize, usize, f64>],
    ) -> Result<Self, ModalError> {
        check_every_coordinate_used(n, a, b)?;
        let entries = |t: &[Triplet<usize, usize, f64>]| t.iter().map(|e| (e.row, e.col, e.val)).collect::<Vec<_>>();
        let (ea, eb) = (entries(a), entries(b));
        check_entries("A", n, ea.iter().copied())?;
        check_entries("B", n, eb.iter().copied())?;
        Self::from_csc(
            Csc::from_entries(n, ea.iter().copied()),
            Csc::from_entries(n, eb.iter().copied()),
        )
    }

    fn from_csc(a: Csc, b: Csc) -> Result<Self, ModalError> {
        let n = a.n;
        let entries = |m: &Csc| -> Vec<(usize, usize, f64)> {
            (0..n)
                .flat_map(|j| (m.col_ptr[j]..m.col_ptr[j + 1]).map(move |k| (m.row_idx[k], j, m.val[k])))
                .collect()
        };
        let max_a = check_entries("A", n, entries(&a).into_iter())?;
        let max_b = check_entries("B", n, entries(&b).into_iter())?;
        let a = symmetrised("A", a, max_a)?;
        let b = symmetrised("B", b, max_b)?;
        Ok(Self {
            a: a.to_faer(),
            b: b.to_faer(),
        })
    }

    /// The order n.
    pub fn dim(&self) -> usize {
        self.a.nrows()
    }

    /// The mass matrix A (symmetrised).
    pub fn a(&self) -> SparseColMatRef<'_, usize, f64> {
        self.a.as_ref()
    }

    /// The stiffness matrix B (symmetrised).
    pub fn b(&self) -> SparseColMatRef<'_, usize, f64> {
        self.b.as_ref()
    }

    /// Number of stored entries of A and B.
    pub fn nnz(&self) -> (usize, usize) {
        (self.a.val().len(), self.b.val().len())
    }

    pub(crate) fn csc_a(&self) -> Csc {
        Csc::from_faer(self.a.as_ref())
    }

    pub(crate) fn csc_b(&self) -> Csc {
        Csc::from_faer(self.b.as_ref())
    }
}

/// y = M x for a full-storage sparse matrix.
pub(crate) fn mul(m: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64]) {
    y.fill(0.0);
    let (symbolic, val) = m.parts();
    let rows = symbolic.row_idx();
    for (j, xj) in x.iter().enumerate() {
        if *xj == 0.0 {
            continue;
        }
        for k in symbolic.col_range(j) {
            y[rows[k]] += val[k] * xj;
        }
    }
}

/// Frobenius norm of a sparse matrix: the norm of its stored values, scaled where their sum of
/// squares would over- or underflow.
pub(crate) fn frobenius(m: SparseColMatRef<'_, usize, f64>) -> f64 {
    vector_norm(faer::ColRef::from_slice(m.val()))
}

/// |x|ᵀ |M| |x|: the scale of the rounding error of xᵀMx.
pub(crate) fn abs_quadratic(m: SparseColMatRef<'_, usize, f64>, x: &[f64]) -> f64 {
    let (symbolic, val) = m.parts();
    let rows = symbolic.row_idx();
    let mut s = 0.0;
    for (j, xj) in x.iter().enumerate() {
        for k in symbolic.col_range(j) {
            s += (val[k] * x[rows[k]] * xj).abs();
        }
    }
    s
}

/// Every coordinate 0..n has an entry (of any value) in A or B: otherwise
/// [`ModalError::EmptyCoordinate`]. Costs O(nnz log nnz) and allocates only the entries' row
/// indices, never anything of size n, so a declared order far beyond the entries is refused
/// before it is allocated. Out-of-range indices are left to the entry checks.
pub fn check_every_coordinate_used(
    n: usize,
    a: &[Triplet<usize, usize, f64>],
    b: &[Triplet<usize, usize, f64>],
) -> Result<(), ModalError> {
    let mut rows: Vec<usize> = a.iter().chain(b).map(|e| e.row).filter(|&r| r < n).collect();
    rows.sort_unstable();
    rows.dedup();
    let first_missing = rows
        .iter()
        .enumerate()
        .find(|(k, r)| *k != **r)
        .map_or(rows.len(), |(k, _)| k);
    if first_missing < n {
        return Err(ModalError::EmptyCoordinate {
            index: first_missing,
            order: n,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(r: usize, c: usize, v: f64) -> Triplet<usize, usize, f64> {
        Triplet::new(r, c, v)
    }

    #[test]
    fn duplicates_are_summed_and_symmetry_checked() {
        let a = [t(0, 0, 1.0), t(1, 1, 1.0), t(1, 1, 1.0)];
        let b = [t(0, 0, 2.0), t(0, 1, -1.0), t(1, 0, -1.0), t(1, 1, 2.0)];
        let p = SparsePencil::from_triplets(2, &a, &b).expect("valid");
        assert_eq!(p.a().val(), &[1.0, 2.0]);
        let bad = [t(0, 0, 2.0), t(0, 1, -1.0), t(1, 1, 2.0)];
        assert!(matches!(
            SparsePencil::from_triplets(2, &a, &bad),
            Err(ModalError::NotSymmetric { what: "B", .. })
        ));
        assert!(matches!(
            SparsePencil::from_triplets(2, &[t(2, 0, 1.0)], &b),
            Err(ModalError::IndexOutOfRange { what: "A", row: 2, .. })
        ));
        assert!(matches!(
            SparsePencil::from_triplets(2, &a, &[t(1, 1, f64::NAN)]),
            Err(ModalError::NonFinite {
                what: "B",
                row: 1,
                col: 1,
                ..
            })
        ));
    }
}
