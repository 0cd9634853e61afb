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
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
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

pub fn vec3(v: &nalgebra::Vector3<f64>) -> [Dd; 3] {
    [Dd::new(v.x), Dd::new(v.y), Dd::new(v.z)]
}

pub fn cross(a: &[Dd; 3], b: &[Dd; 3]) -> [Dd; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn normalize(a: &[Dd; 3]) -> [Dd; 3] {
    let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / norm, a[1] / norm, a[2] / norm]
}

/// The inverse of a 2×2 matrix by its adjugate.
pub fn inverse2(m: &[[Dd; 2]; 2]) -> [[Dd; 2]; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [[m[1][1] / det, -(m[0][1] / det)], [-(m[1][0] / det), m[0][0] / det]]
}

/// The inverse of a 3×3 matrix by its adjugate: exact to about 1e-32·κ relative.
pub fn inverse3(a: &Dd3) -> Dd3 {
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

/// The point mobility m⁻¹ I + [d]×ᵀ J⁻¹ [d]× of a free body of mass `m` and central inertia
/// `j` at the lever `d`, J⁻¹ by the adjugate: the exact W of the stored data to about 1e-32·κ.
pub fn point_mobility(m: f64, j: &nalgebra::Matrix3<f64>, d: &nalgebra::Vector3<f64>) -> Dd3 {
    let j_inv = inverse3(&mat(j));
    let dd = vec3(d);
    let z = Dd::ZERO;
    let k = [[z, -dd[2], dd[1]], [dd[2], z, -dd[0]], [-dd[1], dd[0], z]];
    let mut w = [[Dd::ZERO; 3]; 3];
    for i in 0..3 {
        for l in 0..3 {
            // ([d]ᵀ J⁻¹ [d])_il = Σ_ab k_ai J⁻¹_ab k_bl.
            let mut sum = Dd::ZERO;
            for a in 0..3 {
                for b in 0..3 {
                    sum = sum + k[a][i] * j_inv[a][b] * k[b][l];
                }
            }
            w[i][l] = sum;
        }
        w[i][i] = w[i][i] + Dd::new(1.0) / Dd::new(m);
    }
    w
}
