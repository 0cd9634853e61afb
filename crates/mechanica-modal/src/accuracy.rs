//! The accuracy report of a modal solve: backward errors, A-orthogonality, per-eigenvalue
//! error bounds and the Sturm (inertia) check.
//!
//! Norms ‖A‖, ‖B‖ are Frobenius norms (upper bounds of the 2-norms, so the bounds stay valid).
//! The residuals Bx − ω²Ax and XᵀAX − I are formed exactly ([`Residuals::Exact`]) or bounded
//! through Gaussian sketches ([`Residuals::Sketched`], see [`crate::sketch`]).
//! For a pair (ω², x) with λ = −ω²:
//! - backward error η = ‖Bx + λAx‖ / ((‖B‖ + |λ|‖A‖)‖x‖) (Higham & Higham, "Structured backward
//!   error and condition of generalized eigenvalue problems", SIMAX 20, 1998);
//! - condition κ = (‖B‖ + |λ|‖A‖)‖x‖² / (xᵀAx) of a simple eigenvalue of a definite pencil, so
//!   that |Δλ| ≤ η κ to first order ([`BoundKind::FirstOrder`]);
//! - after refinement, with ε = ‖Bx + λAx‖_{A⁻¹}/‖x‖_A and a gap δ to the rest of the spectrum,
//!   |Δλ| ≤ min(ε, ε²/δ) (residual and Kato–Temple bounds, Parlett, "The Symmetric Eigenvalue
//!   Problem", §4.5 and §10.5, applied to L⁻¹(B)L⁻ᵀ) ([`BoundKind::Residual`]).

use crate::sketch::{Sketch, SketchRows};
use crate::solve::InertiaCheck;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::sparse::SparseColMat;
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::{Mat, MatMut, MatRef, Par};
use std::ops::Range;

/// Where a mode's error bound comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundKind {
    /// η·κ from the pair's backward error and the eigenvalue's condition (first order).
    FirstOrder,
    /// n·u·(‖B‖ + |λ|‖A‖)·‖A⁻¹‖ assuming a backward error n·u (values only; no vectors), with
    /// ‖A⁻¹‖₂ bounded with probability ≥ 1 − 1e-12.
    APriori,
    /// Residual / Kato–Temple bound from an extended-precision residual (refined modes).
    Residual,
}

/// Accuracy of every number of a [`crate::ModalSolution`]; per-mode vectors are in mode order.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyReport {
    /// ‖A‖_F.
    pub norm_a: f64,
    /// ‖B‖_F.
    pub norm_b: f64,
    /// Backward error η of each pair (None for values only).
    pub backward_errors: Vec<Option<f64>>,
    /// max η over the pairs (None for values only or no pairs).
    pub max_backward_error: Option<f64>,
    /// max |(XᵀAX − I)_ij| over the finite modes (None for values only).
    pub orthogonality_error: Option<f64>,
    /// Bound on |ω²_computed − ω²_exact| of each mode.
    pub error_bounds: Vec<f64>,
    /// Where each bound comes from.
    pub bound_kinds: Vec<BoundKind>,
    /// ‖Bx + λAx‖_{A⁻¹}/‖x‖_A in extended precision, for refined modes.
    pub residual_norms_a_inv: Vec<Option<f64>>,
    /// Refinement steps taken per mode (0: not refined).
    pub refinement_steps: Vec<usize>,
    /// The Sturm check: LBLᵀ inertia of B − sA against the computed spectrum.
    pub inertia_check: Option<InertiaCheck>,
    /// How the backward errors and the orthogonality error were measured.
    pub residuals: Residuals,
}

impl AccuracyReport {
    pub(crate) fn empty() -> Self {
        Self {
            norm_a: 0.0,
            norm_b: 0.0,
            backward_errors: Vec::new(),
            max_backward_error: None,
            orthogonality_error: None,
            error_bounds: Vec::new(),
            bound_kinds: Vec::new(),
            residual_norms_a_inv: Vec::new(),
            refinement_steps: Vec::new(),
            inertia_check: None,
            residuals: Residuals::Exact,
        }
    }

    pub(crate) fn a_priori(norm_a: f64, norm_b: f64, bounds: Vec<f64>) -> Self {
        let m = bounds.len();
        Self {
            norm_a,
            norm_b,
            backward_errors: vec![None; m],
            max_backward_error: None,
            orthogonality_error: None,
            error_bounds: bounds,
            bound_kinds: vec![BoundKind::APriori; m],
            residual_norms_a_inv: vec![None; m],
            refinement_steps: vec![0; m],
            inertia_check: None,
            residuals: Residuals::Exact,
        }
    }

    /// Whether every backward error meets the target 10·n·u.
    pub fn meets_backward_error_target(&self, n: usize) -> bool {
        self.max_backward_error
            .is_some_and(|e| e <= 10.0 * n as f64 * f64::EPSILON)
    }
}

/// ‖M‖_F, summed in one pass; only when the sum of squares over- or underflows does it fall back
/// to faer's scaled (slower) norm.
pub(crate) fn frobenius_norm(m: MatRef<'_, f64>) -> f64 {
    let sum: f64 = (0..m.ncols()).map(|j| sum_of_squares(m.col(j))).sum();
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        m.norm_l2()
    }
}

/// Σ v_i² with four independent partial sums (vectorisable when `v` is contiguous).
fn sum_of_squares(v: faer::ColRef<'_, f64>) -> f64 {
    match v.try_as_col_major() {
        Some(c) => {
            let s = c.as_slice();
            let mut acc = [0.0_f64; 4];
            let mut chunks = s.chunks_exact(4);
            for q in &mut chunks {
                for l in 0..4 {
                    acc[l] += q[l] * q[l];
                }
            }
            let tail: f64 = chunks.remainder().iter().map(|x| x * x).sum();
            (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
        }
        None => v.iter().map(|x| x * x).sum(),
    }
}

/// ‖v‖₂ with the one-pass sum of squares and the scaled fallback of [`frobenius_norm`].
fn vector_norm(v: faer::ColRef<'_, f64>) -> f64 {
    let sum = sum_of_squares(v);
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        v.norm_l2()
    }
}

/// How the accuracy report measures the residuals and the A-orthogonality of dense pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Residuals {
    /// A X, B X and XᵀAX formed in full (5n²m flops for m pairs): every backward error and the
    /// orthogonality error are computed exactly (to rounding).
    #[default]
    Exact,
    /// Gaussian sketches ([`crate::sketch`], O(k·n²) flops with k = 32): each backward error and
    /// the orthogonality error (then a bound on ‖XᵀAX − I‖_F) is an upper bound that fails with
    /// probability at most 1e-12; typically 2–4 times the exact value. Where the exact products
    /// cost less (all pairs below n ≈ 200, or a few pairs of any pencil) they are formed
    /// instead, and the report's `residuals` says `Exact`.
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
/// crossover is n ≈ 200 (measured: sketched 1.3–5× slower at n = 12–120, 1.2× faster at 250);
/// for a few pairs of a large pencil the exact products are cheaper at any n.
pub(crate) fn exact_costs_less(n: usize, m: usize) -> bool {
    let (n, m, k) = (n as f64, m as f64, crate::sketch::SKETCH_SIZE as f64);
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

    /// Backward error η_i and first-order bound η_i·κ_i of the pair (ω²_i, x_i). Sketched, the
    /// residual is its probabilistic upper bound and x_iᵀAx_i ≥ 1 − ‖XᵀAX − I‖_F.
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
                let r = (0..n).map(|k| (bxi[k] - omega_sq * axi[k]).powi(2)).sum::<f64>().sqrt();
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
    fn orthogonality_error(&mut self, a: MatRef<'_, f64>, x: MatRef<'_, f64>, par: Par) -> f64 {
        let ax = match self {
            Self::Exact { ax, .. } => ax,
            Self::Sketched {
                sketch,
                orthogonality,
                changed,
            } => {
                if changed.len() > crate::sketch::SKETCH_SIZE {
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

impl AccuracyReport {
    /// Backward errors and first-order bounds of every pair from `products` (max η and the
    /// orthogonality are left to [`AccuracyReport::finish`], once the vectors are final).
    pub(crate) fn from_products(
        products: &PairProducts,
        x: MatRef<'_, f64>,
        omega_sq: &[f64],
        norm_a: f64,
        norm_b: f64,
    ) -> Self {
        let m = omega_sq.len();
        let mut report = Self::a_priori(norm_a, norm_b, vec![0.0; m]);
        report.bound_kinds = vec![BoundKind::FirstOrder; m];
        if matches!(products, PairProducts::Sketched { .. }) {
            report.residuals = Residuals::Sketched;
        }
        for i in 0..m {
            report.set_pair_error(products, x, i, omega_sq[i]);
        }
        report
    }

    /// Recomputes η and the first-order bound of pair i.
    pub(crate) fn set_pair_error(&mut self, products: &PairProducts, x: MatRef<'_, f64>, i: usize, omega_sq: f64) {
        let (eta, bound) = products.pair_error(x, i, omega_sq, self.norm_a, self.norm_b);
        self.backward_errors[i] = Some(eta);
        self.error_bounds[i] = bound;
    }

    /// Sets the A-orthogonality error and max η once the vectors are final. Sketched, the
    /// first-order bounds of unrefined modes are recomputed with the final orthogonality bound.
    pub(crate) fn finish(
        &mut self,
        products: &mut PairProducts,
        a: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        omega_sq: &[f64],
        par: Par,
    ) {
        let m = x.ncols();
        self.orthogonality_error = (m > 0).then(|| products.orthogonality_error(a, x, par));
        if matches!(products, PairProducts::Sketched { .. }) {
            for i in 0..m {
                if self.bound_kinds[i] == BoundKind::FirstOrder {
                    self.set_pair_error(products, x, i, omega_sq[i]);
                }
            }
        }
        self.max_backward_error = (m > 0).then(|| self.backward_errors.iter().flatten().copied().fold(0.0, f64::max));
    }
}

/// Gaussian probes of [`a_inverse_norm_bound`]: with α = 10 the bound fails with probability
/// at most α^(−probes) = 1e-12 (the sketches' [`crate::sketch::FAILURE_PROBABILITY`]).
const NORM_PROBES: usize = 12;
/// Powers of A⁻¹ applied to the probes. The bound overestimates ‖A⁻¹‖₂ by at most
/// (α√(2/π)·max‖ω_i‖)^(1/q): about 3.3 at n = 200 and 4.4 at n = 2000 when A's spectrum is flat
/// (A = I), less when it is graded; trace A⁻¹, the deterministic alternative, is n times
/// too large for A = I.
const NORM_POWER: usize = 4;

/// An upper bound of ‖A⁻¹‖₂ from the Cholesky factor L of A that holds with probability
/// ≥ 1 − 1e-12 over the probes (for an A that does not depend on them; see [`probe_seed`]),
/// and never below the deterministic lower bounds 1/L_nn² and 1/min_i A_ii: for any matrix M and r independent standard Gaussian vectors ω_i,
/// ‖M‖ ≤ α√(2/π)·max_i ‖Mω_i‖ except with probability α^(−r) (Halko, Martinsson & Tropp,
/// "Finding structure with randomness", SIAM Review 53, 2011, Lemma 4.1, after Dixon 1983),
/// applied to M = (L⁻ᵀL⁻¹)^q = A^(−q), whose norm is ‖A⁻¹‖^q. Cost: 2q triangular solves
/// on r columns (2qrn² flops). Probes are renormalised after every power, so the bound
/// is infinite only when ‖A⁻¹‖ itself overflows. A diagonal L (lumped masses) gives the exact
/// value max_i 1/l_ii² instead, with no probability of failure.
pub(crate) fn a_inverse_norm_bound(l: MatRef<'_, f64>, par: Par) -> f64 {
    let n = l.nrows();
    if n == 0 {
        return 0.0;
    }
    if crate::linalg::reduce::is_diagonal(l) {
        return (0..n).map(|i| (l[(i, i)] * l[(i, i)]).recip()).fold(0.0, f64::max);
    }
    let mut v = crate::sketch::gaussian(n, NORM_PROBES, probe_seed(l));
    // ln ‖A^(−k) ω_i‖ after k powers.
    let mut log_norms = [0.0_f64; NORM_PROBES];
    for _ in 0..NORM_POWER {
        solve_lower_triangular_in_place(l, v.as_mut(), par);
        solve_upper_triangular_in_place(l.transpose(), v.as_mut(), par);
        for (j, log_norm) in log_norms.iter_mut().enumerate() {
            let length = vector_norm(v.col(j));
            if !(length.is_finite() && length > 0.0) {
                return f64::INFINITY;
            }
            *log_norm += length.ln();
            v.col_mut(j).iter_mut().for_each(|e| *e /= length);
        }
    }
    let alpha = 10.0_f64;
    let largest = log_norms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let probed = (((alpha * (2.0 / std::f64::consts::PI).sqrt()).ln() + largest) / NORM_POWER as f64).exp();
    // Deterministic lower bounds of ‖A⁻¹‖₂, which no choice of probes can miss:
    // (A⁻¹)_nn = 1/L_nn² and 1/λ_min ≥ 1/A_ii ≥ 1/Σ_k L_ik² for every i.
    let last = l[(n - 1, n - 1)];
    let mut diagonal_of_a = vec![0.0_f64; n];
    for k in 0..n {
        for (i, entry) in l.col(k).iter().enumerate().skip(k) {
            diagonal_of_a[i] += entry * entry;
        }
    }
    let smallest_diagonal = diagonal_of_a.iter().copied().fold(f64::INFINITY, f64::min);
    probed.max(1.0 / (last * last)).max(1.0 / smallest_diagonal)
}

/// The seed of [`a_inverse_norm_bound`]'s probes, hashed (FNV-1a) from L's diagonal: the
/// probability is over the probes for an A chosen independently of them, and with one fixed
/// seed every A built against its probes (a small eigenvector orthogonal to all twelve)
/// would defeat the bound.
fn probe_seed(l: MatRef<'_, f64>) -> u64 {
    (0..l.nrows()).fold(0xcbf2_9ce4_8422_2325_u64, |h, i| {
        (h ^ l[(i, i)].to_bits()).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The a-priori (values-only) error n·u·(‖B‖ + |ω²|‖A‖)·‖A⁻¹‖ of a value whose pair was never
/// measured: a backward error of n·u assumed, ‖A⁻¹‖₂ bounded as in [`a_inverse_norm_bound`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct APrioriModel {
    /// n·u·‖A⁻¹‖₂.
    scale: f64,
    /// The order n.
    order: usize,
    norm_a: f64,
    norm_b: f64,
}

impl APrioriModel {
    pub(crate) fn new(l: MatRef<'_, f64>, norm_a: f64, norm_b: f64, par: Par) -> Self {
        let order = l.nrows();
        let scale = order as f64 * f64::EPSILON * a_inverse_norm_bound(l, par);
        Self {
            scale,
            order,
            norm_a,
            norm_b,
        }
    }

    pub(crate) fn bound(&self, omega_sq: f64) -> f64 {
        self.scale * (self.norm_b + omega_sq.abs() * self.norm_a)
    }

    /// [`normwise_resolution`] without the mode shape: ‖x‖₂² ≤ ‖A⁻¹‖₂ for an A-normalised x.
    pub(crate) fn data_resolution(&self, omega_sq: f64) -> f64 {
        self.bound(omega_sq) / self.order.max(1) as f64
    }

    /// The bounds of the values `omega_sq`.
    pub(crate) fn bounds(&self, omega_sq: &[f64]) -> Vec<f64> {
        omega_sq.iter().map(|&w| self.bound(w)).collect()
    }
}

/// The change of ω² that rounding A and B entrywise can cause for an A-normalised mode shape x:
/// |xᵀδBx| + |ω²|·|xᵀδAx| ≤ u(|x|ᵀ|B||x| + |ω²|·|x|ᵀ|A||x|) for |δA| ≤ u|A|, |δB| ≤ u|B| (u
/// taken as f64::EPSILON, one rounding of each entry with margin). Below it neither the sign
/// nor the size of ω² is determined by the data: a rigid-body mode of a stiffness matrix that is
/// singular only up to rounding (an assembled or rotated one) has a computed ω² of that order,
/// of either sign, however tight its error bound for the stored matrices. Componentwise, so a
/// soft spring beside stiff ones, or a small negative stiffness on a decoupled coordinate,
/// stays resolved. O(n²); [`normwise_resolution`] bounds it from above in O(n).
pub fn data_resolution(a: MatRef<'_, f64>, b: MatRef<'_, f64>, x: &[f64], omega_sq: f64) -> f64 {
    f64::EPSILON * (abs_quadratic(b, x) + omega_sq.abs() * abs_quadratic(a, x))
}

/// An upper bound of [`data_resolution`] from norms: |x|ᵀ|M||x| ≤ ‖M‖_F‖x‖₂².
pub fn normwise_resolution(omega_sq: f64, norm_a: f64, norm_b: f64, shape_norm_sq: f64) -> f64 {
    f64::EPSILON * (norm_b + omega_sq.abs() * norm_a) * shape_norm_sq
}

/// |x|ᵀ|M||x| of a dense M.
fn abs_quadratic(m: MatRef<'_, f64>, x: &[f64]) -> f64 {
    (0..m.ncols())
        .map(|j| {
            let column: f64 = m.col(j).iter().zip(x).map(|(mij, xi)| (mij * xi).abs()).sum();
            column * x[j].abs()
        })
        .sum()
}

/// The resolution the zero classification compares |ω²| with: [`data_resolution`] where
/// |ω²| is within the cheap [`normwise_resolution`] (only there can it decide), the normwise
/// value elsewhere.
pub(crate) fn zero_resolution(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    x: &[f64],
    omega_sq: f64,
    (norm_a, norm_b): (f64, f64),
) -> f64 {
    let shape_norm_sq = x.iter().map(|v| v * v).sum::<f64>();
    let normwise = normwise_resolution(omega_sq, norm_a, norm_b, shape_norm_sq);
    if omega_sq.abs() <= normwise {
        data_resolution(a, b, x, omega_sq)
    } else {
        normwise
    }
}

/// The computed modes used to split a residual into its modal components.
pub(crate) struct ModeBasis<'a> {
    pub a: MatRef<'a, f64>,
    /// Cholesky factor of A.
    pub l: MatRef<'a, f64>,
    /// Computed modes, A-orthonormal to working precision: all selected modes, or (values
    /// only) those formed for refinement.
    pub x: MatRef<'a, f64>,
    /// The index within the selection of each column of `x`.
    pub modes: &'a [usize],
    /// Values only: the error model of the unselected modes' values (never measured), for the
    /// gaps to them; None when they are as accurate as the selected ones.
    pub unselected: Option<APrioriModel>,
}

/// The residual of a refined mode, with the cluster of modes refined together as one block
/// ([`crate::refine::refine_cluster_projected`]; a simple mode is a cluster of one).
pub(crate) struct RefinedResidual {
    /// The mode's index within the selection.
    pub mode: usize,
    /// The selection indices of the modes refined together with it (contains `mode`).
    pub cluster: Range<usize>,
    /// max |x_kᵀAx_l| over distinct refined vectors of the cluster (0 for a single mode).
    pub orthogonality: f64,
    /// (B − ω²A)x from double-double, rounded.
    pub residual: Vec<f64>,
}

/// Replaces the bounds of refined modes by a gap-weighted Kato–Temple bound.
///
/// The residual r = (B − ρA)x of a refined, A-normalised x is split along the computed modes,
/// r = Σ_j c_j A x_j + r_⊥ with c_j = x_jᵀ r; since the eigenvalue error is
/// Σ_{j≠i} |γ_j|²(ω²_j − ω²_i) with r's components γ_j(ω²_j − ρ), it is at most
/// Σ_{j≠i} c_j² / δ_j + ‖r_⊥‖²_{A⁻¹}/δ, with δ_j = |ω²_j − ρ| − bound_j and δ the smallest gap
/// (first order in the error of the computed basis). It is never taken larger than the linear
/// residual bound ε = ‖r‖_{A⁻¹}, and u|ρ| is added for rounding ρ to double. Selected modes
/// missing from the basis only enter through δ (their components stay in r_⊥), and so do
/// unselected modes (outside `first..first + m` of `omega_all`), with the largest bound of the
/// selection as their uncertainty, or (values only) their a-priori error if that is larger.
///
/// A cluster G of p modes refined as one block gets one bound for all its members, the same
/// sums taken over the block: ε² = Σ_{k∈G} ‖r_k‖²_{A⁻¹} (the Frobenius norm of the block
/// residual, which bounds its 2-norm: p eigenvalues lie within it of the Ritz values, Kahan's
/// theorem; Parlett, "The Symmetric Eigenvalue Problem", Thm 11.5.1), Σ_{j∉G} Σ_{k∈G} c_{jk}²/δ_j
/// with δ_j the gap from mode j to the nearest member, and ‖R_⊥‖²_F/δ: the quadratic residual
/// bound of a Ritz block separated by δ from the rest of the spectrum (Mathias, SIMAX 19, 1998).
/// p·γ·s and u·s are added for the block's A-orthogonality defect γ and the rounding, with s
/// the largest |ω²| of the block.
pub(crate) fn residual_bounds(
    report: &mut AccuracyReport,
    omega_sq: &[f64],
    omega_all: &[f64],
    first: usize,
    residuals: &[RefinedResidual],
    basis: &ModeBasis<'_>,
    par: Par,
) {
    let m = omega_sq.len();
    let n = basis.x.nrows();
    let k = residuals.len();
    if k == 0 {
        return;
    }
    let others_bound = report.error_bounds.iter().copied().fold(0.0, f64::max);
    let linear: Vec<f64> = (0..m)
        .map(|i| {
            report.residual_norms_a_inv[i].map_or(report.error_bounds[i], |e| e + f64::EPSILON * omega_sq[i].abs())
        })
        .collect();
    // All refined residuals at once: C = Xᵀ R, and R_⊥ = L⁻¹(R − A X C) in the A⁻¹-norm.
    let r = Mat::from_fn(n, k, |row, col| residuals[col].residual[row]);
    let mut c = Mat::<f64>::zeros(basis.x.ncols(), k);
    faer::linalg::matmul::matmul(
        c.as_mut(),
        faer::Accum::Replace,
        basis.x.transpose(),
        r.as_ref(),
        1.0,
        par,
    );
    let mut xc = Mat::<f64>::zeros(n, k);
    let mut column_of = vec![None; m];
    for (col, &mode) in basis.modes.iter().enumerate() {
        column_of[mode] = Some(col);
    }
    let mut residual_of = vec![None; m];
    for (col, refined) in residuals.iter().enumerate() {
        residual_of[refined.mode] = Some(col);
    }
    faer::linalg::matmul::matmul(xc.as_mut(), faer::Accum::Replace, basis.x, c.as_ref(), 1.0, par);
    let mut rest = r;
    faer::linalg::matmul::matmul(rest.as_mut(), faer::Accum::Add, basis.a, xc.as_ref(), -1.0, par);
    solve_lower_triangular_in_place(basis.l, rest.as_mut(), par);
    for refined in residuals {
        let i = refined.mode;
        let group = refined.cluster.clone();
        // The block's residual columns; a member without one leaves the linear bound.
        let Some(columns) = group
            .clone()
            .map(|g| residual_of[g].zip(report.residual_norms_a_inv[g]))
            .collect::<Option<Vec<(usize, f64)>>>()
        else {
            continue;
        };
        let eps = columns.iter().map(|(_, e)| e * e).sum::<f64>().sqrt();
        let distance = |w: f64| {
            group
                .clone()
                .map(|g| (omega_sq[g] - w).abs())
                .fold(f64::INFINITY, f64::min)
        };
        let mut gap = f64::INFINITY;
        let mut weighted = 0.0;
        let mut usable = true;
        for j in (0..m).filter(|j| !group.contains(j)) {
            let d = distance(omega_sq[j]) - linear[j];
            gap = gap.min(d);
            if let Some(basis_col) = column_of[j] {
                if d > 0.0 {
                    weighted += columns.iter().map(|&(col, _)| c[(basis_col, col)].powi(2)).sum::<f64>() / d;
                } else {
                    usable = false;
                }
            }
        }
        for (k, &w) in omega_all.iter().enumerate() {
            if k < first || k >= first + m {
                let uncertainty = basis
                    .unselected
                    .map_or(others_bound, |model| model.bound(w).max(others_bound));
                gap = gap.min(distance(w) - uncertainty);
            }
        }
        let eps_rest = columns
            .iter()
            .map(|&(col, _)| vector_norm(rest.col(col)).powi(2))
            .sum::<f64>()
            .sqrt();
        let mut bound = eps;
        if gap > eps {
            bound = bound.min(eps * eps / gap);
            if usable && gap > eps_rest {
                bound = bound.min(weighted + eps_rest * eps_rest / gap);
            }
        }
        // Rounding and the block's A-orthogonality defect at the cluster's largest |ω²|: the
        // Rayleigh–Ritz step in double leaves a mixing of order u between members, which moves a
        // member's Rayleigh quotient by up to u² times the cluster's spread (found in review: a
        // zero mode chained to soft ones had ω² = 5e-37 against a bound of 1.7e-40 with |ρ_i|).
        let scale = group.clone().map(|g| omega_sq[g].abs()).fold(0.0, f64::max);
        let defect = group.len() as f64 * refined.orthogonality * scale;
        report.error_bounds[i] = bound + defect + f64::EPSILON * scale;
        report.bound_kinds[i] = BoundKind::Residual;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::reduce::{Cholesky, cholesky};
    use crate::testing;

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
        let mut x = crate::sketch::gaussian(n, 7, 3);
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

    /// The probabilistic bound of ‖A⁻¹‖₂ lies above the true norm and within its worst-case
    /// overestimate (α√(2/π)·max‖ω_i‖)^(1/q) (reached by A = I), for a rotated mass matrix
    /// whose eigenvalues (and so ‖A⁻¹‖ = 1/λ_min) are known, from well to badly conditioned.
    #[test]
    fn a_inverse_bound_holds_and_is_tight() {
        let n = 200;
        let q = testing::random_orthogonal(n, 5);
        for decades in [0.0, 6.0, 12.0] {
            let lambda: Vec<f64> = (0..n)
                .map(|i| 10f64.powf(-decades * i as f64 / (n - 1) as f64))
                .collect();
            let d = Mat::from_fn(n, n, |i, j| if i == j { lambda[i] } else { 0.0 });
            let (a, _) = testing::rotate(&d, &d, &q);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("positive definite");
            };
            let exact = 1.0 / lambda[n - 1];
            let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
            let probes = crate::sketch::gaussian(n, NORM_PROBES, probe_seed(l.as_ref()));
            let longest = (0..NORM_PROBES).map(|j| vector_norm(probes.col(j))).fold(0.0, f64::max);
            let worst =
                (10.0 * (2.0 / std::f64::consts::PI).sqrt() * longest).powf(1.0 / NORM_POWER as f64) * (1.0 + 1e-9);
            assert!(
                bound >= exact && bound <= worst * exact,
                "{decades} decades: {bound:e} vs {exact:e}"
            );
        }
        // One small eigenvalue ε along a dense direction u: the diagonal of A stays near 1,
        // so only the probes can see ‖A⁻¹‖ = 1/ε.
        let u = q.col(0);
        for eps in [1e-2, 1e-4, 1e-8] {
            let a = Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } - (1.0 - eps) * u[i] * u[j]);
            let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
                panic!("positive definite");
            };
            let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
            assert!(bound >= 1.0 / eps && bound <= 10.0 / eps, "ε = {eps:e}: {bound:e}");
        }
        // A diagonal A: exactly 1/min a_ii (to the rounding of l_ii² = a_ii), probes or not.
        let masses: Vec<f64> = (0..n)
            .map(|i| 10f64.powf(6.0 - 12.0 * ((i * 37) % n) as f64 / n as f64))
            .collect();
        let a = Mat::from_fn(n, n, |i, j| if i == j { masses[i] } else { 0.0 });
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("positive definite");
        };
        let exact = 1.0 / masses.iter().copied().fold(f64::INFINITY, f64::min);
        let bound = a_inverse_norm_bound(l.as_ref(), Par::Seq);
        assert!(
            (bound - exact).abs() <= 4.0 * f64::EPSILON * exact,
            "{bound:e} vs {exact:e}"
        );
    }
}
