//! Reduction of the definite pencil (A, B) to a standard symmetric problem: A = L Lᵀ
//! (Cholesky), C = L⁻¹ B L⁻ᵀ, and back-transformation X = L⁻ᵀ Y.
//!
//! The reduction follows the blocked algorithm of LAPACK `dsygst` (itype 1, lower), one block
//! column per step: it costs about n³ flops by updating only the lower triangle of the trailing
//! block with a symmetric rank-2k update, instead of the 2n³ of two full triangular solves.
//!
//! A diagonal A (lumped masses, the usual mass matrix of finite-element and spring–mass models)
//! is recognised: L = diag(√a_ii), C_ij = b_ij/(l_i l_j) and x_i = y_i/l_i cost O(n²) instead
//! of the n³/3 + n³ + n³ flops of factor, reduction and back-transformation, and each entry of C
//! carries a relative error of a few u (no growth with the mass ratio). LAPACK's `dsygvd`
//! (SciPy's `eigh(B, A)`) does the dense work whatever A is. The test is exact (every
//! off-diagonal entry of the symmetrised A is zero); a nearly diagonal A takes the dense path.

use crate::runtime::fork_join::{by_column_chunks, by_column_chunks_at};
use crate::tuning::Tuning;
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{BlockStructure, matmul as tri_matmul};
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// `par` for a factorization or reduction of order `n` ([`crate::Tuning::parallel_factor_from`]).
fn factor_parallelism(n: usize, par: Par) -> Par {
    if n < Tuning::DEFAULT.parallel_factor_from {
        Par::Seq
    } else {
        par
    }
}

/// The outcome of a Cholesky attempt on the mass matrix A.
pub(crate) enum Cholesky {
    /// A = L Lᵀ with every pivot l_ii² above the semidefiniteness tolerance.
    Factor(Mat<f64>),
    /// Pivot `pivot` was not positive, or negligible (numerically singular): below n·u·max|A|,
    /// or for a mass matrix ([`cholesky_mass_owned`]) below n·u times its own diagonal entry.
    Failed {
        /// Index of the first failing or negligible pivot.
        pivot: usize,
    },
}

/// Cholesky factor L (lower) of A = L Lᵀ. A pivot l_ii² ≤ n·u·max_j A_jj counts as failed,
/// since A is then semidefinite to working precision.
pub(crate) fn cholesky(a: MatRef<'_, f64>, par: Par) -> Cholesky {
    cholesky_owned(Mat::from_fn(a.nrows(), a.ncols(), |i, j| lower_entry(a, i, j)), par)
}

/// Entry (i, j) of the lower triangle of `a`, zero above the diagonal: a copy made of these
/// reads only the half of `a` that the factorization and the reduction use.
pub(crate) fn lower_entry(a: MatRef<'_, f64>, i: usize, j: usize) -> f64 {
    if i >= j { a[(i, j)] } else { 0.0 }
}

/// [`cholesky`] of a matrix the caller no longer needs (factored in place, no copy). Its
/// strict upper triangle must be zero (as [`lower_entry`] leaves it): it is not read, and stays
/// zero as that of L.
pub(crate) fn cholesky_owned(mut l: Mat<f64>, par: Par) -> Cholesky {
    let factored = if is_diagonal(l.as_ref()) {
        factor_diagonal_in_place(l.as_mut())
    } else {
        factor_in_place(l.as_mut(), par)
    };
    match factored {
        Err(pivot) => Cholesky::Failed { pivot },
        Ok(()) => Cholesky::Factor(l),
    }
}

/// [`cholesky_owned`] of a mass matrix, with the pivot test scaled column by column: a pivot
/// fails when l_ii² ≤ n·u·a_ii (its own diagonal entry) rather than n·u·max_j a_jj. Cholesky's
/// rounding is invariant under diagonal scaling, so this is the test on the unit-diagonal
/// D^{-1/2}AD^{-1/2}: a graded mass matrix (a chain of point masses over decades) is not taken
/// for a semidefinite one because its light coordinates have small pivots beside heavy ones.
pub(crate) fn cholesky_mass_owned(mut l: Mat<f64>, par: Par) -> Cholesky {
    if is_diagonal(l.as_ref()) {
        return cholesky_owned(l, par);
    }
    let n = l.nrows();
    let diagonal: Vec<f64> = (0..n).map(|i| l[(i, i)]).collect();
    let factored = factor_recursive(l.as_mut(), factor_parallelism(n, par)).and_then(|()| {
        let tolerance = n as f64 * f64::EPSILON;
        match (0..n).find(|&i| {
            let pivot = l[(i, i)] * l[(i, i)];
            pivot.is_nan() || pivot <= tolerance * diagonal[i]
        }) {
            Some(pivot) => Err(pivot),
            None => Ok(()),
        }
    });
    match factored {
        Err(pivot) => Cholesky::Failed { pivot },
        Ok(()) => Cholesky::Factor(l),
    }
}

/// Whether the strict lower triangle of `m` is zero (an exact test: early exit at the first
/// nonzero, so a dense matrix costs a few reads).
pub(crate) fn is_diagonal(m: MatRef<'_, f64>) -> bool {
    (0..m.ncols()).all(|j| (j + 1..m.nrows()).all(|i| m[(i, j)] == 0.0))
}

/// [`factor_in_place`] of a diagonal A (lumped masses): l_ii = √a_ii. A pivot fails only when
/// it is not positive (or NaN): a lumped mass is massless only when it is exactly zero, never
/// for being small beside another mass, since each diagonal entry is its own exact pivot.
fn factor_diagonal_in_place(mut l: MatMut<'_, f64>) -> Result<(), usize> {
    let n = l.nrows();
    if let Some(pivot) = (0..n).find(|&i| {
        let pivot = l[(i, i)];
        pivot.is_nan() || pivot <= 0.0
    }) {
        return Err(pivot);
    }
    for i in 0..n {
        l[(i, i)] = l[(i, i)].sqrt();
    }
    Ok(())
}

/// Factors the lower triangle of `l` in place (the strict upper triangle is not read, and stays
/// zero if it was); Err(pivot) at the first pivot that is not positive or is negligible (l_ii² ≤
/// n·u·max_j l_jj before factoring).
pub(crate) fn factor_in_place(mut l: MatMut<'_, f64>, par: Par) -> Result<(), usize> {
    let (max_diag, par) = (max_diagonal(l.rb()), factor_parallelism(l.nrows(), par));
    factor_recursive(l.rb_mut(), par)?;
    check_pivots(l.rb(), max_diag)
}

/// Factors the lower triangle of `l` in place with no negligible-pivot test: Err(pivot) only at
/// a pivot that is not positive; the caller judges the pivots.
pub(crate) fn factor_unchecked(mut l: MatMut<'_, f64>, par: Par) -> Result<(), usize> {
    let par = factor_parallelism(l.nrows(), par);
    factor_recursive(l.rb_mut(), par)
}

/// The largest diagonal entry of `l`: before factoring, the scale of the pivot test.
pub(crate) fn max_diagonal(l: MatRef<'_, f64>) -> f64 {
    (0..l.nrows()).map(|i| l[(i, i)]).fold(0.0_f64, f64::max)
}

/// The pivot test of a finished factor: Err(pivot) at the first l_ii² that is NaN (an overflowed
/// elimination) or ≤ n·u·`max_diag`.
pub(crate) fn check_pivots(l: MatRef<'_, f64>, max_diag: f64) -> Result<(), usize> {
    let n = l.nrows();
    let tolerance = n as f64 * f64::EPSILON * max_diag;
    match (0..n).find(|&i| {
        let pivot = l[(i, i)] * l[(i, i)];
        pivot.is_nan() || pivot <= tolerance
    }) {
        Some(pivot) => Err(pivot),
        None => Ok(()),
    }
}

/// One sequential step of a blocked right-looking Cholesky: factors columns start..start+width
/// of `l` (the earlier ones factored) and subtracts their outer product from the trailing block.
pub(crate) fn factor_block_step(mut l: MatMut<'_, f64>, start: usize, width: usize) -> Result<(), usize> {
    let n = l.nrows();
    let rest = l.rb_mut().submatrix_mut(start, start, n - start, n - start);
    let (mut l11, _, mut l21, l22) = rest.split_at_mut(width, width);
    factor_recursive(l11.rb_mut(), Par::Seq).map_err(|pivot| pivot + start)?;
    solve_lower_triangular_in_place(l11.rb(), l21.rb_mut().transpose_mut(), Par::Seq);
    subtract_lower_product(l22, l21.rb(), l21.rb(), Par::Seq);
    Ok(())
}

/// Completes a blocked right-looking Cholesky whose first `start` columns are factored and
/// whose trailing block holds their Schur complement, on `par`'s threads; then the pivot test of
/// [`check_pivots`] with `max_diag`, the largest diagonal entry before factoring.
pub(crate) fn factor_trailing(mut l: MatMut<'_, f64>, start: usize, max_diag: f64, par: Par) -> Result<(), usize> {
    let rest = l.nrows() - start.min(l.nrows());
    let trailing = l.rb_mut().submatrix_mut(start, start, rest, rest);
    factor_recursive(trailing, factor_parallelism(rest, par)).map_err(|pivot| pivot + start)?;
    check_pivots(l.rb(), max_diag)
}

/// The number s of leading columns of an order-m lower triangle that hold `area` entries:
/// column j has m − j, so s·m − s²/2 = area (half the triangle: s = (1 − 1/√2)·m).
pub(crate) fn columns_holding(m: usize, area: f64) -> usize {
    let m_f = m as f64;
    let remaining = (m_f * m_f - 2.0 * area).max(0.0);
    ((m_f - remaining.sqrt()) as usize).min(m)
}

/// The lower triangle of `target` −= `lhs` `rhs`ᵀ (the other triangle is not touched).
pub(crate) fn subtract_lower_product(target: MatMut<'_, f64>, lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>, par: Par) {
    tri_matmul(
        target,
        BlockStructure::TriangularLower,
        Accum::Add,
        lhs,
        BlockStructure::Rectangular,
        rhs.transpose(),
        BlockStructure::Rectangular,
        -1.0,
        par,
    );
}

/// Recursive right-looking Cholesky (Gustavson, "Recursion leads to automatic variable
/// blocking for dense linear-algebra algorithms", IBM J. Res. Dev. 41, 1997): with
/// A = [A11 ·; A21 A22], L11 = chol(A11), L21 = A21 L11⁻ᵀ, then chol(A22 − L21 L21ᵀ) with the
/// update on the lower triangle only. Almost all flops land in two large matrix products, which
/// faer runs on every thread, so that it is faster than faer's own blocked factorization at
/// large orders (measured in docs/benchmarks.md). Err(pivot) at the first pivot that is not
/// positive.
fn factor_recursive(mut l: MatMut<'_, f64>, par: Par) -> Result<(), usize> {
    let n = l.nrows();
    if n <= Tuning::DEFAULT.cholesky_base_case {
        let mut mem = faer::dyn_stack::MemBuffer::new(
            faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(n, par, Default::default()),
        );
        let stack = faer::dyn_stack::MemStack::new(&mut mem);
        let result = faer::linalg::cholesky::llt::factor::cholesky_in_place(
            l.rb_mut(),
            Default::default(),
            par,
            stack,
            Default::default(),
        );
        // faer's kernel leaves scratch values in the block's strict upper triangle, which is
        // part of L's (zero) strict upper triangle.
        for j in 1..n {
            l.rb_mut().col_mut(j).subrows_mut(0, j).fill(0.0);
        }
        return match result {
            Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => Err(index),
            _ => Ok(()),
        };
    }
    let n1 = n / 2;
    let (mut l11, _, mut l21, mut l22) = l.split_at_mut(n1, n1);
    factor_recursive(l11.rb_mut(), par)?;
    solve_lower_triangular_in_place(l11.rb(), l21.rb_mut().transpose_mut(), par);
    subtract_lower_product(l22.rb_mut(), l21.rb(), l21.rb(), par);
    factor_recursive(l22, par).map_err(|pivot| pivot + n1)
}

/// C = L⁻¹ B L⁻ᵀ, reading only the lower triangle of `b`; returns C with its lower triangle
/// valid (the upper triangle is unspecified).
pub fn reduce(l: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    reduce_owned(l, b.to_owned(), par)
}

/// [`reduce`] of a copy of B that the caller no longer needs (reduced in place, no copy).
pub(crate) fn reduce_owned(l: MatRef<'_, f64>, mut c: Mat<f64>, par: Par) -> Mat<f64> {
    let par = factor_parallelism(l.nrows(), par);
    if is_diagonal(l) {
        scale_lower_in_place(l, c.as_mut());
    } else {
        reduce_in_place(l, c.as_mut(), par);
    }
    c
}

/// C = L⁻¹ B L⁻ᵀ for a diagonal L: c_ij = (b_ij/l_i)/l_j on the lower triangle, scaled one
/// factor at a time so that tiny masses with a tiny stiffness (1/(l_i l_j) beyond the range of
/// f64 while C is not) do not overflow.
fn scale_lower_in_place(l: MatRef<'_, f64>, mut c: MatMut<'_, f64>) {
    let n = c.nrows();
    let inverse: Vec<f64> = (0..n).map(|i| l[(i, i)].recip()).collect();
    for j in 0..n {
        let column = &mut c.rb_mut().col_mut(j);
        for i in j..n {
            column[i] = column[i] * inverse[i] * inverse[j];
        }
    }
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

/// Blocked sygst, one leading block of [`crate::Tuning::reduce_block`] columns per step (the block
/// itself is reduced by the same recursion): with L = [L11 0; L21 L22] and B split alike, L C Lᵀ =
/// B gives C11 = L11⁻¹ B11 L11⁻ᵀ, H = ½ L21 C11, W = B21 L11⁻ᵀ − H, B22' = B22 − (W L21ᵀ + L21 Wᵀ),
/// C21 = L22⁻¹ (W − H), C22 = L22⁻¹ B22' L22⁻ᵀ. H is formed once per step (LAPACK `dsygst` forms it
/// twice, by two `dsymm`): a sixth of the flops fewer.
fn reduce_in_place(l: MatRef<'_, f64>, c: MatMut<'_, f64>, par: Par) {
    let n = c.nrows();
    let mut half_product = Mat::<f64>::zeros(n, Tuning::DEFAULT.reduce_block.min(n / 2));
    reduce_blocks(l, c, half_product.as_mut(), par);
}

/// The recursion of [`reduce_in_place`]; `scratch` holds H = ½ L21 C11 of each step (at least
/// n − n1 rows and n1 columns).
fn reduce_blocks(l: MatRef<'_, f64>, mut c: MatMut<'_, f64>, mut scratch: MatMut<'_, f64>, par: Par) {
    let n = c.nrows();
    if n <= Tuning::DEFAULT.reduce_base_case {
        mirror_lower(c.as_mut());
        solve_lower_triangular_in_place(l, c.as_mut(), par);
        solve_lower_triangular_in_place(l, c.as_mut().transpose_mut(), par);
        return;
    }
    let n1 = Tuning::DEFAULT.reduce_block.min(n / 2);
    let (l11, _, l21, l22) = l.split_at(n1, n1);
    let (mut c11, _, mut c21, mut c22) = c.split_at_mut(n1, n1);
    reduce_blocks(l11, c11.as_mut(), scratch.rb_mut(), par);
    mirror_lower(c11.as_mut());
    if n - n1 <= Tuning::DEFAULT.split_step_up_to && par.degree() == 2 {
        let half = scratch.rb_mut().submatrix_mut(0, 0, n - n1, n1);
        let step = StepBlocks {
            l11,
            l21,
            l22,
            c11: c11.as_ref(),
        };
        step.on_two_threads(c21, c22.as_mut(), half);
        return reduce_blocks(l22, c22, scratch, par);
    }
    // W = B21 L11⁻ᵀ  ⇔  L11 Wᵀ = B21ᵀ (the rows of W are independent right-hand sides).
    by_column_chunks(c21.as_mut().transpose_mut(), par, &|rhs| {
        solve_lower_triangular_in_place(l11, rhs, Par::Seq)
    });
    let mut half = scratch.rb_mut().submatrix_mut(0, 0, n - n1, n1);
    matmul(half.as_mut(), Accum::Replace, l21, c11.as_ref(), 0.5, par);
    subtract_in_place(c21.as_mut(), half.as_ref());
    subtract_lower_product(c22.as_mut(), c21.as_ref(), l21, par);
    subtract_lower_product(c22.as_mut(), l21, c21.as_ref(), par);
    subtract_in_place(c21.as_mut(), half.as_ref());
    // C21 = L22⁻¹ (W − H) on column chunks, one per thread (faster than faer's parallel solve
    // of the same, measured in docs/benchmarks.md).
    by_column_chunks(c21.as_mut(), par, &|rhs| {
        solve_lower_triangular_in_place(l22, rhs, Par::Seq)
    });
    reduce_blocks(l22, c22, scratch, par);
}

/// The blocks of L and C11 that one step of the reduction reads.
struct StepBlocks<'a> {
    l11: MatRef<'a, f64>,
    l21: MatRef<'a, f64>,
    l22: MatRef<'a, f64>,
    c11: MatRef<'a, f64>,
}

impl StepBlocks<'_> {
    /// One step of [`reduce_blocks`] on two threads, each running sequential kernels: W and
    /// W − H by halves of the rows of C21, the symmetric rank-2k update of C22 by two parts of
    /// its lower triangle of equal area, and (W − 2H) solved with L22 by halves of the columns.
    fn on_two_threads(&self, mut c21: MatMut<'_, f64>, c22: MatMut<'_, f64>, mut half: MatMut<'_, f64>) {
        let rows = c21.nrows() / 2;
        {
            let (c21_top, c21_bottom) = c21.rb_mut().split_at_row_mut(rows);
            let (half_top, half_bottom) = half.rb_mut().split_at_row_mut(rows);
            let (l21_top, l21_bottom) = self.l21.split_at_row(rows);
            rayon::join(
                || self.w_minus_h(c21_top, half_top, l21_top),
                || self.w_minus_h(c21_bottom, half_bottom, l21_bottom),
            );
        }
        subtract_lower_rank_2k_on_two_threads(c22, c21.as_ref(), self.l21);
        let cols = c21.ncols() / 2;
        let (c21_left, c21_right) = c21.split_at_col_mut(cols);
        let (half_left, half_right) = half.as_ref().split_at_col(cols);
        let finish = |mut c: MatMut<'_, f64>, h: MatRef<'_, f64>| {
            subtract_in_place(c.as_mut(), h);
            solve_lower_triangular_in_place(self.l22, c, Par::Seq);
        };
        rayon::join(|| finish(c21_left, half_left), || finish(c21_right, half_right));
    }

    /// Rows of C21 ← B21 L11⁻ᵀ − H with H = ½ L21 C11 (kept in `half`), sequentially.
    fn w_minus_h(&self, mut c21: MatMut<'_, f64>, mut half: MatMut<'_, f64>, l21: MatRef<'_, f64>) {
        solve_lower_triangular_in_place(self.l11, c21.as_mut().transpose_mut(), Par::Seq);
        matmul(half.as_mut(), Accum::Replace, l21, self.c11, 0.5, Par::Seq);
        subtract_in_place(c21, half.as_ref());
    }
}

/// The lower triangle of `target` −= x yᵀ + y xᵀ on two threads, each with sequential kernels:
/// the leading columns holding half the triangle (a triangle and the rectangle below it) and the
/// triangle after them.
fn subtract_lower_rank_2k_on_two_threads(target: MatMut<'_, f64>, x: MatRef<'_, f64>, y: MatRef<'_, f64>) {
    let m = target.nrows();
    let cut = columns_holding(m, 0.25 * (m * m) as f64);
    let (mut top_left, _, mut bottom_left, mut bottom_right) = target.split_at_mut(cut, cut);
    let (x_top, x_bottom) = x.split_at_row(cut);
    let (y_top, y_bottom) = y.split_at_row(cut);
    rayon::join(
        || {
            subtract_lower_product(top_left.as_mut(), x_top, y_top, Par::Seq);
            subtract_lower_product(top_left.as_mut(), y_top, x_top, Par::Seq);
            matmul(
                bottom_left.as_mut(),
                Accum::Add,
                x_bottom,
                y_top.transpose(),
                -1.0,
                Par::Seq,
            );
            matmul(
                bottom_left.as_mut(),
                Accum::Add,
                y_bottom,
                x_top.transpose(),
                -1.0,
                Par::Seq,
            );
        },
        || {
            subtract_lower_product(bottom_right.as_mut(), x_bottom, y_bottom, Par::Seq);
            subtract_lower_product(bottom_right.as_mut(), y_bottom, x_bottom, Par::Seq);
        },
    );
}

/// `target` −= `amount`, entry by entry.
fn subtract_in_place(mut target: MatMut<'_, f64>, amount: MatRef<'_, f64>) {
    for j in 0..target.ncols() {
        for (t, a) in target.rb_mut().col_mut(j).iter_mut().zip(amount.col(j).iter()) {
            *t -= a;
        }
    }
}

/// The plain reduction C = L⁻¹ (L⁻¹ B)ᵀ by two full triangular solves (2n³ flops); kept as the
/// reference the benchmarks and tests compare the symmetric reduction against.
pub fn reduce_two_solves(l: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = b.to_owned();
    solve_lower_triangular_in_place(l, c.as_mut(), par);
    solve_lower_triangular_in_place(l, c.as_mut().transpose_mut(), par);
    c
}

/// X = L⁻ᵀ Y in place (back-transformation of eigenvectors of C to those of the pencil); a
/// diagonal L divides each row.
pub fn back_transform(l: MatRef<'_, f64>, y: MatMut<'_, f64>, par: Par) {
    LowerFactor::new(l).solve_transposed(y, par);
}

/// X = L⁻ᵀ Y into `x` (same shape as `y`, which is left unchanged): each thread copies its own
/// column chunk of Y and solves it, so the copy runs on both threads and the solve finds its
/// columns in cache.
pub(crate) fn back_transform_into(l: MatRef<'_, f64>, y: MatRef<'_, f64>, x: MatMut<'_, f64>, par: Par) {
    let factor = LowerFactor::new(l);
    by_column_chunks_at(x, par, &|first, mut chunk| {
        chunk.copy_from(y.subcols(first, chunk.ncols()));
        factor.solve_transposed(chunk, Par::Seq);
    });
}

/// A lower Cholesky factor L of A with whether it is diagonal, found once: the many solves with
/// L and Lᵀ of refinement then divide rows for lumped masses instead of costing n² per column.
#[derive(Clone, Copy)]
pub(crate) struct LowerFactor<'a> {
    /// L, lower triangular (its strict upper triangle is zero).
    pub(crate) l: MatRef<'a, f64>,
    diagonal: bool,
}

impl<'a> LowerFactor<'a> {
    /// Wraps `l` (one scan of its strict lower triangle, stopping at the first nonzero).
    pub(crate) fn new(l: MatRef<'a, f64>) -> Self {
        Self {
            l,
            diagonal: is_diagonal(l),
        }
    }

    /// Y ← L⁻¹ Y in place (a triangular L is solved on column chunks, one per thread of `par`).
    pub(crate) fn solve(&self, y: MatMut<'_, f64>, par: Par) {
        let l = self.l;
        if self.diagonal {
            return divide_rows(l, y);
        }
        by_column_chunks(y, par, &|rhs| solve_lower_triangular_in_place(l, rhs, Par::Seq));
    }

    /// Y ← L⁻ᵀ Y in place.
    pub(crate) fn solve_transposed(&self, y: MatMut<'_, f64>, par: Par) {
        let l = self.l;
        if self.diagonal {
            return divide_rows(l, y);
        }
        by_column_chunks(y, par, &|rhs| {
            solve_upper_triangular_in_place(l.transpose(), rhs, Par::Seq)
        });
    }
}

/// Y ← diag(L)⁻¹ Y.
fn divide_rows(l: MatRef<'_, f64>, mut y: MatMut<'_, f64>) {
    let inverse: Vec<f64> = (0..l.nrows()).map(|i| l[(i, i)].recip()).collect();
    for j in 0..y.ncols() {
        y.rb_mut()
            .col_mut(j)
            .iter_mut()
            .zip(&inverse)
            .for_each(|(e, s)| *e *= s);
    }
}

/// The Cholesky factor L (lower, upper triangle zeroed) of A = LLᵀ exactly as [`crate::solve()`]
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

    /// A dense Cholesky factor (of a random SPD matrix from `seed`) and a diagonal one,
    /// diag(1, 2, …, n), the two kinds of L that [`LowerFactor`] tells apart.
    fn dense_and_diagonal_factors(n: usize, seed: u64) -> (Mat<f64>, Mat<f64>) {
        let dense = cholesky_lower(spd(n, seed).as_ref(), Par::Seq).expect("spd matrix must factor");
        let diagonal = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 } else { 0.0 });
        (dense, diagonal)
    }

    #[test]
    fn symmetric_reduction_matches_two_triangular_solves() {
        // 700: several blocks of `Tuning::reduce_block`, each step's H in the shared scratch, on
        // two threads (every step as two-thread phases); 1300: the first steps with faer's parallel
        // kernels (trailing order above `Tuning::split_step_up_to`), the later ones in phases.
        for n in [1, 5, 48, 49, 130, 257, 700, 1300] {
            let a = spd(n, 1);
            let b = spd(n, 2);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("spd matrix must factor")
            };
            let c = reduce(l.as_ref(), b.as_ref(), Par::rayon(2));
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

    /// The copying back-transformation solves L^T X = Y(:, first..end) column for column, on
    /// one thread and on two (chunks start at nonzero column offsets of the selection), for a
    /// dense and for a diagonal L; Y is left unchanged.
    #[test]
    fn back_transform_into_solves_the_selected_columns() {
        let n = 300;
        let (dense, diagonal) = dense_and_diagonal_factors(n, 4);
        let y = spd(n, 5);
        let (first, count) = (37, 201);
        for l in [&dense, &diagonal] {
            for par in [Par::Seq, Par::rayon(2)] {
                let mut x = Mat::<f64>::from_fn(n, count, |_, _| f64::NAN);
                back_transform_into(l.as_ref(), y.subcols(first, count), x.as_mut(), par);
                // L^T X reproduces the selected columns to a few n*u of their size.
                let back = l.transpose() * &x;
                let scale = y.norm_max() + l.norm_max() * x.norm_max();
                for j in 0..count {
                    for i in 0..n {
                        let error = (back[(i, j)] - y[(i, first + j)]).abs();
                        assert!(error <= 4.0 * n as f64 * f64::EPSILON * scale, "({i}, {j}): {error:e}");
                    }
                }
            }
        }
        assert_eq!(y, spd(n, 5));
    }

    #[test]
    fn recursive_cholesky_names_the_failing_pivot_in_every_block() {
        // Orders past the base case, so the failing pivot lies in a trailing block of the
        // recursion (its index must be offset) or in the leading one.
        for (n, bad) in [(300, 0), (300, 127), (300, 150), (300, 299), (700, 555)] {
            let mut a = spd(n, 3);
            // Make row/column `bad` a copy of row/column `bad − 1` (semidefinite: the Schur
            // complement's pivot `bad` vanishes), or zero it at bad = 0.
            for i in 0..n {
                let v = if bad == 0 { 0.0 } else { a[(i, bad - 1)] };
                a[(i, bad)] = v;
                a[(bad, i)] = v;
            }
            if bad > 0 {
                a[(bad, bad)] = a[(bad - 1, bad - 1)];
            }
            match cholesky(a.as_ref(), Par::rayon(2)) {
                Cholesky::Failed { pivot } => assert_eq!(pivot, bad, "n = {n}"),
                Cholesky::Factor(_) => panic!("n = {n}: a semidefinite matrix factored"),
            }
            // An indefinite matrix: a negative diagonal entry far down.
            let mut b = spd(n, 4);
            b[(bad, bad)] = -1.0;
            match cholesky(b.as_ref(), Par::rayon(2)) {
                Cholesky::Failed { pivot } => assert!(pivot <= bad, "n = {n}: pivot {pivot} after {bad}"),
                Cholesky::Factor(_) => panic!("n = {n}: an indefinite matrix factored"),
            }
        }
    }

    #[test]
    fn diagonal_mass_reduction_matches_the_dense_one() {
        // A diagonal over twelve decades: L, C and X = L⁻ᵀY from the scaling path agree with
        // the triangular solves of the general path to a few u (entrywise, relative for L).
        let n = 200;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                10f64.powf(-6.0 + 12.0 * i as f64 / (n - 1) as f64)
            } else {
                0.0
            }
        });
        let b = spd(n, 6);
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("positive diagonal must factor")
        };
        assert!(is_diagonal(l.as_ref()));
        for i in 0..n {
            assert!((l[(i, i)] - a[(i, i)].sqrt()).abs() <= 2.0 * f64::EPSILON * l[(i, i)]);
        }
        let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
        let r = reduce_two_solves(l.as_ref(), b.as_ref(), Par::Seq);
        for j in 0..n {
            for i in j..n {
                assert!(
                    (c[(i, j)] - r[(i, j)]).abs() <= 8.0 * f64::EPSILON * r[(i, j)].abs(),
                    "({i},{j})"
                );
            }
        }
        let mut x = b.clone();
        back_transform(l.as_ref(), x.as_mut(), Par::Seq);
        let mut reference = b.clone();
        solve_upper_triangular_in_place(l.transpose(), reference.as_mut(), Par::Seq);
        for j in 0..n {
            for i in 0..n {
                assert!((x[(i, j)] - reference[(i, j)]).abs() <= 4.0 * f64::EPSILON * reference[(i, j)].abs());
            }
        }
    }

    #[test]
    fn diagonal_scaling_does_not_overflow_where_c_is_representable() {
        // A = 2⁻¹⁰³⁰ I (subnormal, exact) and B = 2⁻¹⁰³⁰ T: C = T exactly, though 1/(l_i l_j)
        // = 2¹⁰³⁰ is beyond f64.
        let n = 6;
        let tiny = 2f64.powi(-1030);
        let a = Mat::from_fn(n, n, |i, j| if i == j { tiny } else { 0.0 });
        let t = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        });
        let b = Mat::from_fn(n, n, |i, j| tiny * t[(i, j)]);
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("a positive diagonal factors")
        };
        let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
        for j in 0..n {
            for i in j..n {
                assert_eq!(c[(i, j)], t[(i, j)], "({i},{j})");
            }
        }
    }

    #[test]
    fn diagonal_mass_names_its_failing_pivot() {
        // Zero and negative diagonal entries fail at their index; a lumped mass is massless
        // only when it is exactly zero.
        let n = 50;
        for (bad, value) in [(0, 0.0), (17, -1.0), (31, -0.0)] {
            let a = Mat::from_fn(n, n, |i, j| match (i == j, i == bad) {
                (true, true) => value,
                (true, false) => 1.0 + i as f64,
                _ => 0.0,
            });
            match cholesky(a.as_ref(), Par::Seq) {
                Cholesky::Failed { pivot } => assert_eq!(pivot, bad),
                Cholesky::Factor(_) => panic!("a_{bad}{bad} = {value} factored"),
            }
        }
    }

    #[test]
    fn a_tiny_lumped_mass_is_a_mass() {
        // 1e-20 beside masses of order 50 (far below n·u·max a_jj) is still a positive pivot.
        let n = 50;
        let a = Mat::from_fn(n, n, |i, j| match (i == j, i == 49) {
            (true, true) => 1e-20,
            (true, false) => 1.0 + i as f64,
            _ => 0.0,
        });
        match cholesky(a.as_ref(), Par::Seq) {
            Cholesky::Factor(l) => assert_eq!(l[(49, 49)], 1e-10),
            Cholesky::Failed { pivot } => panic!("pivot {pivot} failed"),
        }
    }

    #[test]
    fn factor_solves_match_faer_on_dense_and_diagonal_factors() {
        // L⁻¹Y and L⁻ᵀY by column chunks on two threads, and by row division for a diagonal L,
        // against faer's sequential triangular solves (entrywise within a few u of the result).
        let n = 300;
        let (dense, diagonal) = dense_and_diagonal_factors(n, 7);
        let y = spd(n, 8);
        for (l, is_diag) in [(&dense, false), (&diagonal, true)] {
            let factor = LowerFactor::new(l.as_ref());
            assert_eq!(factor.diagonal, is_diag);
            let mut forward = y.clone();
            factor.solve(forward.as_mut(), Par::rayon(2));
            let mut reference = y.clone();
            solve_lower_triangular_in_place(l.as_ref(), reference.as_mut(), Par::Seq);
            let mut backward = y.clone();
            factor.solve_transposed(backward.as_mut(), Par::rayon(2));
            let mut reference_t = y.clone();
            solve_upper_triangular_in_place(l.transpose(), reference_t.as_mut(), Par::Seq);
            for (got, want) in [(&forward, &reference), (&backward, &reference_t)] {
                let tol = 8.0 * n as f64 * f64::EPSILON * want.norm_max();
                assert!((got - want).norm_max() <= tol, "diagonal: {is_diag}");
            }
        }
    }

    #[test]
    fn recursive_cholesky_reproduces_the_matrix() {
        // ‖LLᵀ − A‖_max ≤ c·n·u·max|A| (backward stability), across base case and recursion.
        for n in [1, 127, 128, 129, 300, 1000] {
            let a = spd(n, 5);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::rayon(2)) else {
                panic!("spd matrix must factor")
            };
            let llt = &l * l.transpose();
            let tol = 4.0 * n as f64 * f64::EPSILON * a.norm_max();
            for j in 0..n {
                for i in 0..n {
                    assert!((llt[(i, j)] - a[(i, j)]).abs() <= tol, "n = {n} ({i}, {j})");
                }
            }
        }
    }
}
