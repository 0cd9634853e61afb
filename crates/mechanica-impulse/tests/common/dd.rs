//! Double-double arithmetic (about 32 significant digits) for independent references.
#![allow(dead_code)]

use std::ops::{Add, Div, Mul, Neg, Sub};

/// An unevaluated sum hi + lo with |lo| ≤ ½ ulp(hi).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let v = s - a;
    (s, (a - (s - v)) + (b - v))
}

fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };
    pub fn new(x: f64) -> Self {
        Dd { hi: x, lo: 0.0 }
    }
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
    pub fn abs(self) -> Self {
        if self.hi < 0.0 { -self } else { self }
    }
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Dd::ZERO;
        }
        let x = self.hi.sqrt();
        // One Newton step in double-double: x + (a − x²)/(2x).
        let r = self - Dd::new(x) * Dd::new(x);
        Dd::new(x) + r / Dd::new(2.0 * x)
    }
}

impl From<f64> for Dd {
    fn from(x: f64) -> Self {
        Dd::new(x)
    }
}

impl Add for Dd {
    type Output = Dd;
    fn add(self, o: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, o.hi);
        let (t, f) = two_sum(self.lo, o.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}

impl Neg for Dd {
    type Output = Dd;
    fn neg(self) -> Dd {
        Dd { hi: -self.hi, lo: -self.lo }
    }
}

impl Sub for Dd {
    type Output = Dd;
    fn sub(self, o: Dd) -> Dd {
        self + (-o)
    }
}

impl Mul for Dd {
    type Output = Dd;
    fn mul(self, o: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, o.hi);
        let e = e + (self.hi * o.lo + self.lo * o.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

impl Div for Dd {
    type Output = Dd;
    fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        let r = self - o * Dd::new(q1);
        let q2 = r.hi / o.hi;
        let r = r - o * Dd::new(q2);
        let q3 = r.hi / o.hi;
        let (hi, lo) = quick_two_sum(q1, q2);
        Dd { hi, lo } + Dd::new(q3)
    }
}

/// A 3×3 matrix in double-double, row-major.
pub type Dd3 = [[Dd; 3]; 3];

pub fn mat(m: &nalgebra::Matrix3<f64>) -> Dd3 {
    let mut r = [[Dd::ZERO; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = Dd::new(m[(i, j)]);
        }
    }
    r
}

pub fn mul(a: &Dd3, b: &Dd3) -> Dd3 {
    let mut r = [[Dd::ZERO; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                r[i][j] = r[i][j] + a[i][k] * b[k][j];
            }
        }
    }
    r
}

pub fn mul_vec(a: &Dd3, x: &[Dd; 3]) -> [Dd; 3] {
    let mut r = [Dd::ZERO; 3];
    for i in 0..3 {
        for k in 0..3 {
            r[i] = r[i] + a[i][k] * x[k];
        }
    }
    r
}

/// The inverse by the adjugate: exact to about 1e-32·κ relative.
pub fn inverse(a: &Dd3) -> Dd3 {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]
    };
    let det = a[0][0] * c(0, 0) + a[0][1] * c(0, 1) + a[0][2] * c(0, 2);
    let mut r = [[Dd::ZERO; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[j][i] = c(i, j) / det;
        }
    }
    r
}

/// [d]×, the cross-product matrix.
pub fn cross_matrix(d: &[Dd; 3]) -> Dd3 {
    let z = Dd::ZERO;
    [[z, -d[2], d[1]], [d[2], z, -d[0]], [-d[1], d[0], z]]
}

pub fn vec(v: &nalgebra::Vector3<f64>) -> [Dd; 3] {
    [Dd::new(v.x), Dd::new(v.y), Dd::new(v.z)]
}
