//! The products behind the residuals and the A-orthogonality of dense pairs: A X and B X formed
//! exactly, or bounded through Gaussian sketches ([`super::sketch`]), and kept up to date as
//! refinement changes columns of X.

use crate::certify::sketch::{Sketch, SketchRows};
use crate::linalg::norms::{euclidean_norm, vector_norm};
use faer::sparse::SparseColMat;
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::{Mat, MatMut, MatRef, Par};

/// How the accuracy report measures the residuals and the A-orthogonality of dense pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Residuals {
    /// A X, B X and XᵀAX formed in full (5n²m flops for m pairs): every backward error and the
    /// orthogonality error are computed exactly (to rounding).
    #[default]
    Exact,
    /// Gaussian sketches (`crate::certify::sketch`, O(k·n²) flops with k = 32): each backward error
    /// and the orthogonality error (then a bound on ‖XᵀAX − I‖_F) is an upper bound that fails with
    /// probability at most 1e-12; typically 2–4 times the exact value. Where the exact products
    /// cost less (all pairs below n ≈ 200, or a few pairs of any pencil) they are formed instead,
    /// and the report's `residuals` says `Exact`.
    Sketched,
}

/// The products behind the residuals of a set of pairs; refined columns are recomputed one by
/// one, so the report after refinement costs O(n²) per refined mode.
pub(crate) enum PairProducts {
    /// A X and B X, and B by its nonzeros when it has few.
    Exact {
        ax: Mat<f64>,
        bx: Mat<f64>,
        sparse_b: Option<SparseColMat<usize, f64>>,
    },
    /// S A X and S B X, and the bound on ‖XᵀAX − I‖_F; `changed`: the columns changed since
    /// the bound was computed.
    Sketched {
        sketch: Sketch,
        orthogonality: f64,
        changed: Vec<usize>,
    },
}

/// out = A X; a diagonal A (lumped masses) scales the rows in O(nm) instead of the 2n²m of a
/// matrix product.
fn mass_product(mut out: MatMut<'_, f64>, a: MatRef<'_, f64>, x: MatRef<'_, f64>, par: Par) {
    if crate::linalg::reduce::is_diagonal(a) {
        for j in 0..x.ncols() {
            for i in 0..x.nrows() {
                out[(i, j)] = a[(i, i)] * x[(i, j)];
            }
        }
    } else {
        faer::linalg::matmul::matmul(out, faer::Accum::Replace, a, x, 1.0, par);
    }
}

/// Whether the exact products of m pairs of order n cost less time than their sketches: A X,
/// B X and XᵀAX take 4n²m + 2nm² flops in large products; the sketches 4kn² + 10knm flops in
/// thin products (counted twice: they run at about half the rate) and k(n + m) Gaussian
/// numbers (a logarithm and a cosine each, about 1000 flops' time). For all pairs the
/// crossover is n ≈ 200 (measured in docs/benchmarks.md); for a few pairs of a large pencil the
/// exact products are cheaper at any n.
pub(crate) fn exact_costs_less(n: usize, m: usize) -> bool {
    let (n, m, k) = (n as f64, m as f64, crate::certify::sketch::SKETCH_SIZE as f64);
    let exact = 4.0 * n * n * m + 2.0 * n * m * m;
    let sketch = 2.0 * (4.0 * k * n * n + 10.0 * k * n * m) + 1000.0 * k * (n + m);
    exact <= sketch
}

/// out = B X; a B with few nonzeros (a banded or assembled stiffness stored densely, kept by
/// its nonzeros in `sparse_b`) costs 2·nnz·m flops instead of the 2n²m of a matrix product.
fn stiffness_product(
    out: MatMut<'_, f64>,
    b: MatRef<'_, f64>,
    sparse_b: Option<&SparseColMat<usize, f64>>,
    x: MatRef<'_, f64>,
    par: Par,
) {
    match sparse_b {
        Some(s) => sparse_dense_matmul(out, faer::Accum::Replace, s.as_ref(), x, 1.0, par),
        None => faer::linalg::matmul::matmul(out, faer::Accum::Replace, b, x, 1.0, par),
    }
}

impl PairProducts {
    /// A X and B X (2n²m flops each), or their sketches where those cost less
    /// ([`exact_costs_less`]).
    /// `rows`: the sketch's S·A and S·B when already formed.
    pub(crate) fn new(
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        how: Residuals,
        rows: Option<SketchRows>,
        par: Par,
    ) -> Self {
        match how {
            Residuals::Exact => {
                let (n, m) = (a.nrows(), x.ncols());
                let mut ax = Mat::<f64>::zeros(n, m);
                let mut bx = Mat::<f64>::zeros(n, m);
                let sparse_b = crate::dd::sparse_columns(b);
                mass_product(ax.as_mut(), a, x, par);
                stiffness_product(bx.as_mut(), b, sparse_b.as_ref(), x, par);
                Self::Exact { ax, bx, sparse_b }
            }
            Residuals::Sketched if exact_costs_less(a.nrows(), x.ncols()) => {
                Self::new(a, b, x, Residuals::Exact, None, par)
            }
            Residuals::Sketched => {
                let sketch = Sketch::new(a, b, x, rows, par);
                let orthogonality = sketch.orthogonality_bound(a, x, par);
                Self::Sketched {
                    sketch,
                    orthogonality,
                    changed: Vec::new(),
                }
            }
        }
    }

    /// Recomputes column `i` after x_i changed.
    pub(crate) fn update_column(
        &mut self,
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        i: usize,
        par: Par,
    ) {
        match self {
            Self::Exact { ax, bx, sparse_b } => {
                let xi = x.subcols(i, 1);
                mass_product(ax.as_mut().subcols_mut(i, 1), a, xi, par);
                stiffness_product(bx.as_mut().subcols_mut(i, 1), b, sparse_b.as_ref(), xi, par);
            }
            Self::Sketched { sketch, changed, .. } => {
                sketch.update_column(x, i);
                if !changed.contains(&i) {
                    changed.push(i);
                }
            }
        }
    }

    /// Recomputes the columns `cols` after those x_i changed: one product with A and one with B
    /// over all of them (a product per column would cost a fork of the threads each).
    pub(crate) fn update_columns(
        &mut self,
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        cols: &[usize],
        par: Par,
    ) {
        match self {
            Self::Exact { ax, bx, sparse_b } => {
                let changed = gather_columns(x, cols);
                let mut a_changed = Mat::<f64>::zeros(x.nrows(), cols.len());
                let mut b_changed = Mat::<f64>::zeros(x.nrows(), cols.len());
                mass_product(a_changed.as_mut(), a, changed.as_ref(), par);
                stiffness_product(b_changed.as_mut(), b, sparse_b.as_ref(), changed.as_ref(), par);
                for (k, &c) in cols.iter().enumerate() {
                    ax.col_mut(c).copy_from(a_changed.col(k));
                    bx.col_mut(c).copy_from(b_changed.col(k));
                }
            }
            Self::Sketched { .. } => {
                for &c in cols {
                    self.update_column(a, b, x, c, par);
                }
            }
        }
    }

    /// Backward error η_i and first-order bound max(η_i, u)·κ_i of the pair (ω²_i, x_i) (the
    /// rounding allowance of the reported bound is added by [`crate::certify::report::AccuracyReport::finish`]). Sketched,
    /// the residual is its probabilistic upper bound and x_iᵀAx_i ≥ 1 − ‖XᵀAX − I‖_F.
    pub(crate) fn pair_error(
        &self,
        x: MatRef<'_, f64>,
        i: usize,
        omega_sq: f64,
        norm_a: f64,
        norm_b: f64,
    ) -> (f64, f64) {
        let xi = x.col(i);
        let n = xi.nrows();
        let (r, xax) = match self {
            Self::Exact { ax, bx, .. } => {
                let (axi, bxi) = (ax.col(i), bx.col(i));
                let r: Vec<f64> = (0..n).map(|k| bxi[k] - omega_sq * axi[k]).collect();
                let r = euclidean_norm(&r);
                (r, (0..n).map(|k| xi[k] * axi[k]).sum::<f64>())
            }
            Self::Sketched {
                sketch, orthogonality, ..
            } => (sketch.residual_bound(i, omega_sq), 1.0 - orthogonality),
        };
        let xnorm = vector_norm(xi);
        let scale = norm_b + omega_sq.abs() * norm_a;
        let eta = if scale * xnorm > 0.0 { r / (scale * xnorm) } else { 0.0 };
        let kappa = if xax > 0.0 {
            scale * xnorm * xnorm / xax
        } else {
            f64::INFINITY
        };
        (eta, eta.max(f64::EPSILON) * kappa)
    }

    /// max |(XᵀAX − I)_ij| over the lower triangle (only the lower triangle of XᵀAX is formed),
    /// or, sketched, the bound on ‖XᵀAX − I‖_F of the final vectors: after a few columns
    /// changed, [`orthogonality_after_changes`]; after more than the sketch's size, a new sketch.
    pub(crate) fn orthogonality_error(&mut self, a: MatRef<'_, f64>, x: MatRef<'_, f64>, par: Par) -> f64 {
        let ax = match self {
            Self::Exact { ax, .. } => ax,
            Self::Sketched {
                sketch,
                orthogonality,
                changed,
            } => {
                if changed.len() > crate::certify::sketch::SKETCH_SIZE {
                    *orthogonality = sketch.orthogonality_bound(a, x, par);
                } else if !changed.is_empty() {
                    *orthogonality = orthogonality_after_changes(*orthogonality, a, x, changed, par);
                }
                changed.clear();
                return *orthogonality;
            }
        };
        let m = x.ncols();
        let mut g = Mat::<f64>::zeros(m, m);
        faer::linalg::matmul::triangular::matmul(
            g.as_mut(),
            faer::linalg::matmul::triangular::BlockStructure::TriangularLower,
            faer::Accum::Replace,
            x.transpose(),
            faer::linalg::matmul::triangular::BlockStructure::Rectangular,
            ax.as_ref(),
            faer::linalg::matmul::triangular::BlockStructure::Rectangular,
            1.0,
            par,
        );
        let mut orth = 0.0_f64;
        for j in 0..m {
            for i in j..m {
                let target = if i == j { 1.0 } else { 0.0 };
                orth = orth.max((g[(i, j)] - target).abs());
            }
        }
        orth
    }
}

/// The columns `cols` of `x`, side by side.
fn gather_columns(x: MatRef<'_, f64>, cols: &[usize]) -> Mat<f64> {
    Mat::from_fn(x.nrows(), cols.len(), |i, k| x[(i, cols[k])])
}

/// An upper bound of ‖XᵀAX − I‖_F after the columns `cols` of X changed, from `bound` ≥ its
/// value before. E = XᵀAX − I is symmetric; outside the changed rows and columns it is as it
/// was, so bounded by `bound`, and the changed rows R = X_Cᵀ A X − I_C (formed exactly, 2n²c +
/// 2nmc flops for c changed columns, where a new sketch costs 2n²k + 4nmk) and their transposes
/// cover the rest: ‖E‖_F² ≤ bound² + 2‖R‖_F².
fn orthogonality_after_changes(bound: f64, a: MatRef<'_, f64>, x: MatRef<'_, f64>, cols: &[usize], par: Par) -> f64 {
    let changed = gather_columns(x, cols);
    let mut a_changed = Mat::<f64>::zeros(x.nrows(), cols.len());
    mass_product(a_changed.as_mut(), a, changed.as_ref(), par);
    let mut rows = Mat::<f64>::zeros(x.ncols(), cols.len());
    faer::linalg::matmul::matmul(
        rows.as_mut(),
        faer::Accum::Replace,
        x.transpose(),
        a_changed.as_ref(),
        1.0,
        par,
    );
    for (k, &col) in cols.iter().enumerate() {
        rows[(col, k)] -= 1.0;
    }
    let rows_sq = rows.norm_l2().powi(2);
    (bound * bound + 2.0 * rows_sq).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sketched ‖XᵀAX − I‖_F bound follows columns changed after it was formed: two
    /// columns of an A-orthonormal X are spoiled (one mixed with another mode, one scaled), and
    /// the bound updated from the changed rows is above the exact norm and within a factor √2.
    #[test]
    fn the_sketched_orthogonality_bound_follows_changed_columns() {
        let n = 300;
        let a = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 / n as f64 } else { 0.0 });
        let b = Mat::from_fn(n, n, |i, j| if i == j { 2.0 } else { 0.0 });
        let mut x = Mat::from_fn(n, n, |i, j| if i == j { a[(i, i)].sqrt().recip() } else { 0.0 });
        let mut products = PairProducts::new(a.as_ref(), b.as_ref(), x.as_ref(), Residuals::Sketched, None, Par::Seq);
        assert!(matches!(products, PairProducts::Sketched { .. }));
        assert!(products.orthogonality_error(a.as_ref(), x.as_ref(), Par::Seq) < 1e-13);
        x[(7, 5)] = 0.01;
        x[(9, 9)] *= 1.001;
        products.update_columns(a.as_ref(), b.as_ref(), x.as_ref(), &[5, 9], Par::Seq);
        let bound = products.orthogonality_error(a.as_ref(), x.as_ref(), Par::Seq);
        let gram = x.transpose() * &a * &x - Mat::<f64>::identity(n, n);
        let exact = gram.norm_l2();
        assert!(exact > 1e-3, "{exact}");
        assert!(bound >= exact && bound <= 1.5 * exact, "{bound} vs {exact}");
    }
    /// A banded stiffness is multiplied by its nonzeros (and a dense one is not), with the
    /// products of the dense kernel to rounding: B X, a batch of changed columns and one changed
    /// column, entry by entry within n·u·(|B||X|).
    #[test]
    fn banded_stiffness_products_match_the_dense_ones() {
        let n = 120;
        let b = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2e6 + i as f64,
            1 => -1e6,
            2 => 0.25,
            _ => 0.0,
        });
        let a = Mat::from_fn(n, n, |i, j| if i == j { 1.0 + i as f64 } else { 0.0 });
        let mut x = crate::certify::sketch::gaussian(n, 7, 3);
        let mut products = PairProducts::new(a.as_ref(), b.as_ref(), x.as_ref(), Residuals::Exact, None, Par::Seq);
        let check = |products: &PairProducts, x: &Mat<f64>| {
            let PairProducts::Exact { bx, sparse_b, .. } = products else {
                panic!("exact products asked for")
            };
            assert!(sparse_b.is_some());
            let dense = &b * x;
            let magnitude = b.map(|v| v.abs()) * x.map(|v| v.abs());
            for j in 0..x.ncols() {
                for i in 0..n {
                    let tol = n as f64 * f64::EPSILON * magnitude[(i, j)];
                    assert!((bx[(i, j)] - dense[(i, j)]).abs() <= tol, "({i}, {j})");
                }
            }
        };
        check(&products, &x);
        for i in 0..n {
            x[(i, 2)] = (i as f64).sin();
            x[(i, 5)] = (i as f64).cos();
        }
        products.update_columns(a.as_ref(), b.as_ref(), x.as_ref(), &[2, 5], Par::Seq);
        x[(0, 6)] = 3.0;
        products.update_column(a.as_ref(), b.as_ref(), x.as_ref(), 6, Par::Seq);
        check(&products, &x);
        let full = Mat::from_fn(n, n, |i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let PairProducts::Exact { sparse_b, .. } =
            PairProducts::new(a.as_ref(), full.as_ref(), x.as_ref(), Residuals::Exact, None, Par::Seq)
        else {
            panic!("exact products asked for")
        };
        assert!(sparse_b.is_none());
    }
}
