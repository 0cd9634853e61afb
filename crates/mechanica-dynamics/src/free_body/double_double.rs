//! Unevaluated sums hi + lo of two f64 ("double-double", about 106 significant bits), enough
//! to carry the quarter period K and π through argument reductions of |u| up to ~1e15 without
//! losing the low bits. The error-free transformations are Knuth's two-sum and the
//! fused-multiply-add product.

/// hi + lo with |lo| ≤ ulp(hi)/2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DoubleDouble {
    pub hi: f64,
    pub lo: f64,
}

/// π to 106 bits.
pub(crate) const PI: DoubleDouble = DoubleDouble {
    hi: std::f64::consts::PI,
    lo: 1.224_646_799_147_353_2e-16,
};

/// s + e = a + b exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// p + e = a·b exactly.
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl DoubleDouble {
    pub(crate) const fn from_f64(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }

    fn normalized(hi: f64, lo: f64) -> Self {
        let (hi, lo) = two_sum(hi, lo);
        Self { hi, lo }
    }

    /// a + b for two f64, exactly.
    pub(crate) fn sum(a: f64, b: f64) -> Self {
        let (hi, lo) = two_sum(a, b);
        Self { hi, lo }
    }

    /// a·b for two f64, exactly.
    pub(crate) fn product(a: f64, b: f64) -> Self {
        let (hi, lo) = two_prod(a, b);
        Self { hi, lo }
    }

    pub(crate) fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    pub(crate) fn add(self, other: Self) -> Self {
        let (s, e) = two_sum(self.hi, other.hi);
        Self::normalized(s, e + self.lo + other.lo)
    }

    pub(crate) fn sub(self, other: Self) -> Self {
        self.add(other.neg())
    }

    pub(crate) fn mul(self, other: Self) -> Self {
        let (p, e) = two_prod(self.hi, other.hi);
        Self::normalized(p, e + self.hi * other.lo + self.lo * other.hi)
    }

    pub(crate) fn scale(self, factor: f64) -> Self {
        let (p, e) = two_prod(self.hi, factor);
        Self::normalized(p, e + self.lo * factor)
    }

    pub(crate) fn div(self, other: Self) -> Self {
        let q = self.hi / other.hi;
        let remainder = self.sub(other.scale(q));
        Self::normalized(q, remainder.hi / other.hi)
    }

    /// √self for self ≥ 0 (one Newton correction of the f64 root).
    pub(crate) fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Self::from_f64(0.0);
        }
        let s = self.hi.sqrt();
        let (p, e) = two_prod(s, s);
        let residual = (self.hi - p) - e + self.lo;
        Self::normalized(s, residual / (2.0 * s))
    }
}

/// sin w and cos w in double-double for |w| ≤ 1, by their Taylor series (terms below 1e-34).
pub(crate) fn sin_cos(w: DoubleDouble) -> (DoubleDouble, DoubleDouble) {
    let w2 = w.mul(w).neg();
    let series = |first: DoubleDouble, start: f64| {
        let (mut term, mut sum, mut n) = (first, first, start);
        while term.hi.abs() > 1e-34 * sum.hi.abs().max(f64::MIN_POSITIVE) {
            term = term.mul(w2).div(DoubleDouble::from_f64((n + 1.0) * (n + 2.0)));
            sum = sum.add(term);
            n += 2.0;
        }
        sum
    };
    (series(w, 1.0), series(DoubleDouble::from_f64(1.0), 0.0))
}
