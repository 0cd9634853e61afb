//! Validation of A, C, B and the Fan–Lin–Van Dooren scaling by powers of two.
//!
//! s = γ s̃ and P̃(s̃) = δ P(s): Ã = γ²δA, C̃ = γδC, B̃ = δB with γ = 2^g ≈ √(‖B‖/‖A‖) and
//! δ = 2^d ≈ 1/max(‖B‖, γ‖C‖, γ²‖A‖). Powers of two make the scaled coefficients exact copies of
//! the stored ones, and the backward error and relative condition of an eigenvalue are the same
//! for both problems, so everything is certified on the scaled problem and only s and its
//! absolute bound are multiplied back by γ.

use crate::error::ModalError;
use crate::linalg::norms::frobenius_norm;
use crate::linalg::powers_of_two::{exponent, times_power_of_two};
use faer::{Mat, MatRef};

/// The scaled problem P̃(s̃) = s̃²Ã + s̃C̃ + B̃ and its scales.
pub(super) struct ScaledProblem {
    /// Ã, C̃, B̃.
    pub a: Mat<f64>,
    pub c: Mat<f64>,
    pub b: Mat<f64>,
    /// ‖Ã‖_F, ‖C̃‖_F, ‖B̃‖_F.
    pub norm_a: f64,
    pub norm_c: f64,
    pub norm_b: f64,
    /// γ = 2^gamma_exponent, δ = 2^delta_exponent.
    pub gamma_exponent: i32,
    pub delta_exponent: i32,
}

impl ScaledProblem {
    /// Checks the shapes and entries of A, C, B and scales them.
    pub(super) fn new(a: MatRef<'_, f64>, c: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<Self, ModalError> {
        let n = a.nrows();
        for (what, m) in [("A", a), ("C", c), ("B", b)] {
            check_matrix(what, m, n)?;
        }
        let (la, lc, lb) = (log2_norm(a), log2_norm(c), log2_norm(b));
        if n > 0 && la.is_none() && lc.is_none() && lb.is_none() {
            return Err(ModalError::SingularQuadratic { order: n });
        }
        let g = frequency_exponent(la, lc, lb);
        let largest = [lb, lc.map(|l| l + f64::from(g)), la.map(|l| l + 2.0 * f64::from(g))]
            .into_iter()
            .flatten()
            .fold(f64::NEG_INFINITY, f64::max);
        let d = if largest.is_finite() {
            -(largest.round() as i32)
        } else {
            0
        };
        let a = scaled_copy("A", a, 2 * g + d)?;
        let c = scaled_copy("C", c, g + d)?;
        let b = scaled_copy("B", b, d)?;
        Ok(Self {
            norm_a: frobenius_norm(a.as_ref()),
            norm_c: frobenius_norm(c.as_ref()),
            norm_b: frobenius_norm(b.as_ref()),
            a,
            c,
            b,
            gamma_exponent: g,
            delta_exponent: d,
        })
    }

    /// The order n.
    pub(super) fn order(&self) -> usize {
        self.a.nrows()
    }
}

/// n × n with finite entries.
fn check_matrix(what: &'static str, m: MatRef<'_, f64>, n: usize) -> Result<(), ModalError> {
    if m.nrows() != n || m.ncols() != n {
        return Err(ModalError::BadShape {
            what,
            rows: m.nrows(),
            cols: m.ncols(),
            expected: n,
        });
    }
    for col in 0..n {
        for row in 0..n {
            let value = m[(row, col)];
            if !value.is_finite() {
                return Err(ModalError::NonFinite { what, row, col, value });
            }
        }
    }
    Ok(())
}

/// log₂‖M‖_F, None for M = 0: the Frobenius norm of M/2^e with 2^e its largest |entry|, so
/// that it neither overflows nor underflows.
fn log2_norm(m: MatRef<'_, f64>) -> Option<f64> {
    let largest = (0..m.ncols())
        .flat_map(|j| m.col(j).iter().map(|v| v.abs()).collect::<Vec<_>>())
        .fold(0.0_f64, f64::max);
    if largest == 0.0 {
        return None;
    }
    let e = exponent(largest);
    let unit = Mat::from_fn(m.nrows(), m.ncols(), |i, j| times_power_of_two(m[(i, j)], -e));
    Some(f64::from(e) + frobenius_norm(unit.as_ref()).log2())
}

/// g with 2^g ≈ √(‖B‖/‖A‖) (Fan, Lin & Van Dooren); when A or B vanishes, the scale of the
/// linear part: ‖B‖/‖C‖ (A = 0) or ‖C‖/‖A‖ (B = 0).
fn frequency_exponent(la: Option<f64>, lc: Option<f64>, lb: Option<f64>) -> i32 {
    let g = match (la, lc, lb) {
        (Some(la), _, Some(lb)) => (lb - la) / 2.0,
        (None, Some(lc), Some(lb)) => lb - lc,
        (Some(la), Some(lc), None) => lc - la,
        _ => 0.0,
    };
    g.round() as i32
}

/// M·2^e, refused when a nonzero entry would leave the normal range (its digits would be lost,
/// and the certificate would be for another matrix).
fn scaled_copy(what: &str, m: MatRef<'_, f64>, e: i32) -> Result<Mat<f64>, ModalError> {
    let scaled = Mat::from_fn(m.nrows(), m.ncols(), |i, j| times_power_of_two(m[(i, j)], e));
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            let (stored, value) = (m[(i, j)], scaled[(i, j)]);
            if stored != 0.0 && !(value.is_finite() && value.abs() >= f64::MIN_POSITIVE) {
                return Err(ModalError::OutOfRange {
                    what: format!("{what}[{i}, {j}] = {stored:e}"),
                    detail: format!(
                        "scaled by 2^{e} to balance the coefficients it leaves the normal range of doubles"
                    ),
                });
            }
        }
    }
    Ok(scaled)
}
