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
