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

use nalgebra::Matrix3;

/// The unit roundoff u = 2⁻⁵³ of binary64.
pub(crate) const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// a + b = s + e exactly (Knuth's TwoSum).
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let v = s - a;
    (s, (a - (s - v)) + (b - v))
}

/// a·b = p + e exactly (TwoProduct with a fused multiply-add).
pub(crate) fn two_product(a: f64, b: f64) -> (f64, f64) {
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

/// A double-double number hi + lo (|lo| ≤ ½ ulp(hi)), about 32 significant digits: just the
/// operations the exact contact frame needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

impl Dd {
    /// The double `x`.
    pub fn new(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }

    fn normalized(hi: f64, lo: f64) -> Self {
        let (hi, lo) = two_sum(hi, lo);
        Self { hi, lo }
    }

    /// self + other.
    pub fn add(self, other: Self) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        Self::normalized(s, e + self.lo + other.lo)
    }

    /// self·other.
    pub fn mul(self, other: Self) -> Self {
        let (p, e) = two_product(self.hi, other.hi);
        Self::normalized(p, e + self.hi * other.lo + self.lo * other.hi)
    }

    /// −self.
    pub fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    /// self/other (other ≠ 0), by one correction of the quotient of the high parts.
    pub fn div(self, other: Self) -> Self {
        let q = self.hi / other.hi;
        let r = self.add(other.mul(Self::new(q)).neg());
        Self::normalized(q, (r.hi + r.lo) / other.hi)
    }

    /// √self (self ≥ 0), by one Newton correction of the square root of the high part.
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Self::new(0.0);
        }
        let r = self.hi.sqrt();
        let (p, e) = two_product(r, r);
        Self::normalized(r, ((self.hi - p) - e + self.lo) / (2.0 * r))
    }
}

/// The inverse of a 3×3 matrix by its adjugate in double-double, as hi + lo: accurate to
/// about 1e-32·κ(m) relative, so beyond one rounding for κ up to 1e15. `None` when the
/// determinant is zero.
pub(crate) fn inverse3(m: &Matrix3<f64>) -> Option<(Matrix3<f64>, Matrix3<f64>)> {
    let x = |i: usize, j: usize| Dd::new(m[(i, j)]);
    let cofactor = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        x(i1, j1).mul(x(i2, j2)).add(x(i1, j2).mul(x(i2, j1)).neg())
    };
    let det = (0..3).fold(Dd::new(0.0), |acc, k| acc.add(x(0, k).mul(cofactor(0, k))));
    if det.hi == 0.0 || !det.hi.is_finite() {
        return None;
    }
    let (mut hi, mut lo) = (Matrix3::zeros(), Matrix3::zeros());
    for i in 0..3 {
        for j in 0..3 {
            let entry = cofactor(j, i).div(det);
            (hi[(i, j)], lo[(i, j)]) = (entry.hi, entry.lo);
        }
    }
    Some((hi, lo))
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
    fn double_double_keeps_what_one_double_rounds_away() {
        // (1 + 2⁻⁶⁰)·3 / 3 = 1 + 2⁻⁶⁰, and √((1 + 2⁻³⁰)²) = 1 + 2⁻³⁰, both beyond one double.
        let x = Dd::new(1.0).add(Dd::new(2f64.powi(-60)));
        let y = x.mul(Dd::new(3.0)).div(Dd::new(3.0));
        assert_eq!((y.hi, y.lo), (1.0, 2f64.powi(-60)));
        let a = Dd::new(1.0 + 2f64.powi(-30));
        let root = a.mul(a).sqrt();
        assert_eq!((root.hi, root.lo), (1.0 + 2f64.powi(-30), 0.0));
    }

    #[test]
    fn the_double_double_inverse_is_exact_beyond_one_rounding() {
        // M = diag(1e-9, 3, 7): (hi + lo)·d = 1 to about 1e-32 on the diagonal of M⁻¹, and the
        // off-diagonal entries vanish.
        let m = Matrix3::new(1e-9, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 7.0);
        let (hi, lo) = inverse3(&m).expect("invertible");
        assert_eq!(hi - Matrix3::from_diagonal(&hi.diagonal()), Matrix3::zeros());
        for (k, d) in [1e-9f64, 3.0, 7.0].into_iter().enumerate() {
            let (p, e) = two_product(hi[(k, k)], d);
            assert!((p - 1.0 + e + lo[(k, k)] * d).abs() <= 1e-30);
        }
        assert!(inverse3(&Matrix3::zeros()).is_none());
    }

    #[test]
    fn the_compensated_product_keeps_what_the_rows_cancel() {
        // 1e16 + 1 − 1e16 = 1 and 0.1 + 0.2 − 0.3 = 2⁻⁵⁵ exactly for these doubles (plain
        // summation gives 0 and 2⁻⁵⁴), each as hi + lo.
        assert_eq!(dot2_split(&[1e16, 1.0, -1e16], &[1.0; 3]), (1.0, 0.0));
        let (hi, lo) = dot2_split(&[0.1, 0.2, -0.3], &[1.0; 3]);
        assert_eq!(hi + lo, 2f64.powi(-55));
    }
}
