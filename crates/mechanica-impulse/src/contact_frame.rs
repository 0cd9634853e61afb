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
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// A 3×3 matrix as an unevaluated sum (hi, lo).
pub(crate) type FrameMatrix = (Matrix3<f64>, Matrix3<f64>);

/// A 3-vector as an unevaluated sum (hi, lo).
pub(crate) type FrameVector = (Vector3<f64>, Vector3<f64>);

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
    pub fn congruence(&self, w: &Matrix3<f64>) -> FrameMatrix {
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
    pub fn components(&self, u: &Vector3<f64>) -> FrameVector {
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

    /// The column i of R as a double-double vector.
    fn axis(&self, i: usize) -> [Dd; 3] {
        [0, 1, 2].map(|k| Dd::new(self.hi[(k, i)]).add(Dd::new(self.lo[(k, i)])))
    }

    /// One body's share of the contact in this frame, from its mobility G = `g` + `g_lo`
    /// (6×6, about its centre of mass), its velocity state `state` = (v₀, ω) and the lever
    /// d = p − x₀ = `lever` (hi, lo): W_ij = e_iᵀ G e_j and u_i = e_iᵀ state with
    /// e_i = (t_i, d × t_i), the velocity of the contact point along t_i per unit state (7.92).
    /// Every product is kept to about twice the working precision, so a body whose G is large
    /// along a direction in which the contact barely moves (a needle's spin) loses nothing to
    /// the rounding of W; returns ((W hi, W lo), (u hi, u lo)).
    pub fn body_terms(
        &self,
        (g, g_lo): (&Matrix6<f64>, &Matrix6<f64>),
        state: &Vector6<f64>,
        lever: (&Vector3<f64>, &Vector3<f64>),
    ) -> (FrameMatrix, FrameVector) {
        let rows = self.point_rows(lever);
        // G e_j, each entry hi + lo.
        let g_rows: Vec<[Dd; 6]> = rows
            .iter()
            .map(|e| {
                [0, 1, 2, 3, 4, 5].map(|a| {
                    let mut x = Vec::with_capacity(18);
                    let mut y = Vec::with_capacity(18);
                    for b in 0..6 {
                        x.extend_from_slice(&[g[(a, b)], g[(a, b)], g_lo[(a, b)]]);
                        y.extend_from_slice(&[e[b].hi, e[b].lo, e[b].hi]);
                    }
                    let (hi, lo) = dot2_split(&x, &y);
                    Dd { hi, lo }
                })
            })
            .collect();
        (gram(&rows, &g_rows), velocity(&rows, state))
    }

    /// [`ContactFrame::body_terms`] for a mobility given as G = Σ b_k b_kᵀ (a hinged body):
    /// W = S Sᵀ with S_ik = e_i·b_k, so that W has exactly the rank of the allowed motions
    /// (one for a revolute hinge) up to its last rounding, however small the contact's share.
    pub fn factored_body_terms(
        &self,
        factor: &[Vector6<f64>],
        state: &Vector6<f64>,
        lever: (&Vector3<f64>, &Vector3<f64>),
    ) -> (FrameMatrix, FrameVector) {
        let rows = self.point_rows(lever);
        let s: Vec<Vec<Dd>> = rows
            .iter()
            .map(|e| {
                factor
                    .iter()
                    .map(|b| {
                        let x: Vec<f64> = (0..6).flat_map(|a| [e[a].hi, e[a].lo]).collect();
                        let y: Vec<f64> = (0..6).flat_map(|a| [b[a], b[a]]).collect();
                        let (hi, lo) = dot2_split(&x, &y);
                        Dd { hi, lo }
                    })
                    .collect()
            })
            .collect();
        (
            symmetric_products(|i, j| (s[i].clone(), s[j].clone())),
            velocity(&rows, state),
        )
    }

    /// The rows e_i = (t_i, d × t_i) (i = 1, 2, 3) in double-double for the lever (hi, lo).
    fn point_rows(&self, lever: (&Vector3<f64>, &Vector3<f64>)) -> Vec<[Dd; 6]> {
        let d = [0, 1, 2].map(|k| Dd::new(lever.0[k]).add(Dd::new(lever.1[k])));
        (0..3)
            .map(|i| {
                let t = self.axis(i);
                let m = cross(&d, &t);
                [t[0], t[1], t[2], m[0], m[1], m[2]]
            })
            .collect()
    }
}

/// W_ij = e_i·(G e_j) as (hi, lo) from the rows e and the products G e (double-double).
fn gram(rows: &[[Dd; 6]], g_rows: &[[Dd; 6]]) -> FrameMatrix {
    symmetric_products(|i, j| (rows[i].to_vec(), g_rows[j].to_vec()))
}

/// The symmetric 3×3 matrix with entries a·b for (a, b) = `pair(i, j)` (double-double
/// vectors), each entry as (hi, lo) in compensated arithmetic.
fn symmetric_products(pair: impl Fn(usize, usize) -> (Vec<Dd>, Vec<Dd>)) -> FrameMatrix {
    let (mut w, mut w_lo) = (Matrix3::zeros(), Matrix3::zeros());
    for i in 0..3 {
        for j in i..3 {
            let (a, b) = pair(i, j);
            let x: Vec<f64> = a.iter().flat_map(|v| [v.hi, v.hi, v.lo]).collect();
            let y: Vec<f64> = b.iter().flat_map(|v| [v.hi, v.lo, v.hi]).collect();
            let (h, l) = dot2_split(&x, &y);
            (w[(i, j)], w[(j, i)], w_lo[(i, j)], w_lo[(j, i)]) = (h, h, l, l);
        }
    }
    (w, w_lo)
}

/// u_i = e_i·state as (hi, lo).
fn velocity(rows: &[[Dd; 6]], state: &Vector6<f64>) -> FrameVector {
    let (mut u, mut u_lo) = (Vector3::zeros(), Vector3::zeros());
    for i in 0..3 {
        let e = &rows[i];
        let x: Vec<f64> = (0..6).flat_map(|a| [e[a].hi, e[a].lo]).collect();
        let y: Vec<f64> = (0..6).flat_map(|a| [state[a], state[a]]).collect();
        (u[i], u_lo[i]) = dot2_split(&x, &y);
    }
    (u, u_lo)
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
