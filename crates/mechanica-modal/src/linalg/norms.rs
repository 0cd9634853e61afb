//! Euclidean and Frobenius norms in one pass over the data, with a scaled fallback where the
//! sum of squares over- or underflows.

use faer::MatRef;

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
pub(crate) fn vector_norm(v: faer::ColRef<'_, f64>) -> f64 {
    let sum = sum_of_squares(v);
    if sum.is_finite() && sum > 1e-280 {
        sum.sqrt()
    } else {
        v.norm_l2()
    }
}
