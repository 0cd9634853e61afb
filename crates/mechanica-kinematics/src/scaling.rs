//! Exact power-of-two scaling and norms that neither overflow nor underflow in their
//! intermediate squares.
//!
//! Multiplying by a power of two is exact (outside the subnormal range), so a computation
//! done on data scaled into [0.5, 1) and scaled back gives the same rounded result as the
//! unscaled one would, without the spurious overflow of squares and sums of squares at the
//! ends of the double range. These helpers serve every crate of the workspace.

use nalgebra::{Matrix3, Vector3};

/// The power of two 2^k closest above `max_abs` (so that `max_abs`·2^−k ∈ [0.5, 1)), for a
/// finite non-zero `max_abs`, clamped to the normal range [2^−1022, 2^1023]. Returns 1 for
/// zero and non-finite input.
pub fn power_of_two_above(max_abs: f64) -> f64 {
    if max_abs == 0.0 || !max_abs.is_finite() {
        return 1.0;
    }
    let exponent = ((max_abs.abs().to_bits() >> 52) & 0x7ff) as i64 - 1023;
    let k = (exponent + 1).clamp(-1022, 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// 2^k for an exponent k in the normal range [−1022, 1023].
fn two_to(k: i64) -> f64 {
    f64::from_bits(((k.clamp(-1022, 1023) + 1023) as u64) << 52)
}

/// x = m·2^e with |m| ∈ [1, 2) for a finite non-zero x (subnormals included).
fn split_exponent(x: f64) -> (f64, i64) {
    let (x, shift) = if x.abs() < f64::MIN_POSITIVE {
        (x * two_to(64), -64)
    } else {
        (x, 0)
    };
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mantissa = f64::from_bits((bits & !(0x7ff << 52)) | (1023 << 52));
    (mantissa, exponent + shift)
}

/// m·2^e, rounded once unless the result is subnormal (then possibly twice).
fn with_exponent(mut m: f64, mut e: i64) -> f64 {
    while e > 1023 {
        m *= two_to(1023);
        e -= 1023;
        if !m.is_finite() {
            return m;
        }
    }
    while e < -1022 {
        m *= two_to(-1022);
        e += 1022;
        if m == 0.0 {
            return m;
        }
    }
    m * two_to(e)
}

/// The product of `factors` with the exponents kept apart: each factor is split into a
/// mantissa in [1, 2) and a power of two, the mantissas are multiplied and renormalised and
/// the exponents summed, and the result is assembled once. It overflows to ±∞ or underflows
/// to 0 only when the exact product does, and carries the rounding of n − 1 multiplications
/// (plus one more in the subnormal range). A zero factor gives 0, a non-finite one the plain
/// product.
pub fn product(factors: &[f64]) -> f64 {
    if factors.iter().any(|f| !f.is_finite() || *f == 0.0) {
        return factors.iter().product();
    }
    let (mut m, mut e) = (1.0, 0_i64);
    for &f in factors {
        let (fm, fe) = split_exponent(f);
        let (pm, pe) = split_exponent(m * fm);
        m = pm;
        e += fe + pe;
    }
    with_exponent(m, e)
}

/// The Euclidean norm of `v` computed on v/2^k (k from its largest entry) and scaled back:
/// exact to a few ulps whenever the result is representable; +∞ only when it exceeds
/// f64::MAX.
pub fn norm(v: &Vector3<f64>) -> f64 {
    let scale = power_of_two_above(v.amax());
    (v / scale).norm() * scale
}

/// v/|v| formed on v/2^k (k from its largest entry), so that neither the squares of tiny or
/// subnormal entries (whose rounding would leave the result off unit length by 1e-5 and more)
/// nor those of huge ones spoil it; None for a zero or non-finite v.
pub fn unit(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    if !v.iter().all(|x| x.is_finite()) || v.amax() == 0.0 {
        return None;
    }
    let scaled = v / power_of_two_above(v.amax());
    let scaled = if scaled.amax() < 0.5 {
        scaled / scaled.amax()
    } else {
        scaled
    };
    Some(scaled / scaled.norm())
}

/// The Frobenius norm of `m`, scaled like [`norm`].
pub fn frobenius_norm(m: &Matrix3<f64>) -> f64 {
    let scale = power_of_two_above(m.amax());
    (m / scale).norm() * scale
}

/// The Euclidean norm of the entries of `values`, scaled like [`norm`].
pub fn norm_of(values: &[f64]) -> f64 {
    let max = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let scale = power_of_two_above(max);
    values.iter().map(|v| (v / scale) * (v / scale)).sum::<f64>().sqrt() * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_vectors_have_unit_length_at_both_ends_of_the_range() {
        for v in [
            Vector3::new(5.5065031927300575e-160, 3.090332484e-314, 0.0),
            Vector3::new(3e-320, -4e-320, 0.0),
            Vector3::new(1.7e308, -1.7e308, 1e308),
            Vector3::new(1.0, 1e-300, -2.0),
        ] {
            let e = unit(&v).expect("a non-zero finite vector");
            // The exact length of e, from its entries in double-double: within a few ulps of 1.
            let length_sq: f64 = e.iter().map(|x| x * x).sum();
            assert!((length_sq - 1.0).abs() <= 4.0 * f64::EPSILON, "{v:?} → {e:?}");
            // e is parallel to v: their cross product vanishes relative to the scale.
            let s = v / v.amax();
            assert!(e.cross(&s).amax() <= 4.0 * f64::EPSILON, "{v:?} → {e:?}");
        }
        assert!(unit(&Vector3::zeros()).is_none());
        assert!(unit(&Vector3::new(f64::NAN, 1.0, 0.0)).is_none());
    }

    #[test]
    fn scaled_norms_are_exact_at_both_ends_of_the_range() {
        // |(3, 4, 0)·2^k| = 5·2^k exactly, for k from the subnormal range to the largest
        // exponent whose result is representable; the plain norm overflows or underflows there.
        for k in [-1070, -600, -10, 0, 10, 600, 1020] {
            let s = 2f64.powi(k);
            let v = Vector3::new(3.0, 4.0, 0.0) * s;
            assert_eq!(norm(&v), 5.0 * s, "k = {k}");
            assert_eq!(norm_of(v.as_slice()), 5.0 * s, "k = {k}");
            assert_eq!(frobenius_norm(&Matrix3::from_diagonal(&v)), 5.0 * s, "k = {k}");
        }
        assert_eq!(Vector3::new(3e200, 4e200, 0.0).norm(), f64::INFINITY);
        // Past f64::MAX the norm is +∞, and only there.
        assert_eq!(norm(&Vector3::new(f64::MAX, f64::MAX, 0.0)), f64::INFINITY);
        assert!(norm(&Vector3::new(1e308, 1e308, 1e308)).is_finite());
        assert_eq!(norm(&Vector3::zeros()), 0.0);
        assert_eq!(power_of_two_above(0.75), 1.0);
        assert_eq!(power_of_two_above(1.0), 2.0);
        assert_eq!(power_of_two_above(f64::MAX), 2f64.powi(1023));
    }

    #[test]
    fn products_overflow_and_underflow_only_when_their_value_does() {
        // 1e200·1e200·1e-300 = 1e100 (the plain left-to-right product overflows first);
        // 1e-200·1e-200·1e300 = 1e-100 (the plain product underflows first).
        assert!((product(&[1e200, 1e200, 1e-300]) / 1e100 - 1.0).abs() <= 4.0 * f64::EPSILON);
        assert!((product(&[1e-200, 1e-200, 1e300]) / 1e-100 - 1.0).abs() <= 4.0 * f64::EPSILON);
        // Exact powers of two land exactly, down into the subnormals.
        assert_eq!(product(&[2f64.powi(-600), 2f64.powi(-470)]), 2f64.powi(-1070));
        assert_eq!(product(&[2f64.powi(600), 2f64.powi(423)]), 2f64.powi(1023));
        assert_eq!(product(&[f64::MAX, 2.0]), f64::INFINITY);
        assert_eq!(product(&[f64::MIN_POSITIVE, 2f64.powi(-60)]), 0.0);
        assert_eq!(product(&[-3.0, 0.5, -2.0]), 3.0);
        assert_eq!(product(&[]), 1.0);
        assert_eq!(product(&[5.0, 0.0, f64::MAX]), 0.0);
    }
}
