//! The vector operations that the closed-form Hessians are written in, evaluated either on
//! values or on magnitudes.
//!
//! A formula built from sums, differences and products of its inputs, evaluated in
//! [`Magnitudes`] on the componentwise absolute values of those inputs, turns every difference
//! into a sum and so yields, entry by entry, the sum of the absolute values of the terms the
//! [`Values`] evaluation adds up. The rounding of the value is bounded by a multiple of that
//! sum (Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., §3.1: a sum or dot
//! product of computed terms errs by γ_k times the sum of the terms' magnitudes): this is how
//! the field's Hessian is given a componentwise rounding bound without a second derivation.

use nalgebra::{Matrix3, Vector3};
use std::ops::{Add, Sub};

/// The operations of a formula whose value or magnitude is evaluated.
pub(crate) trait Arithmetic {
    /// u × v.
    fn cross(u: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64>;
    /// [w]×, the matrix with [w]× x = w × x.
    fn skew(w: &Vector3<f64>) -> Matrix3<f64>;
    /// ax(M) = (M₃₂ − M₂₃, M₁₃ − M₃₁, M₂₁ − M₁₂).
    fn axial(m: &Matrix3<f64>) -> Vector3<f64>;
    /// a − b.
    fn difference<T: Add<Output = T> + Sub<Output = T>>(a: T, b: T) -> T;
}

/// Ordinary evaluation in double precision.
pub(crate) struct Values;

/// Evaluation on magnitudes: every input is taken non-negative and every difference is a sum.
pub(crate) struct Magnitudes;

impl Arithmetic for Values {
    fn cross(u: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
        u.cross(v)
    }

    fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
        w.cross_matrix()
    }

    fn axial(m: &Matrix3<f64>) -> Vector3<f64> {
        Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
    }

    fn difference<T: Add<Output = T> + Sub<Output = T>>(a: T, b: T) -> T {
        a - b
    }
}

impl Arithmetic for Magnitudes {
    fn cross(u: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(u.y * v.z + u.z * v.y, u.z * v.x + u.x * v.z, u.x * v.y + u.y * v.x)
    }

    fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::new(0.0, w.z, w.y, w.z, 0.0, w.x, w.y, w.x, 0.0)
    }

    fn axial(m: &Matrix3<f64>) -> Vector3<f64> {
        Vector3::new(m[(2, 1)] + m[(1, 2)], m[(0, 2)] + m[(2, 0)], m[(1, 0)] + m[(0, 1)])
    }

    fn difference<T: Add<Output = T> + Sub<Output = T>>(a: T, b: T) -> T {
        a + b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn vector() -> impl Strategy<Value = Vector3<f64>> {
        (-1e3..1e3_f64, -1e3..1e3_f64, -1e3..1e3_f64).prop_map(|(x, y, z)| Vector3::new(x, y, z))
    }

    proptest! {
        /// Each operation on magnitudes bounds the magnitude of the operation on values, and
        /// equals it when no cancellation can occur (non-negative, disjoint supports).
        #[test]
        fn magnitudes_bound_the_values(u in vector(), v in vector()) {
            let (mu, mv) = (u.abs(), v.abs());
            let cross = Magnitudes::cross(&mu, &mv) - Values::cross(&u, &v).abs();
            prop_assert!(cross.iter().all(|&e| e >= -1e-9 * mu.norm() * mv.norm()));
            let skew = Magnitudes::skew(&mu) - Values::skew(&u).abs();
            prop_assert!(skew.iter().all(|&e| e == 0.0));
            let m = u * v.transpose();
            let axial = Magnitudes::axial(&m.abs()) - Values::axial(&m).abs();
            prop_assert!(axial.iter().all(|&e| e >= -1e-9 * m.abs().max()));
            prop_assert_eq!(Magnitudes::difference(2.0, 3.0), 5.0);
            prop_assert_eq!(Values::difference(2.0, 3.0), -1.0);
        }
    }

    #[test]
    fn the_magnitude_of_a_cross_product_is_exact_without_cancellation() {
        let u = Vector3::new(1.0, 0.0, 0.0);
        let v = Vector3::new(0.0, 2.0, 3.0);
        assert_eq!(Magnitudes::cross(&u, &v), Vector3::new(0.0, 3.0, 2.0));
        assert_eq!(Values::cross(&u, &v).abs(), Vector3::new(0.0, 3.0, 2.0));
    }
}
