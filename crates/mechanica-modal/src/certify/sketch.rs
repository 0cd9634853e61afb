//! Gaussian sketches of the accuracy report: residual norms and the A-orthogonality error of m
//! dense pairs in O(k·n²) flops instead of the 5n²m of the exact products A X, B X and XᵀAX.
//!
//! For a fixed vector r and an independent k×n matrix S with standard normal entries,
//! ‖Sr‖²/‖r‖² is χ²_k distributed, and the Chernoff bound of its lower tail gives
//! P(‖Sr‖² ≤ t·k·‖r‖²) ≤ (t·e^{1−t})^{k/2} for 0 < t < 1. So ‖r‖ ≤ ‖Sr‖/√(t·k) holds except
//! with probability at most that. The same bound holds for ‖EΩ‖_F against ‖E‖_F with an m×k
//! Gaussian Ω, since Σσ_i²χ²_{k,i} has a smaller moment generating function at negative
//! arguments than the single term χ²_k·Σσ_i² (Π(1 + 2s·w_i) ≥ 1 + 2s for weights summing to 1).
//! The sketches use a fixed seed (reproducible reports); they are independent of the pencil.

use crate::linalg::norms::euclidean_norm;
use faer::{Accum, Mat, MatRef, Par};

/// Rows of the residual sketch (and columns of the orthogonality sketch).
pub const SKETCH_SIZE: usize = 32;

/// The probability, per reported quantity, that a sketched bound does not hold.
pub const FAILURE_PROBABILITY: f64 = 1e-12;

/// The largest t in (0, 1) with (t·e^{1−t})^{k/2} ≤ p (bisection; the left side increases in t).
pub(crate) fn chernoff_fraction(k: usize, p: f64) -> f64 {
    let tail = |t: f64| (0.5 * k as f64) * (t.ln() + 1.0 - t);
    let target = p.ln();
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) <= target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// A rows×cols matrix of standard normal numbers (Box–Muller on a 64-bit LCG from `seed`).
pub(crate) fn gaussian(rows: usize, cols: usize, seed: u64) -> Mat<f64> {
    let mut state = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        // In (0, 1]: never 0, so the logarithm below is finite.
        ((state >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    };
    Mat::from_fn(rows, cols, |_, _| {
        let (u1, u2) = (uniform(), uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    })
}

fn product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(lhs.nrows(), rhs.ncols());
    faer::linalg::matmul::matmul(out.as_mut(), Accum::Replace, lhs, rhs, 1.0, par);
    out
}

/// The sketch's rows S·A and S·B (k×n): they do not depend on the modes, so a solve can form
/// them early (on idle core time, [`crate::runtime::idle_task`]).
pub(crate) struct SketchRows {
    sa: Mat<f64>,
    sb: Mat<f64>,
}

impl SketchRows {
    /// S·A and S·B for the fixed-seed Gaussian S of every report, formed on one thread: the
    /// same products whether an idle thread or the report forms them, so that the report's
    /// bounds do not depend on which did (4kn² flops).
    pub(crate) fn new(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Self {
        let s = gaussian(SKETCH_SIZE, a.nrows(), 1);
        Self {
            sa: product(s.as_ref(), a, Par::Seq),
            sb: product(s.as_ref(), b, Par::Seq),
        }
    }
}

/// The sketched products S·A·X and S·B·X of a set of pairs, and the bound factor 1/√(t·k).
pub(crate) struct Sketch {
    rows: SketchRows,
    sax: Mat<f64>,
    sbx: Mat<f64>,
    factor: f64,
}

impl Sketch {
    /// S A, S B (k×n; taken from `rows` when given, 4·k·n² flops otherwise) and their products
    /// with X (4·k·n·m flops).
    pub(crate) fn new(
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        x: MatRef<'_, f64>,
        rows: Option<SketchRows>,
        par: Par,
    ) -> Self {
        let n = a.nrows();
        let rows = rows
            .filter(|r| r.sa.shape() == (SKETCH_SIZE, n) && r.sb.shape() == (SKETCH_SIZE, n))
            .unwrap_or_else(|| SketchRows::new(a, b));
        let (sax, sbx) = (product(rows.sa.as_ref(), x, par), product(rows.sb.as_ref(), x, par));
        let factor = 1.0 / (chernoff_fraction(SKETCH_SIZE, FAILURE_PROBABILITY) * SKETCH_SIZE as f64).sqrt();
        Self { rows, sax, sbx, factor }
    }

    /// Recomputes column i after x_i changed.
    pub(crate) fn update_column(&mut self, x: MatRef<'_, f64>, i: usize) {
        let xi = x.subcols(i, 1);
        let (sa, sb) = (self.rows.sa.as_ref(), self.rows.sb.as_ref());
        faer::linalg::matmul::matmul(
            self.sax.as_mut().subcols_mut(i, 1),
            Accum::Replace,
            sa,
            xi,
            1.0,
            Par::Seq,
        );
        faer::linalg::matmul::matmul(
            self.sbx.as_mut().subcols_mut(i, 1),
            Accum::Replace,
            sb,
            xi,
            1.0,
            Par::Seq,
        );
    }

    /// An upper bound of ‖B x_i − ω² A x_i‖ that fails with probability ≤ [`FAILURE_PROBABILITY`].
    pub(crate) fn residual_bound(&self, i: usize, omega_sq: f64) -> f64 {
        let (sax, sbx) = (self.sax.col(i), self.sbx.col(i));
        let rows: Vec<f64> = (0..SKETCH_SIZE).map(|r| sbx[r] - omega_sq * sax[r]).collect();
        self.factor * euclidean_norm(&rows)
    }

    /// An upper bound of ‖XᵀAX − I‖_F (≥ every |(XᵀAX − I)_ij|) that fails with probability
    /// ≤ [`FAILURE_PROBABILITY`]: the norm of (XᵀAX − I)Ω for an m×k Gaussian Ω (6·k·n·m flops).
    pub(crate) fn orthogonality_bound(&self, a: MatRef<'_, f64>, x: MatRef<'_, f64>, par: Par) -> f64 {
        let omega = gaussian(x.ncols(), SKETCH_SIZE, 2);
        let x_omega = product(x, omega.as_ref(), par);
        let a_x_omega = product(a, x_omega.as_ref(), par);
        // (XᵀAX − I)Ω = XᵀAXΩ − Ω.
        let mut e = Mat::from_fn(omega.nrows(), omega.ncols(), |r, c| -omega[(r, c)]);
        faer::linalg::matmul::matmul(e.as_mut(), Accum::Add, x.transpose(), a_x_omega.as_ref(), 1.0, par);
        let sum: f64 = (0..SKETCH_SIZE)
            .map(|c| e.col(c).iter().map(|v| v * v).sum::<f64>())
            .sum();
        self.factor * sum.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chernoff_fraction_meets_its_probability() {
        let t = chernoff_fraction(SKETCH_SIZE, FAILURE_PROBABILITY);
        let k = SKETCH_SIZE as f64;
        let bound = (t * (1.0 - t).exp()).powf(0.5 * k);
        // To the rounding of this check's own powf.
        assert!(bound <= FAILURE_PROBABILITY * (1.0 + 1e-9), "{t} {bound:e}");
        assert!(bound > 0.5 * FAILURE_PROBABILITY, "{t} {bound:e}");
        // Mean of χ²_k is k: the fraction is well below 1.
        assert!(t > 0.01 && t < 0.2);
    }

    /// The Gaussian numbers have mean 0 and variance 1 (to sampling error), so ‖Sr‖² ≈ k‖r‖².
    #[test]
    fn the_sketch_entries_are_standard_normal() {
        let g = gaussian(200, 200, 7);
        let n = 40_000.0;
        let mean: f64 = g
            .col_iter()
            .flat_map(|c| c.iter().copied().collect::<Vec<_>>())
            .sum::<f64>()
            / n;
        let var: f64 = g
            .col_iter()
            .flat_map(|c| c.iter().map(|v| v * v).collect::<Vec<_>>())
            .sum::<f64>()
            / n;
        assert!(mean.abs() < 0.02, "{mean}");
        assert!((var - 1.0).abs() < 0.03, "{var}");
    }

    /// On every column of a random matrix the sketched bound is above the exact norm, and by
    /// no more than the factor the lower tail allows (≈ 3.8 with high probability here).
    #[test]
    fn residual_bounds_hold_and_are_tight() {
        let n = 300;
        let a = Mat::<f64>::identity(n, n);
        let b = gaussian(n, n, 11);
        let x = Mat::<f64>::identity(n, 50);
        let sketch = Sketch::new(a.as_ref(), b.as_ref(), x.as_ref(), None, Par::Seq);
        for i in 0..50 {
            let exact = (0..n).map(|r| b[(r, i)].powi(2)).sum::<f64>().sqrt();
            let bound = sketch.residual_bound(i, 0.0);
            assert!(bound >= exact && bound <= 8.0 * exact, "column {i}: {bound} vs {exact}");
        }
    }

    /// Rows formed early are the ones used (rows of 2B double every residual bound), and rows of
    /// another order are ignored (the sketch forms its own).
    #[test]
    fn rows_formed_early_are_used_when_they_fit() {
        let n = 120;
        let a = Mat::<f64>::identity(n, n);
        let b = gaussian(n, n, 11);
        let twice = Mat::from_fn(n, n, |i, j| 2.0 * b[(i, j)]);
        let x = Mat::<f64>::identity(n, 30);
        let plain = Sketch::new(a.as_ref(), b.as_ref(), x.as_ref(), None, Par::Seq);
        let doubled_rows = SketchRows::new(a.as_ref(), twice.as_ref());
        let doubled = Sketch::new(a.as_ref(), b.as_ref(), x.as_ref(), Some(doubled_rows), Par::Seq);
        let small = SketchRows::new(
            a.as_ref().submatrix(0, 0, 60, 60),
            twice.as_ref().submatrix(0, 0, 60, 60),
        );
        let ignored = Sketch::new(a.as_ref(), b.as_ref(), x.as_ref(), Some(small), Par::Seq);
        for i in 0..30 {
            assert_eq!(doubled.residual_bound(i, 0.0), 2.0 * plain.residual_bound(i, 0.0));
            assert_eq!(ignored.residual_bound(i, 0.0), plain.residual_bound(i, 0.0));
        }
    }

    /// The orthogonality bound is above ‖XᵀAX − I‖_F for a perturbed orthonormal X.
    #[test]
    fn orthogonality_bound_holds() {
        let n = 200;
        let a = Mat::<f64>::identity(n, n);
        let noise = gaussian(n, n, 5);
        let x = Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } + 1e-9 * noise[(i, j)]);
        let sketch = Sketch::new(a.as_ref(), a.as_ref(), x.as_ref(), None, Par::Seq);
        let g = x.transpose() * &x;
        let exact = Mat::from_fn(n, n, |i, j| g[(i, j)] - if i == j { 1.0 } else { 0.0 }).norm_l2();
        let bound = sketch.orthogonality_bound(a.as_ref(), x.as_ref(), Par::Seq);
        assert!(bound >= exact && bound <= 8.0 * exact, "{bound:e} vs {exact:e}");
    }
}
