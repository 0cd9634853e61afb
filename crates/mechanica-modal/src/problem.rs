//! The validated symmetric pencil (A, B) of det(λA + B) = 0 ((8.89), see docs/theory.md).

use crate::ModalError;
use faer::{Mat, MatRef};
use std::sync::Arc;

/// Symmetry is accepted when |M_ij − M_ji| ≤ `SYMMETRY_ULPS` · u · max|M|: the rounding
/// that assembling a matrix in a different summation order can leave, and no more.
pub const SYMMETRY_ULPS: f64 = 64.0;

/// A symmetric pencil: mass matrix A (positive semidefinite) and stiffness matrix B
/// (symmetric, any inertia), both n×n and finite. Stored symmetrised exactly, and shared (a
/// clone, or the solver's idle-time certificate thread, holds the same storage).
#[derive(Debug, Clone)]
pub struct PencilProblem {
    a: Arc<Mat<f64>>,
    b: Arc<Mat<f64>>,
}

impl PencilProblem {
    /// Validates shapes, finiteness and symmetry of A and B (no definiteness check yet).
    pub fn new(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<Self, ModalError> {
        let n = a.nrows();
        Ok(Self {
            a: Arc::new(checked_symmetric("A", a, n)?),
            b: Arc::new(checked_symmetric("B", b, n)?),
        })
    }

    /// The order n of the pencil.
    pub fn dim(&self) -> usize {
        self.a.nrows()
    }

    /// The mass matrix A.
    pub fn a(&self) -> MatRef<'_, f64> {
        self.a.as_ref().as_ref()
    }

    /// The stiffness matrix B.
    pub fn b(&self) -> MatRef<'_, f64> {
        self.b.as_ref().as_ref()
    }
}

/// Checks that `m` is n×n, finite and symmetric within [`SYMMETRY_ULPS`]; returns ½(M + Mᵀ).
fn checked_symmetric(what: &'static str, m: MatRef<'_, f64>, n: usize) -> Result<Mat<f64>, ModalError> {
    if m.nrows() != n || m.ncols() != n {
        return Err(ModalError::BadShape {
            what,
            rows: m.nrows(),
            cols: m.ncols(),
            expected: n,
        });
    }
    let mut max_abs = 0.0_f64;
    for j in 0..n {
        for i in 0..n {
            let value = m[(i, j)];
            if !value.is_finite() {
                return Err(ModalError::NonFinite {
                    what,
                    row: i,
                    col: j,
                    value,
                });
            }
            max_abs = max_abs.max(value.abs());
        }
    }
    let tolerance = SYMMETRY_ULPS * f64::EPSILON * max_abs;
    for j in 0..n {
        for i in (j + 1)..n {
            let difference = (m[(i, j)] - m[(j, i)]).abs();
            if difference > tolerance {
                return Err(ModalError::NotSymmetric {
                    what,
                    row: i,
                    col: j,
                    difference,
                    tolerance,
                });
            }
        }
    }
    Ok(Mat::from_fn(n, n, |i, j| symmetric_mean(m[(i, j)], m[(j, i)])))
}

/// The entry of ½(M + Mᵀ) from an entry x and its mirror y. Equal entries are kept as they are
/// (halving each would round among subnormal numbers). Otherwise each is halved first, so that
/// entries near the largest double do not overflow: exact for normal numbers, and since an entry
/// and its mirror are within SYMMETRY_ULPS, the midpoint to the last bit except among subnormals.
pub(crate) fn symmetric_mean(x: f64, y: f64) -> f64 {
    if x == y { x } else { 0.5 * x + 0.5 * y }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asymmetric_stiffness_is_located() {
        let a = Mat::<f64>::identity(3, 3);
        let mut b = Mat::<f64>::identity(3, 3);
        b[(2, 0)] = 1e-3;
        match PencilProblem::new(a.as_ref(), b.as_ref()) {
            Err(ModalError::NotSymmetric {
                what: "B",
                row: 2,
                col: 0,
                ..
            }) => {}
            other => panic!("expected a located asymmetry, got {other:?}"),
        }
    }

    #[test]
    fn mismatched_sizes_are_rejected() {
        let a = Mat::<f64>::identity(3, 3);
        let b = Mat::<f64>::identity(2, 2);
        assert!(matches!(
            PencilProblem::new(a.as_ref(), b.as_ref()),
            Err(ModalError::BadShape {
                what: "B",
                expected: 3,
                ..
            })
        ));
    }
}
