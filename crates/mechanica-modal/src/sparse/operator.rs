//! The shift-invert operator x ↦ K⁻¹(Ax) with the Cholesky factor of K = B − σA, the mass
//! matrix as the iteration applies it, and the sequential block products of the iteration.

use crate::error::ModalError;
use crate::sparse::pencil::{Csc, mul};
use crate::sparse::supernodal::SupernodalSolver;
use crate::tuning::Tuning;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};
use std::time::{Duration, Instant};

/// Shift-invert operator x ↦ K⁻¹(Ax) with the Cholesky factor of K = B − σA.
pub(crate) struct Operator<'a> {
    pub(crate) symbolic: &'a SymbolicCholesky<usize>,
    pub(crate) values: Vec<f64>,
    pub(crate) a: Mass<'a>,
    pub(crate) applications: usize,
    pub(crate) solve_time: Duration,
    /// Row-interleaved copy of the block being solved (kept: no page faults per solve).
    pub(crate) work: Vec<f64>,
}

impl Operator<'_> {
    /// x ← K⁻¹x for an n × b column-major block, counted and timed.
    pub(crate) fn solve_block(&mut self, x: &mut [f64], b: usize) {
        let clock = Instant::now();
        solve_with(self.symbolic, &self.values, x, b, &mut self.work);
        self.applications += b;
        self.solve_time += clock.elapsed();
    }
}

/// x ← K⁻¹x for an n × b column-major block (one pass over the factor for all columns) with
/// the factor (`symbolic`, `values`) of K and the scratch `work`: [`SupernodalSolver`] for a
/// supernodal factor, faer's solve for a simplicial one. Sequential: on a shared machine
/// threaded triangular solves contend badly.
pub(crate) fn solve_with(
    symbolic: &SymbolicCholesky<usize>,
    values: &[f64],
    x: &mut [f64],
    b: usize,
    work: &mut Vec<f64>,
) {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(supernodal) => {
            let fwd = symbolic.perm().map(|p| p.arrays().0);
            SupernodalSolver::new(supernodal, values, fwd).solve_in_place(x, b, work);
        }
        SymbolicCholeskyRaw::Simplicial(_) => {
            let n = symbolic.nrows();
            let req = symbolic.solve_in_place_scratch::<f64>(b, Par::Seq);
            let mut mem = MemBuffer::new(req);
            LltRef::new(symbolic, values).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(x, n, b),
                Par::Seq,
                MemStack::new(&mut mem),
            );
        }
    }
}

/// Factors K = B − σA (lower triangle read) with a symbolic analysis of its pattern; on a
/// non-positive pivot returns its index.
pub(crate) fn factor_llt(symbolic: &SymbolicCholesky<usize>, k: &Csc) -> Result<Result<Vec<f64>, usize>, ModalError> {
    let m = k.to_faer();
    // Sequential: no slower than two threads on 2-D grids (measured in docs/benchmarks.md), and
    // no contention on a shared machine.
    let par = Par::Seq;
    let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
    let mut mem = MemBuffer::try_new(req).map_err(|_| ModalError::Factorization {
        what: "B − σA",
        detail: "out of memory for the factorization workspace".into(),
    })?;
    let mut values = vec![0.0; symbolic.len_val()];
    let result = symbolic.factorize_numeric_llt(
        &mut values,
        m.as_ref(),
        Side::Lower,
        Default::default(),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    );
    Ok(match result {
        Ok(_) => Ok(values),
        Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => Err(index),
    })
}

/// The mass matrix A as the iteration applies it (a dozen products per block step): a diagonal
/// A (lumped masses, the common case) elementwise, which vectorises; any other by columns.
#[derive(Clone, Copy)]
pub(crate) enum Mass<'a> {
    /// The diagonal entries, in order.
    Diagonal(&'a [f64]),
    Sparse(faer::sparse::SparseColMatRef<'a, usize, f64>),
}

impl<'a> Mass<'a> {
    pub(crate) fn of(a: faer::sparse::SparseColMatRef<'a, usize, f64>) -> Self {
        let (symbolic, val) = a.parts();
        let n = a.ncols();
        let diagonal = val.len() == n
            && symbolic.col_ptr().iter().enumerate().all(|(j, &p)| p == j)
            && symbolic.row_idx().iter().enumerate().all(|(k, &i)| i == k);
        if diagonal { Mass::Diagonal(val) } else { Mass::Sparse(a) }
    }

    pub(crate) fn nrows(&self) -> usize {
        match self {
            Mass::Diagonal(d) => d.len(),
            Mass::Sparse(a) => a.nrows(),
        }
    }

    /// y = A x.
    pub(crate) fn apply(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Mass::Diagonal(d) => {
                for ((y, x), d) in y.iter_mut().zip(x).zip(*d) {
                    *y = d * x;
                }
            }
            Mass::Sparse(a) => mul(*a, x, y),
        }
    }

    /// Y = A X for n × b column-major blocks.
    pub(crate) fn apply_block(&self, x: &[f64], y: &mut [f64]) {
        let n = self.nrows();
        for (xc, yc) in x.chunks_exact(n).zip(y.chunks_exact_mut(n)) {
            self.apply(xc, yc);
        }
    }
}

/// lhs · rhs, sequential (faer's threaded kernels contend on a shared machine at these sizes).
pub(crate) fn product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(lhs.nrows(), rhs.ncols());
    product_to(out.as_mut(), lhs, rhs);
    out
}

/// out ← lhs · rhs, with `out` the column-major storage of the product (sequential).
pub(crate) fn product_into(out: &mut [f64], lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) {
    product_to(
        MatMut::from_column_major_slice_mut(out, lhs.nrows(), rhs.ncols()),
        lhs,
        rhs,
    );
}

/// target ← lhs · rhs, sequential.
fn product_to(target: MatMut<'_, f64>, lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) {
    faer::linalg::matmul::matmul(target, faer::Accum::Replace, lhs, rhs, 1.0, Par::Seq);
}

pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// K = B − σA factored at a shift σ below the spectrum.
pub(crate) struct ShiftedFactor {
    /// The union of the patterns of A and B (that of every B − sA).
    pub(crate) pattern: Csc,
    /// Its symbolic Cholesky analysis (AMD ordering).
    pub(crate) symbolic: SymbolicCholesky<usize>,
    /// The shift σ.
    pub(crate) sigma: f64,
    /// Cholesky factorizations tried to find it.
    pub(crate) attempts: usize,
}

/// Factors K = B − σA (`b`, `a`) at the given shift, or at the automatic σ = −√u·‖B‖_F/‖A‖_F
/// (`ratio`) lowered by factors of 1000 while K is not positive definite (at most
/// [`Tuning::shift_attempts`] tries); returns the factor's numeric values beside it.
/// [`ModalError::NoDefiniteShift`] when no tried shift gives a positive definite K.
pub(crate) fn factor_below_spectrum(
    a: &Csc,
    b: &Csc,
    ratio: f64,
    shift: Option<f64>,
) -> Result<(ShiftedFactor, Vec<f64>), ModalError> {
    let pattern = Csc::combine(1.0, b, 1.0, a);
    let symbolic = factorize_symbolic_cholesky(
        pattern.to_faer().symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        // faer's own choice (supernodal on large grids): a simplicial factor has cheaper solves
        // but a slower factorization, which costs more than that saves.
        CholeskySymbolicParams::default(),
    )
    .map_err(|e| ModalError::Factorization {
        what: "B − σA (symbolic)",
        detail: format!("{e:?}"),
    })?;
    let mut sigma = shift.unwrap_or(-f64::EPSILON.sqrt() * ratio.max(f64::MIN_POSITIVE));
    let mut attempts = 0;
    let values = loop {
        attempts += 1;
        match factor_llt(&symbolic, &Csc::combine(1.0, b, -sigma, a))? {
            Ok(values) => break values,
            Err(pivot) => {
                if shift.is_some() || attempts >= Tuning::DEFAULT.shift_attempts {
                    return Err(ModalError::NoDefiniteShift {
                        lowest_shift: sigma,
                        pivot,
                    });
                }
                sigma *= 1e3;
            }
        }
    };
    let factor = ShiftedFactor {
        pattern,
        symbolic,
        sigma,
        attempts,
    };
    Ok((factor, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diagonal fast path is taken exactly for diagonal matrices, and agrees with the
    /// general product; n stored entries that are not the diagonal (a column with two, another
    /// with none) are not mistaken for it.
    #[test]
    fn mass_applies_diagonal_and_general_matrices_alike() {
        use faer::sparse::{SparseColMat, Triplet};
        let matrix = |entries: &[(usize, usize, f64)]| {
            let triplets: Vec<_> = entries.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
            SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &triplets).expect("valid")
        };
        let x = [1.5, -2.0, 0.25];
        let diagonal = matrix(&[(0, 0, 2.0), (1, 1, 3.0), (2, 2, 4.0)]);
        let mass = Mass::of(diagonal.as_ref());
        assert!(matches!(mass, Mass::Diagonal(_)));
        let mut y = [0.0; 3];
        mass.apply(&x, &mut y);
        assert_eq!(y, [3.0, -6.0, 1.0]);
        let shifted = matrix(&[(0, 0, 2.0), (1, 0, 3.0), (2, 2, 4.0)]);
        let mass = Mass::of(shifted.as_ref());
        assert!(matches!(mass, Mass::Sparse(_)));
        mass.apply(&x, &mut y);
        assert_eq!(y, [3.0, 4.5, 1.0]);
    }
}
