//! The factorizations of the multiplier equations: A = LLᵀ (Cholesky of the mass matrix) and
//! the Schur complement S = J A⁻¹ Jᵀ factored in the order of the equations.
//!
//! **Rank test.** Cholesky of S without pivoting, row by row, is rank revealing for the
//! question "which equation depends on the earlier ones": the pivot d_r of row r is the squared
//! distance (in the metric A⁻¹) of J's row r from the span of the earlier rows, so
//! d_r / S_rr = sin²θ_r with θ_r the angle between row r and that span, independent of the
//! row's units. Row r is redundant when d_r ≤ ε S_rr (ε the relative pivot tolerance), or when
//! the row itself is rounding noise: ‖J_r‖₁ ≤ ε·(the magnitude of the terms J_r is summed
//! from), e.g. the out-of-plane equation of a planar loop. The first redundant row is reported
//! as [`DynamicsError::RedundantConstraint`].

use super::evaluate::Evaluated;
use crate::error::DynamicsError;
use faer::linalg::solvers::{DenseSolveCore, Llt, Solve};
use faer::{Mat, Side};

/// The default relative pivot tolerance ε of the rank test (sin θ ≈ 1e-6).
pub const DEFAULT_PIVOT_TOLERANCE: f64 = 1e-12;

/// ‖M‖∞ (largest row sum of magnitudes).
pub(crate) fn norm_inf(m: &Mat<f64>) -> f64 {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// A symmetric positive definite metric W (the mass matrix A, or the identity) factored.
pub(crate) struct Metric {
    llt: Llt<f64>,
    matrix: Mat<f64>,
}

impl Metric {
    /// Cholesky of `matrix`; [`DynamicsError::SingularMassMatrix`] when it is not positive
    /// definite.
    pub fn new(matrix: Mat<f64>) -> Result<Self, DynamicsError> {
        let llt = matrix.llt(Side::Lower).map_err(|e| {
            let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = e;
            DynamicsError::SingularMassMatrix {
                pivot: index,
                value: matrix[(index, index)],
            }
        })?;
        Ok(Self { llt, matrix })
    }

    /// W⁻¹ B.
    pub fn solve(&self, b: &Mat<f64>) -> Mat<f64> {
        self.llt.solve(b)
    }

    /// W.
    pub fn matrix(&self) -> &Mat<f64> {
        &self.matrix
    }

    /// κ∞(W) = ‖W‖∞ ‖W⁻¹‖∞.
    pub fn condition(&self) -> f64 {
        norm_inf(&self.matrix) * norm_inf(&self.llt.inverse())
    }
}

/// The first redundant row found by [`Schur::new`]: (row, pivot, scale).
pub(crate) type Redundant = (usize, f64, f64);

/// S = J W⁻¹ Jᵀ and Y = W⁻¹ Jᵀ, with S = L_S L_Sᵀ factored in the order of the rows.
pub(crate) struct Schur {
    /// Y = W⁻¹ Jᵀ, n×m.
    pub y: Mat<f64>,
    /// S, m×m.
    pub s: Mat<f64>,
    /// The lower Cholesky factor of S.
    l: Mat<f64>,
}

impl Schur {
    /// Forms and factors S for the Jacobian of `evaluated` in the metric `metric`; the first
    /// redundant row (module docs) is returned as the error.
    pub fn new(metric: &Metric, evaluated: &Evaluated, tolerance: f64) -> Result<Self, Redundant> {
        let j = &evaluated.jacobian;
        let m = j.nrows();
        for r in 0..m {
            let norm: f64 = (0..j.ncols()).map(|k| j[(r, k)].abs()).sum();
            if norm <= tolerance * evaluated.row_scale[r] {
                return Err((r, norm, evaluated.row_scale[r]));
            }
        }
        let y = metric.solve(&j.transpose().to_owned());
        let product = j * &y;
        let s = Mat::from_fn(m, m, |a, b| 0.5 * (product[(a, b)] + product[(b, a)]));
        let l = factor_in_order(&s, tolerance)?;
        Ok(Self { y, s, l })
    }

    /// S⁻¹ b.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let m = b.len();
        let mut x = b.to_vec();
        for r in 0..m {
            let sum: f64 = (0..r).map(|c| self.l[(r, c)] * x[c]).sum();
            x[r] = (x[r] - sum) / self.l[(r, r)];
        }
        for r in (0..m).rev() {
            let sum: f64 = (r + 1..m).map(|c| self.l[(c, r)] * x[c]).sum();
            x[r] = (x[r] - sum) / self.l[(r, r)];
        }
        x
    }

    /// κ∞(S) = ‖S‖∞ ‖S⁻¹‖∞, with S⁻¹ from the factor (m solves).
    pub fn condition(&self) -> f64 {
        let m = self.s.nrows();
        let mut inverse_norm = 0.0f64;
        let mut rows = vec![0.0; m];
        for c in 0..m {
            let mut e = vec![0.0; m];
            e[c] = 1.0;
            for (row, x) in rows.iter_mut().zip(self.solve(&e)) {
                *row += x.abs();
            }
        }
        for row in rows {
            inverse_norm = inverse_norm.max(row);
        }
        norm_inf(&self.s) * inverse_norm
    }
}

/// The lower Cholesky factor of `s`, row by row in order; the first row whose pivot d_r falls
/// to ε·S_rr or below is returned as (r, d_r, S_rr).
fn factor_in_order(s: &Mat<f64>, tolerance: f64) -> Result<Mat<f64>, Redundant> {
    let m = s.nrows();
    let mut l = Mat::<f64>::zeros(m, m);
    for r in 0..m {
        for c in 0..r {
            let sum: f64 = (0..c).map(|k| l[(r, k)] * l[(c, k)]).sum();
            l[(r, c)] = (s[(r, c)] - sum) / l[(c, c)];
        }
        let pivot = s[(r, r)] - (0..r).map(|k| l[(r, k)] * l[(r, k)]).sum::<f64>();
        if pivot.is_nan() || pivot <= tolerance * s[(r, r)] {
            return Err((r, pivot, s[(r, r)]));
        }
        l[(r, r)] = pivot.sqrt();
    }
    Ok(l)
}
