//! Euclidean and Frobenius norms in one pass over the data, with a scaled second pass where the
//! sum of squares over- or underflows.

use faer::MatRef;

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

/// √Σ vᵢ² computed on vᵢ·2⁻ᵉ with 2ᵉ ≤ max|vᵢ| < 2ᵉ⁺¹, then times 2ᵉ: no intermediate
/// over- or underflows (a NaN or ∞ entry gives itself).
fn scaled_norm<I: Iterator<Item = f64>>(values: impl Fn() -> I) -> f64 {
    let largest = values().fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    let exponent = largest.log2().floor() as i32;
    // Two steps: 2^±1074 alone is out of range.
    let (down_1, down_2) = (2f64.powi(-exponent / 2), 2f64.powi(-exponent + exponent / 2));
    let sum: f64 = values().map(|v| (v * down_1 * down_2).powi(2)).sum();
    sum.sqrt() / down_1 / down_2
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
