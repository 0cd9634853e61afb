//! Shared pieces of the modal benches: the benchmark pencils, the nalgebra peer, conversions to
//! the column-major buffers LAPACK takes, and the error measures every method is judged by.

use mechanica::kinematics::nalgebra::{DMatrix, SymmetricEigen};
use mechanica::modal::faer::sparse::Triplet;
use mechanica::modal::faer::{Accum, Mat, MatRef, get_global_parallelism};
use mechanica_modal::testing;

/// The dense benchmark pencil of order n with a closed-form spectrum: masses d_i = 1 + i/n,
/// A = Qᵀ D Q and B = Qᵀ D^½ T D^½ Q with T = tridiag(−1, 2, −1) the fixed–fixed unit chain and Q
/// a random orthogonal matrix (seed 42). With z = D^½ Q x, B x = ω² A x becomes T z = ω² z, so
/// ω² = [`testing::fixed_chain_omega_sq`] while A is dense and not a multiple of the identity.
pub fn rotated_fixed_chain(n: usize) -> (Mat<f64>, Mat<f64>) {
    let d: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 / n as f64).collect();
    let a = Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 });
    let (_, t) = testing::fixed_chain(n);
    let b = Mat::from_fn(n, n, |i, j| (d[i] * d[j]).sqrt() * t[(i, j)]);
    testing::rotate(&a, &b, &testing::random_orthogonal(n, 42))
}

/// [`testing::lumped_chain`] with masses 1 + i/n and seed 42: the lumped-mass counterpart of
/// [`rotated_fixed_chain`] (same ω², A diagonal, B dense).
pub fn lumped_fixed_chain(n: usize) -> (Mat<f64>, Mat<f64>) {
    let d: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 / n as f64).collect();
    testing::lumped_chain(&d, 42)
}

/// Column-major copy with leading dimension nrows (the layout LAPACK takes).
pub fn to_col_major(m: MatRef<'_, f64>) -> Vec<f64> {
    let (r, c) = (m.nrows(), m.ncols());
    (0..c).flat_map(|j| (0..r).map(move |i| m[(i, j)])).collect()
}

/// An n×m faer matrix from a column-major buffer.
pub fn from_col_major(data: &[f64], rows: usize, cols: usize) -> Mat<f64> {
    Mat::from_fn(rows, cols, |i, j| data[i + rows * j])
}

/// nalgebra copy of a faer matrix.
pub fn to_nalgebra(m: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// faer copy of a nalgebra matrix.
pub fn from_nalgebra(m: &DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// Nonzero entries of a dense matrix as triplets (for the sparse solver).
pub fn to_triplets(m: MatRef<'_, f64>) -> Vec<Triplet<usize, usize, f64>> {
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

/// Dense matrix from triplets (duplicates summed).
pub fn from_triplets(n: usize, t: &[Triplet<usize, usize, f64>]) -> Mat<f64> {
    let mut m = Mat::zeros(n, n);
    for e in t {
        m[(e.row, e.col)] += e.val;
    }
    m
}

/// The nalgebra peer for all pairs of the definite pencil: Cholesky A = LLᵀ, C = L⁻¹BL⁻ᵀ by two
/// triangular solves, `SymmetricEigen`, X = L⁻ᵀY. Returns (ω² ascending, X) or None when A
/// does not factor. nalgebra has no values-only or generalized symmetric driver.
pub fn nalgebra_all_pairs(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let chol = a.clone().cholesky()?;
    let l = chol.l();
    let lb = l.solve_lower_triangular(b)?;
    let c = l.solve_lower_triangular(&lb.transpose())?;
    let eig = SymmetricEigen::new(c);
    let x = l.transpose().solve_upper_triangular(&eig.eigenvectors)?;
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let values = order.iter().map(|&i| eig.eigenvalues[i]).collect();
    let sorted = DMatrix::from_fn(x.nrows(), x.ncols(), |r, c| x[(r, order[c])]);
    Some((values, sorted))
}

/// max_j η_j with η_j = ‖B x_j − ω²_j A x_j‖ / ((‖B‖_F + |ω²_j| ‖A‖_F) ‖x_j‖): the backward
/// error of each pair (the same measure mechanica reports), computed here independently.
pub fn max_backward_error(a: MatRef<'_, f64>, b: MatRef<'_, f64>, x: MatRef<'_, f64>, omega_sq: &[f64]) -> f64 {
    let (n, m) = (x.nrows(), x.ncols().min(omega_sq.len()));
    let par = get_global_parallelism();
    let x = x.subcols(0, m);
    let mut ax = Mat::<f64>::zeros(n, m);
    let mut bx = Mat::<f64>::zeros(n, m);
    mechanica::modal::faer::linalg::matmul::matmul(ax.as_mut(), Accum::Replace, a, x, 1.0, par);
    mechanica::modal::faer::linalg::matmul::matmul(bx.as_mut(), Accum::Replace, b, x, 1.0, par);
    let (na, nb) = (a.norm_l2(), b.norm_l2());
    (0..m)
        .map(|j| {
            let w = omega_sq[j];
            let r = (0..n)
                .map(|i| (bx[(i, j)] - w * ax[(i, j)]).powi(2))
                .sum::<f64>()
                .sqrt();
            r / ((nb + w.abs() * na) * x.col(j).norm_l2())
        })
        .fold(0.0, f64::max)
}

/// Error of one computed ω² against the exact one: relative, |ŵ − w|/|w|, except for an exact
/// zero (rigid-body) mode, where it is |ŵ|/`scale` (normwise, with scale = the largest exact ω²).
pub fn eigenvalue_error(computed: f64, exact: f64, scale: f64) -> f64 {
    if exact == 0.0 {
        computed.abs() / scale
    } else {
        (computed - exact).abs() / exact.abs()
    }
}

/// Max [`eigenvalue_error`] over the first min(k, len) modes (both lists ascending).
pub fn max_eigenvalue_error(computed: &[f64], exact: &[f64], k: usize, scale: f64) -> f64 {
    computed
        .iter()
        .zip(exact)
        .take(k)
        .map(|(&c, &e)| eigenvalue_error(c, e, scale))
        .fold(0.0, f64::max)
}
