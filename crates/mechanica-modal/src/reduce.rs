//! Reduction of the definite pencil (A, B) to a standard symmetric problem: A = L Lᵀ
//! (Cholesky), C = L⁻¹ B L⁻ᵀ, and back-transformation X = L⁻ᵀ Y.
//!
//! The reduction follows the blocked algorithm of LAPACK `dsygst` (itype 1, lower), written
//! recursively: it costs about n³ flops by updating only the lower triangle of the trailing
//! block with a symmetric rank-2k update, instead of the 2n³ of two full triangular solves.

use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{BlockStructure, matmul as tri_matmul};
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::reborrow::ReborrowMut;
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// Below this order the reduction uses two plain triangular solves (cheap at that size).
const BASE_CASE: usize = 48;

/// The outcome of a Cholesky attempt on the mass matrix A.
pub(crate) enum Cholesky {
    /// A = L Lᵀ with every pivot l_ii² above the semidefiniteness tolerance.
    Factor(Mat<f64>),
    /// Pivot `pivot` was not positive, or smaller than n·u·max|A| (numerically singular).
    Failed {
        /// Index of the first failing or negligible pivot.
        pivot: usize,
    },
}

/// Cholesky factor L (lower) of A = L Lᵀ. A pivot l_ii² ≤ n·u·max_j A_jj counts as failed,
/// since A is then semidefinite to working precision.
pub(crate) fn cholesky(a: MatRef<'_, f64>, par: Par) -> Cholesky {
    cholesky_owned(a.to_owned(), par)
}

/// [`cholesky`] of a matrix the caller no longer needs (factored in place, no copy).
pub(crate) fn cholesky_owned(mut l: Mat<f64>, par: Par) -> Cholesky {
    if let Err(pivot) = factor_in_place(l.as_mut(), par) {
        return Cholesky::Failed { pivot };
    }
    let n = l.nrows();
    for j in 0..n {
        for i in 0..j {
            l[(i, j)] = 0.0;
        }
    }
    Cholesky::Factor(l)
}

/// Factors the lower triangle of `l` in place (the strict upper triangle is neither read nor
/// cleared); Err(pivot) at the first pivot that is not positive or is negligible (l_ii² ≤
/// n·u·max_j l_jj before factoring).
pub(crate) fn factor_in_place(mut l: MatMut<'_, f64>, par: Par) -> Result<(), usize> {
    let n = l.nrows();
    let mut mem = faer::dyn_stack::MemBuffer::new(
        faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(n, par, Default::default()),
    );
    let stack = faer::dyn_stack::MemStack::new(&mut mem);
    let max_diag = (0..n).map(|i| l[(i, i)]).fold(0.0_f64, f64::max);
    let result = faer::linalg::cholesky::llt::factor::cholesky_in_place(
        l.rb_mut(),
        Default::default(),
        par,
        stack,
        Default::default(),
    );
    if let Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) = result {
        return Err(index);
    }
    let tolerance = n as f64 * f64::EPSILON * max_diag;
    match (0..n).find(|&i| l[(i, i)] * l[(i, i)] <= tolerance) {
        Some(pivot) => Err(pivot),
        None => Ok(()),
    }
}

/// C = L⁻¹ B L⁻ᵀ, reading only the lower triangle of `b`; returns C with its lower triangle
/// valid (the upper triangle is unspecified).
pub fn reduce(l: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = b.to_owned();
    reduce_in_place(l, c.as_mut(), par);
    c
}

/// Copies the strict lower triangle of `c` onto its upper triangle.
fn mirror_lower(mut c: MatMut<'_, f64>) {
    let n = c.nrows();
    for j in 0..n {
        for i in 0..j {
            c[(i, j)] = c[(j, i)];
        }
    }
}

/// Recursive sygst: with L = [L11 0; L21 L22] and B split alike, L C Lᵀ = B gives
/// C11 = L11⁻¹ B11 L11⁻ᵀ, W = B21 L11⁻ᵀ − ½ L21 C11, B22' = B22 − (W L21ᵀ + L21 Wᵀ),
/// C21 = L22⁻¹ (W − ½ L21 C11), C22 = L22⁻¹ B22' L22⁻ᵀ.
fn reduce_in_place(l: MatRef<'_, f64>, mut c: MatMut<'_, f64>, par: Par) {
    let n = c.nrows();
    if n <= BASE_CASE {
        mirror_lower(c.as_mut());
        solve_lower_triangular_in_place(l, c.as_mut(), par);
        solve_lower_triangular_in_place(l, c.as_mut().transpose_mut(), par);
        return;
    }
    let n1 = n / 2;
    let (l11, _, l21, l22) = l.split_at(n1, n1);
    let (mut c11, _, mut c21, mut c22) = c.split_at_mut(n1, n1);
    reduce_in_place(l11, c11.as_mut(), par);
    mirror_lower(c11.as_mut());
    // W = B21 L11⁻ᵀ  ⇔  L11 Wᵀ = B21ᵀ.
    solve_lower_triangular_in_place(l11, c21.as_mut().transpose_mut(), par);
    matmul(c21.as_mut(), Accum::Add, l21, c11.as_ref(), -0.5, par);
    tri_matmul(
        c22.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Add,
        c21.as_ref(),
        BlockStructure::Rectangular,
        l21.transpose(),
        BlockStructure::Rectangular,
        -1.0,
        par,
    );
    tri_matmul(
        c22.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Add,
        l21,
        BlockStructure::Rectangular,
        c21.as_ref().transpose(),
        BlockStructure::Rectangular,
        -1.0,
        par,
    );
    matmul(c21.as_mut(), Accum::Add, l21, c11.as_ref(), -0.5, par);
    solve_lower_triangular_in_place(l22, c21.as_mut(), par);
    reduce_in_place(l22, c22, par);
}

/// The plain reduction C = L⁻¹ (L⁻¹ B)ᵀ by two full triangular solves (2n³ flops); kept as the
/// reference the benchmarks and tests compare the symmetric reduction against.
pub fn reduce_two_solves(l: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = b.to_owned();
    solve_lower_triangular_in_place(l, c.as_mut(), par);
    solve_lower_triangular_in_place(l, c.as_mut().transpose_mut(), par);
    c
}

/// X = L⁻ᵀ Y in place (back-transformation of eigenvectors of C to those of the pencil).
pub fn back_transform(l: MatRef<'_, f64>, y: MatMut<'_, f64>, par: Par) {
    solve_upper_triangular_in_place(l.transpose(), y, par);
}

/// The Cholesky factor L (lower, upper triangle zeroed) of A = LLᵀ exactly as [`crate::solve`]
/// computes it, or None if A is not numerically positive definite (for stage benchmarks).
pub fn cholesky_lower(a: MatRef<'_, f64>, par: Par) -> Option<Mat<f64>> {
    match cholesky(a, par) {
        Cholesky::Factor(l) => Some(l),
        Cholesky::Failed { .. } => None,
    }
}

/// Public entry to the symmetric reduction for benchmarks: returns (L, C) with C's lower
/// triangle valid, or None if A is not numerically positive definite.
pub fn cholesky_and_reduce(a: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Option<(Mat<f64>, Mat<f64>)> {
    match cholesky(a, par) {
        Cholesky::Factor(l) => {
            let c = reduce(l.as_ref(), b, par);
            Some((l, c))
        }
        Cholesky::Failed { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spd(n: usize, seed: u64) -> Mat<f64> {
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let g = Mat::from_fn(n, n, |_, _| next());
        let mut a = &g * g.transpose();
        for i in 0..n {
            a[(i, i)] += n as f64;
        }
        a
    }

    #[test]
    fn symmetric_reduction_matches_two_triangular_solves() {
        for n in [1, 5, 48, 49, 130, 257] {
            let a = spd(n, 1);
            let b = spd(n, 2);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("spd matrix must factor")
            };
            let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
            let r = reduce_two_solves(l.as_ref(), b.as_ref(), Par::Seq);
            // Both are backward stable reductions of the same C; they agree to a few n·u·‖C‖.
            let scale = r.norm_max();
            let tol = 8.0 * n as f64 * f64::EPSILON * scale;
            for j in 0..n {
                for i in j..n {
                    assert!((c[(i, j)] - r[(i, j)]).abs() <= tol, "n={n} ({i},{j})");
                }
            }
        }
    }
}
