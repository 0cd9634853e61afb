//! The contact frame (t₁, t₂, n̂) of a normal n, and W and u⁻ expressed in it, all to about
//! twice the working precision.
//!
//! n̂ = n/|n|, t₁ = (n̂ × e_k)/|n̂ × e_k| with e_k the coordinate axis least aligned with n, and
//! t₂ = n̂ × t₁, each entry kept as hi + lo. A frame rounded to one double per entry is
//! orthonormal and perpendicular to n only to rounding: its n̂ is a normal tilted by about u,
//! and for a body whose mobility is large in one direction (a needle spinning about its axis)
//! that tilt moves the impulse by κ·u. In the double-double frame, Rᵀ W R and Rᵀ u⁻ are the
//! exact components for the given normal up to u² terms.

use crate::compensated::{Dd, dot2_split, two_product};
use nalgebra::{Matrix3, Vector3};

/// The frame R = (t₁, t₂, n̂) as hi + lo (columns).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ContactFrame {
    /// The rounded frame.
    pub hi: Matrix3<f64>,
    /// The remainder: R = hi + lo to about 1e-32.
    pub lo: Matrix3<f64>,
}

/// The unit vector v/|v| of a double-double vector.
fn normalize(v: [Dd; 3]) -> [Dd; 3] {
    let norm = v[0].mul(v[0]).add(v[1].mul(v[1])).add(v[2].mul(v[2])).sqrt();
    v.map(|x| x.div(norm))
}

/// a × b in double-double.
fn cross(a: &[Dd; 3], b: &[Dd; 3]) -> [Dd; 3] {
    let term = |i: usize, j: usize| a[i].mul(b[j]).add(a[j].mul(b[i]).neg());
    [term(1, 2), term(2, 0), term(0, 1)]
}

impl ContactFrame {
    /// The frame of the (non-zero) normal `n`.
    pub fn new(n: &Vector3<f64>) -> Self {
        let n_hat = normalize([Dd::new(n.x), Dd::new(n.y), Dd::new(n.z)]);
        let k = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
            0
        } else if n.y.abs() <= n.z.abs() {
            1
        } else {
            2
        };
        let mut axis = [Dd::new(0.0); 3];
        axis[k] = Dd::new(1.0);
        let t1 = normalize(cross(&n_hat, &axis));
        let t2 = cross(&n_hat, &t1);
        let high = |v: &[Dd; 3]| Vector3::new(v[0].hi, v[1].hi, v[2].hi);
        let low = |v: &[Dd; 3]| Vector3::new(v[0].lo, v[1].lo, v[2].lo);
        Self {
            hi: Matrix3::from_columns(&[high(&t1), high(&t2), high(&n_hat)]),
            lo: Matrix3::from_columns(&[low(&t1), low(&t2), low(&n_hat)]),
        }
    }

    /// Rᵀ W R as hi + lo (symmetric parts): each entry Σ_kl R_ki W_kl R_lj summed in compensated
    /// arithmetic, the products of the high parts split exactly, the low parts to first order,
    /// so that it is exact up to about u²·Σ|terms| however much the terms cancel.
    pub fn congruence(&self, w: &Matrix3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
        let (r, r_lo) = (&self.hi, &self.lo);
        let entry = |i: usize, j: usize| {
            let (mut x, mut y) = ([0.0; 36], [0.0; 36]);
            for k in 0..3 {
                for l in 0..3 {
                    let (p, e) = two_product(r[(k, i)], w[(k, l)]);
                    let slot = 4 * (3 * k + l);
                    x[slot..slot + 4].copy_from_slice(&[p, e, r_lo[(k, i)] * w[(k, l)], p]);
                    y[slot..slot + 4].copy_from_slice(&[r[(l, j)], r[(l, j)], r[(l, j)], r_lo[(l, j)]]);
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

    /// Rᵀ u as hi + lo.
    pub fn components(&self, u: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let (mut hi, mut lo) = (Vector3::zeros(), Vector3::zeros());
        for i in 0..3 {
            let (r, r_lo) = (self.hi.column(i), self.lo.column(i));
            (hi[i], lo[i]) = dot2_split(
                &[r[0], r[1], r[2], r_lo[0], r_lo[1], r_lo[2]],
                &[u.x, u.y, u.z, u.x, u.y, u.z],
            );
        }
        (hi, lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_orthonormal_and_normal_beyond_one_rounding() {
        // (R_hi + R_lo)ᵀ (R_hi + R_lo) = I and (t_i)·n = 0 to about 1e-31, checked by
        // compensated products of the parts.
        for n in [
            Vector3::new(-2.0, -3.0, -6.0) / 7.0,
            Vector3::new(0.3, 0.1, -0.9).normalize(),
            Vector3::new(1.0, 1e-9, 0.0).normalize(),
        ] {
            let frame = ContactFrame::new(&n);
            let (r, lo) = (frame.hi, frame.lo);
            for i in 0..3 {
                for j in 0..3 {
                    let (a, a_lo, b, b_lo) = (r.column(i), lo.column(i), r.column(j), lo.column(j));
                    let (h, l) = dot2_split(
                        &[a[0], a[1], a[2], a_lo[0], a_lo[1], a_lo[2], a[0], a[1], a[2]],
                        &[b[0], b[1], b[2], b[0], b[1], b[2], b_lo[0], b_lo[1], b_lo[2]],
                    );
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((h - expected + l).abs() <= 1e-30, "{n}: ({i}, {j})");
                }
            }
            // t₁, t₂ ⟂ n (the normal as given, not normalised).
            for i in 0..2 {
                let (h, l) = frame.components(&n);
                assert!((h[i] + l[i]).abs() <= 1e-30, "{n}: t{i}·n");
            }
        }
    }
}
