//! Compensated (error-free-transformation) sums and dot products.
//!
//! `dot2` is the Ogita–Rump–Oishi "Dot2" algorithm: the products and the running sum are
//! split exactly into a double and its rounding error (TwoProduct by fused multiply-add,
//! TwoSum), and the errors are summed alongside. The result is as accurate as if the dot
//! product were computed in twice the working precision and then rounded:
//! |dot2(x, y) − x·y| ≤ u·|x·y| + γ²_{2n}·Σ|xᵢ yᵢ|, u = 2⁻⁵³, γ_k = k u/(1 − k u).
//! The impact process evaluates contact velocities u = u⁻ + W P and the normal rate
//! b = (W d)_n with it, because both cancel heavily when W has a large entry along a
//! direction in which the impulse barely moves (a needle's spin about its own axis).

use nalgebra::{Matrix3, Vector3};

/// The unit roundoff u = 2⁻⁵³ of binary64.
pub(crate) const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// a + b = s + e exactly (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let v = s - a;
    (s, (a - (s - v)) + (b - v))
}

/// a·b = p + e exactly (TwoProduct with a fused multiply-add).
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// The dot product Σ xᵢ yᵢ of two equally long slices, computed as if in double the working
/// precision (Dot2).
pub(crate) fn dot2(x: &[f64], y: &[f64]) -> f64 {
    let (hi, lo) = dot2_split(x, y);
    hi + lo
}

/// [`dot2`] kept unrounded as hi + lo (|lo| ≤ ½ ulp(hi)): equal to Σ xᵢ yᵢ up to
/// γ²_{2n}·Σ|xᵢ yᵢ|.
pub(crate) fn dot2_split(x: &[f64], y: &[f64]) -> (f64, f64) {
    debug_assert_eq!(x.len(), y.len());
    let (mut sum, mut error) = (0.0, 0.0);
    for (&a, &b) in x.iter().zip(y) {
        let (p, e_p) = two_product(a, b);
        let (s, e_s) = two_sum(sum, p);
        sum = s;
        error += e_p + e_s;
    }
    two_sum(sum, error)
}

/// The congruence Rᵀ W R as an unevaluated sum hi + lo of two symmetric matrices: each entry
/// Σ_kl R_ki W_kl R_lj is summed in compensated arithmetic from the exact splits of the
/// products R_ki W_kl, so that hi + lo is exact up to about u²·Σ|terms| however much the terms
/// cancel (a large W seen along a direction in which it is small). Rounding it to one double
/// per entry would perturb a block of condition κ by κ·u; the impact process keeps both parts.
pub(crate) fn congruence(r: &Matrix3<f64>, w: &Matrix3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let entry = |i: usize, j: usize| {
        let (mut x, mut y) = ([0.0; 18], [0.0; 18]);
        for k in 0..3 {
            for l in 0..3 {
                let (p, e) = two_product(r[(k, i)], w[(k, l)]);
                let slot = 2 * (3 * k + l);
                x[slot] = p;
                x[slot + 1] = e;
                y[slot] = r[(l, j)];
                y[slot + 1] = r[(l, j)];
            }
        }
        dot2_split(&x, &y)
    };
    let (mut hi, mut lo) = (Matrix3::zeros(), Matrix3::zeros());
    for i in 0..3 {
        for j in i..3 {
            let (h, l) = entry(i, j);
            (hi[(i, j)], hi[(j, i)], lo[(i, j)], lo[(j, i)]) = (h, h, l, l);
        }
    }
    (hi, lo)
}

/// The matrix–vector product M x as hi + lo, each component in compensated arithmetic.
pub(crate) fn mul_vec(m: &Matrix3<f64>, x: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let (mut hi, mut lo) = (Vector3::zeros(), Vector3::zeros());
    for i in 0..3 {
        (hi[i], lo[i]) = dot2_split(&[m[(i, 0)], m[(i, 1)], m[(i, 2)]], x.as_slice());
    }
    (hi, lo)
}

/// Σ |xᵢ yᵢ|: the magnitude against which the rounding of a plain dot product is measured.
pub(crate) fn abs_dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| (a * b).abs()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot2_recovers_what_plain_summation_cancels() {
        // 1e16 + 1 − 1e16: the plain sum loses the 1, Dot2 keeps it exactly.
        let x = [1e16, 1.0, -1e16];
        let y = [1.0, 1.0, 1.0];
        let plain: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert_eq!(plain, 0.0);
        assert_eq!(dot2(&x, &y), 1.0);
        // Products whose rounding errors carry the result: (1 + 2⁻³⁰)² − 1 − 2⁻²⁹ = 2⁻⁶⁰.
        let a = 1.0 + 2f64.powi(-30);
        assert_eq!(dot2(&[a, -1.0, -2f64.powi(-29)], &[a, 1.0, 1.0]), 2f64.powi(-60));
        assert_eq!(abs_dot(&x, &y), 2e16 + 1.0);
    }

    #[test]
    fn the_congruence_keeps_the_small_entries_of_a_large_rank_one_term() {
        // W = 1e12 a aᵀ + I with a ⟂ e₃ of R = I: the (2, 2) entry is exactly 1, which a plain
        // product R ᵀ W R also gets; rotate by a quarter turn about e₃ (exact) so that the
        // entries mix, and compare with the exact rotated matrix.
        let a = Vector3::new(0.6, 0.8, 0.0);
        let w = a * a.transpose() * 1e12 + Matrix3::identity();
        let r = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let exact = Matrix3::new(w[(1, 1)], -w[(1, 0)], 0.0, -w[(0, 1)], w[(0, 0)], 0.0, 0.0, 0.0, 1.0);
        assert_eq!(congruence(&r, &w), (exact, Matrix3::zeros()));
        assert_eq!(mul_vec(&w, &Vector3::z()), (Vector3::z(), Vector3::zeros()));
    }
}
