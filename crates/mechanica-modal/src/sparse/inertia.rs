//! Sylvester inertia of the sparse matrix B − sA: how many modes of a [`SparsePencil`] lie below
//! a shift s (the sparse counterpart of [`crate::count_below`]).
//!
//! B − sA is factored by faer's supernodal LBLᵀ with Bunch–Kaufman pivoting inside each supernode
//! ("intranodal"; the fill-reducing AMD ordering is kept), and the signs of the 1×1 and 2×2 blocks
//! of the block-diagonal factor are counted. For patterns faer keeps simplicial (e.g. diagonal
//! matrices) the factorization is an unpivoted LDLᵀ. By Sylvester's law of inertia the number of
//! negative eigenvalues equals the number of modes with ω² < s when A is positive definite (or
//! semidefinite with B positive definite on the null space of A). Pivoting confined to supernodes
//! is not backward stable in the worst case: the smallest and largest |pivot| are reported so that
//! a suspicious factorization (tiny pivots, growth) can be recognised.

use crate::sparse::pencil::{Csc, SparsePencil};
use crate::{InertiaCount, ModalError};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::{Par, Side};

/// The inertia of B − sA with the pivot sizes of its factorization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseInertiaCount {
    /// The counts (as for the dense [`crate::count_below`]).
    pub count: InertiaCount,
    /// Smallest |eigenvalue| over the 1×1 and 2×2 pivot blocks (0 when not known: dense path).
    pub min_pivot: f64,
    /// Largest |eigenvalue| over the pivot blocks (growth shows as max_pivot ≫ ‖B − sA‖).
    pub max_pivot: f64,
}

/// The symbolic analysis (AMD ordering, supernodal structure) of a pattern, reusable for every
/// shift of the same pencil.
pub(crate) fn symbolic_supernodal(k: &Csc) -> Result<SymbolicCholesky<usize>, ModalError> {
    let m = k.to_faer();
    factorize_symbolic_cholesky(
        m.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .map_err(|e| ModalError::Factorization {
        what: "B − sA (symbolic)",
        detail: format!("{e:?}"),
    })
}

/// Counts the modes of the sparse pencil with ω² below `shift`.
pub fn count_below_sparse(pencil: &SparsePencil, shift: f64) -> Result<SparseInertiaCount, ModalError> {
    if !shift.is_finite() {
        return Err(ModalError::BadShift(shift));
    }
    let (a, b) = (pencil.csc_a(), pencil.csc_b());
    let k = Csc::combine(1.0, &b, -shift, &a);
    let symbolic = symbolic_supernodal(&k)?;
    inertia_with(&symbolic, &k, shift)
}

/// The inertia of the matrix `k` (= B − shift·A) with a symbolic analysis of its pattern.
pub(crate) fn inertia_with(
    symbolic: &SymbolicCholesky<usize>,
    k: &Csc,
    shift: f64,
) -> Result<SparseInertiaCount, ModalError> {
    let n = k.n;
    if n == 0 {
        return Ok(SparseInertiaCount {
            count: InertiaCount {
                shift,
                below: 0,
                zero: 0,
                above: 0,
            },
            min_pivot: 0.0,
            max_pivot: 0.0,
        });
    }
    let (values, subdiag) = factor_lblt(symbolic, k)?;
    let pivots = pivot_eigenvalues(symbolic, &values, &subdiag, n);
    Ok(count_signs(pivots, shift))
}

/// The intranode Bunch–Kaufman LBLᵀ factorization of `k` (lower triangle read, sequential): the
/// factor's values and the subdiagonal of its 2×2 pivot blocks.
fn factor_lblt(symbolic: &SymbolicCholesky<usize>, k: &Csc) -> Result<(Vec<f64>, Vec<f64>), ModalError> {
    let n = k.n;
    let m = k.to_faer();
    let par = Par::Seq;
    let params = Default::default();
    let req = symbolic.factorize_numeric_intranode_lblt_scratch::<f64>(par, params);
    let mut mem = MemBuffer::try_new(req).map_err(|_| ModalError::Factorization {
        what: "B − sA",
        detail: "out of memory for the factorization workspace".into(),
    })?;
    let mut values = vec![0.0; symbolic.len_val()];
    let mut subdiag = vec![0.0; n];
    let mut fwd = vec![0usize; n];
    let mut inv = vec![0usize; n];
    let lblt = symbolic.factorize_numeric_intranode_lblt(
        &mut values,
        &mut subdiag,
        &mut fwd,
        &mut inv,
        m.as_ref(),
        Side::Lower,
        par,
        MemStack::new(&mut mem),
        params,
    );
    let _ = lblt;
    Ok((values, subdiag))
}

/// The eigenvalues of the pivot blocks of a factor (`values`, `subdiag`), in any order.
fn pivot_eigenvalues(symbolic: &SymbolicCholesky<usize>, values: &[f64], subdiag: &[f64], n: usize) -> Vec<f64> {
    let mut pivots: Vec<f64> = Vec::with_capacity(n);
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(supernodal) => {
            let col_ptr_val = supernodal.col_ptr_for_val();
            let begin = supernodal.supernode_begin();
            let end = supernodal.supernode_end();
            let row_ptr = supernodal.col_ptr_for_row_idx();
            for s in 0..supernodal.n_supernodes() {
                let (start, stop) = (begin[s], end[s]);
                let size = stop - start;
                let rows = size + (row_ptr[s + 1] - row_ptr[s]);
                let block = &values[col_ptr_val[s]..col_ptr_val[s + 1]];
                let diag = |i: usize| block[i + i * rows];
                let mut i = 0;
                while i < size {
                    let e = subdiag[start + i];
                    if e != 0.0 && i + 1 < size {
                        let (d1, d2) = (diag(i), diag(i + 1));
                        let mean = 0.5 * (d1 + d2);
                        let radius = (0.25 * (d1 - d2) * (d1 - d2) + e * e).sqrt();
                        pivots.extend([mean - radius, mean + radius]);
                        i += 2;
                    } else {
                        pivots.push(diag(i));
                        i += 1;
                    }
                }
            }
        }
        SymbolicCholeskyRaw::Simplicial(simplicial) => {
            // faer falls back to an unpivoted LDLᵀ here; D sits on the diagonal of L.
            let factor = simplicial.factor();
            let rows = factor.row_idx();
            for j in 0..n {
                let d = factor.col_range(j).find(|&p| rows[p] == j).map_or(0.0, |p| values[p]);
                pivots.push(d);
            }
        }
    }
    pivots
}

/// The inertia at `shift` from the pivot blocks' eigenvalues: a pivot that is zero or not
/// finite counts as zero.
fn count_signs(pivots: Vec<f64>, shift: f64) -> SparseInertiaCount {
    let (mut below, mut zero, mut above) = (0, 0, 0);
    let (mut min_pivot, mut max_pivot) = (f64::INFINITY, 0.0_f64);
    for v in pivots {
        if !v.is_finite() || v == 0.0 {
            zero += 1;
            min_pivot = 0.0;
            continue;
        }
        min_pivot = min_pivot.min(v.abs());
        max_pivot = max_pivot.max(v.abs());
        if v < 0.0 {
            below += 1;
        } else {
            above += 1;
        }
    }
    SparseInertiaCount {
        count: InertiaCount {
            shift,
            below,
            zero,
            above,
        },
        min_pivot,
        max_pivot,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PencilProblem, count_below, testing};
    use faer::sparse::Triplet;

    fn sparse_of(m: &faer::Mat<f64>) -> Vec<Triplet<usize, usize, f64>> {
        let mut t = Vec::new();
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                if m[(i, j)] != 0.0 {
                    t.push(Triplet::new(i, j, m[(i, j)]));
                }
            }
        }
        t
    }

    #[test]
    fn sparse_count_agrees_with_dense_count_and_closed_form() {
        // A ring has double eigenvalues; the rotated chain is dense (one supernode).
        let (a, b) = testing::ring(40);
        let exact = testing::ring_omega_sq(40);
        let sparse = SparsePencil::from_triplets(40, &sparse_of(&a), &sparse_of(&b)).expect("valid");
        let dense = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid");
        for shift in [-1.0, 0.05, 0.5, 1.3, 2.1, 3.9, 5.0] {
            let s = count_below_sparse(&sparse, shift).expect("count");
            let d = count_below(&dense, shift).expect("count");
            assert_eq!(s.count.below, d.below, "shift {shift}: {s:?} {d:?}");
            assert_eq!(s.count.below, exact.iter().filter(|w| **w < shift).count());
            assert_eq!(s.count.below + s.count.above, 40);
        }
    }
}
