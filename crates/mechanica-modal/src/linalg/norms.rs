//! Euclidean and Frobenius norms in one pass over the data, with a scaled second pass where the
//! sum of squares over- or underflows.

use faer::MatRef;

use super::powers_of_two::{exponent, times_power_of_two};

/// ‖M‖_F, summed in one pass; only when the sum of squares over- or underflows is it summed
/// again on the entries scaled by a power of two (exact), so that it is finite whenever the
/// norm is representable.
pub(crate) fn frobenius_norm(m: MatRef<'_, f64>) -> f64 {
    let sum: f64 = (0..m.ncols()).map(|j| sum_of_squares(m.col(j))).sum();
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        scaled_norm(|| (0..m.ncols()).flat_map(move |j| m.col(j).iter().copied()))
    }
}

/// √Σ vᵢ² computed on vᵢ·2⁻ᵉ with 2ᵉ⁻¹ ≤ max|vᵢ| < 2ᵉ, then times 2ᵉ: no intermediate
/// over- or underflows (a NaN or ∞ entry gives itself).
fn scaled_norm<I: Iterator<Item = f64>>(values: impl Fn() -> I) -> f64 {
    let largest = values().fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    let e = exponent(largest);
    let sum: f64 = values().map(|v| times_power_of_two(v, -e).powi(2)).sum();
    times_power_of_two(sum.sqrt(), e)
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
pub(crate) fn vector_norm(v: faer::ColRef<'_, f64>) -> f64 {
    let sum = sum_of_squares(v);
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        scaled_norm(|| v.iter().copied())
    }
}

/// √Σ vᵢ² of a few values (norms of columns, residual norms) without over- or underflow of the
/// squares: exact scaling by a power of two where the plain sum leaves the safe range.
pub(crate) fn euclidean_norm(values: &[f64]) -> f64 {
    let sum: f64 = values.iter().map(|v| v * v).sum();
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        scaled_norm(|| values.iter().copied())
    }
}

/// a·(a/b) for a ≥ 0 and b > 0, the quadratic residual bound ε²/δ without the underflow of ε²
/// (an ε below 1e-154 squares to zero): rounded up by one subnormal spacing, the most a
/// product that lands among subnormal numbers can lose.
pub(crate) fn square_over(a: f64, b: f64) -> f64 {
    a * (a / b) + f64::from_bits(1)
}

/// √(Σ xᵢyᵢ) for a non-negative sum (as xᵀK⁻¹x with y = K⁻¹x), with x and y scaled by one power
/// of two 2ᵉ near their largest entry first: neither the products nor the square root over- or
/// underflow while the result is a normal number. A negative sum (rounding) gives 0.
pub(crate) fn sqrt_of_dot(x: &[f64], y: &[f64]) -> f64 {
    let plain: f64 = x.iter().zip(y).map(|(a, b)| a * b).sum();
    if plain.is_finite() && plain > 1e-280 {
        return plain.sqrt();
    }
    let largest = x.iter().chain(y).fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return plain.max(0.0).sqrt();
    }
    let e = exponent(largest);
    let sum: f64 = x
        .iter()
        .zip(y)
        .map(|(a, b)| times_power_of_two(*a, -e) * times_power_of_two(*b, -e))
        .sum();
    times_power_of_two(sum.max(0.0).sqrt(), e)
}

/// √(a² + b²) without spurious over- or underflow, as `f64::hypot`, but by one square root
/// when the larger magnitude lies in [2^−500, 2^500] (then a² + b² is a normal double, and a
/// square of the smaller that underflows is below 2^−75 of the sum): within 2 ulps, for
/// the plane rotations of the tridiagonal eigensolvers.
pub(crate) fn fast_hypot(a: f64, b: f64) -> f64 {
    const LOW: f64 = 3.054936363499605e-151; // 2^−500
    const HIGH: f64 = 3.273390607896142e150; // 2^500
    let larger = a.abs().max(b.abs());
    if (LOW..=HIGH).contains(&larger) {
        (a * a + b * b).sqrt()
    } else {
        a.hypot(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 2^±600 the plain squares over- or underflow; the scaled forms are exact for these
    /// powers of two (3-4-5 triangles).
    #[test]
    fn norms_dots_and_quadratic_bounds_keep_tiny_and_huge_values() {
        for e in [-1000, -600, -300, 0, 300, 600] {
            let s = times_power_of_two(1.0, e);
            assert_eq!(euclidean_norm(&[3.0 * s, 4.0 * s]), 5.0 * s, "2^{e}");
            assert_eq!(sqrt_of_dot(&[3.0 * s, 4.0 * s], &[3.0 * s, 4.0 * s]), 5.0 * s, "2^{e}");
        }
        // ε²/δ with ε = 2^-600, δ = 2^-500: 2^-700, where ε² alone would be 0.
        let eps = times_power_of_two(1.0, -600);
        let bound = square_over(eps, times_power_of_two(1.0, -500));
        assert!(bound >= times_power_of_two(1.0, -700) && bound <= times_power_of_two(1.0, -699));
        // A product below the normal range is rounded up, never down to zero.
        assert!(square_over(times_power_of_two(1.0, -540), 1.0) > 0.0);
    }
    /// Against `f64::hypot` on both sides of the fast range's edges, at every scale, signs
    /// and zeros included: within 2 ulps.
    #[test]
    fn fast_hypot_agrees_with_hypot_at_every_scale() {
        let mut rng = crate::testing::graded::SplitMix::new(0x2545_f491_4f6c_dd1d);
        for _ in 0..200_000 {
            let bits = rng.next_u64();
            let e_a = (bits % 2100) as i32 - 1074;
            let e_b = e_a - ((bits >> 12) % 80) as i32;
            let mantissa = |r: u64| 1.0 + (r % 1_000_003) as f64 / 1_000_003.0;
            let a = times_power_of_two(mantissa(bits >> 20), e_a.min(1022));
            let b = times_power_of_two(mantissa(bits >> 40), e_b.clamp(-1074, 1022));
            let (a, b) = if bits & 1 == 0 { (-a, b) } else { (b, a) };
            let (fast, exact) = (fast_hypot(a, b), a.hypot(b));
            assert!(
                (fast - exact).abs() <= 2.0 * f64::EPSILON * exact,
                "{a:e} {b:e}: {fast:e} {exact:e}"
            );
        }
        assert_eq!(fast_hypot(0.0, 0.0), 0.0);
        assert_eq!(fast_hypot(-3.0, 4.0), 5.0);
    }
}
