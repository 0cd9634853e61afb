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

/// The matrix–vector product M x as hi + lo, each component in compensated arithmetic.
pub(crate) fn mul_vec(m: &Matrix3<f64>, x: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let (mut hi, mut lo) = (Vector3::zeros(), Vector3::zeros());
    for i in 0..3 {
        (hi[i], lo[i]) = dot2_split(&[m[(i, 0)], m[(i, 1)], m[(i, 2)]], x.as_slice());
    }
    (hi, lo)
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
    fn the_compensated_product_keeps_what_the_rows_cancel() {
        // Row 0: 1e16 + 1 − 1e16 = 1; row 1: 0.1 + 0.2 − 0.3 = 2⁻⁵⁵ exactly for these doubles
        // (plain summation gives 2⁻⁵⁴).
        let m = Matrix3::new(1e16, 1.0, -1e16, 0.1, 0.2, -0.3, 0.0, 0.0, 1.0);
        let (hi, lo) = mul_vec(&m, &Vector3::new(1.0, 1.0, 1.0));
        assert_eq!(hi + lo, Vector3::new(1.0, 2f64.powi(-55), 1.0));
    }
}
