//! The 6×6 algebra of the articulated-body recursion, in world components about a body's
//! origin, ordered (angular, linear) for motions and (moment, force) for wrenches, so that a
//! motion and a wrench pair to a power by the plain dot product (7.44).

use crate::spatial::{WorldInertia, Wrench};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// The skew matrix \[r\]× with \[r\]× x = r × x.
pub(crate) fn skew(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// The rigid-body inertia about o: (ω̇, a_o) ↦ (M_o, F) with M_o = J_o ω̇ + m c × a_o and
/// F = m (a_o + ω̇ × c): blocks \[\[J_C − m\[c\]×², m\[c\]×\], \[−m\[c\]×, m I\]\] (Steiner (3.27)).
pub(crate) fn body_inertia(body: &WorldInertia) -> Matrix6<f64> {
    let k = skew(&body.c) * body.mass;
    let p = body.inertia_c - skew(&body.c) * k;
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&p);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&k);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-k));
    out.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * body.mass));
    out
}

/// The inertia `i` about a child's origin seen from its parent's origin, the child lying at
/// r = o_child − o_parent: Xᵀ I X with X = \[\[1, 0\], \[−\[r\]×, 1\]\] the motion shift.
pub(crate) fn shifted_inertia(i: &Matrix6<f64>, r: &Vector3<f64>) -> Matrix6<f64> {
    let k = skew(r);
    let p = i.fixed_view::<3, 3>(0, 0).into_owned();
    let q = i.fixed_view::<3, 3>(0, 3).into_owned();
    let rr = i.fixed_view::<3, 3>(3, 3).into_owned();
    let kr = k * rr;
    let top_right = q + kr;
    let top_left = p - q * k + k * q.transpose() - kr * k;
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&top_left);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&top_right);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&top_right.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&rr);
    out
}

/// A wrench as (moment, force).
pub(crate) fn wrench_vector(w: &Wrench) -> Vector6<f64> {
    Vector6::new(w.moment.x, w.moment.y, w.moment.z, w.force.x, w.force.y, w.force.z)
}

/// A wrench vector about the child's origin moved to the parent's origin (7.29).
pub(crate) fn shifted_wrench(w: &Vector6<f64>, r: &Vector3<f64>) -> Vector6<f64> {
    let f = Vector3::new(w[3], w[4], w[5]);
    let m = Vector3::new(w[0], w[1], w[2]) + r.cross(&f);
    Vector6::new(m.x, m.y, m.z, f.x, f.y, f.z)
}

/// A motion (ω̇, a) at the parent's origin moved to the child's origin: (ω̇, a + ω̇ × r).
pub(crate) fn shifted_motion(a: &Vector6<f64>, r: &Vector3<f64>) -> Vector6<f64> {
    let wd = Vector3::new(a[0], a[1], a[2]);
    let lin = Vector3::new(a[3], a[4], a[5]) + wd.cross(r);
    Vector6::new(wd.x, wd.y, wd.z, lin.x, lin.y, lin.z)
}

/// A motion column (w, v) as a 6-vector.
pub(crate) fn motion_vector(w: &Vector3<f64>, v: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
}

/// The inverse of the symmetric positive definite top-left `dim`×`dim` block of `d` by
/// Cholesky, in the same block of the result. Fails with (pivot, scale) when a pivot is not
/// above 8u times `scale`, the magnitude the block's entries were computed from (below it the
/// block is singular to working precision), or the largest diagonal entry if that is larger.
pub(crate) fn invert_spd_block(d: &Matrix6<f64>, dim: usize, scale: f64) -> Result<Matrix6<f64>, (f64, f64)> {
    let scale = (0..dim).map(|i| d[(i, i)].abs()).fold(scale, f64::max);
    let mut l = Matrix6::zeros();
    for j in 0..dim {
        let mut pivot = d[(j, j)];
        for k in 0..j {
            pivot -= l[(j, k)] * l[(j, k)];
        }
        if !pivot.is_finite() || pivot <= 8.0 * f64::EPSILON * scale {
            return Err((pivot, scale));
        }
        let root = pivot.sqrt();
        l[(j, j)] = root;
        for i in j + 1..dim {
            let mut s = d[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = s / root;
        }
    }
    // Columns of L⁻¹ by forward substitution, then (L⁻¹)ᵀ L⁻¹.
    let mut l_inv = Matrix6::zeros();
    for c in 0..dim {
        for i in c..dim {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for k in c..i {
                s -= l[(i, k)] * l_inv[(k, c)];
            }
            l_inv[(i, c)] = s / l[(i, i)];
        }
    }
    let mut out = Matrix6::zeros();
    for a in 0..dim {
        for b in 0..dim {
            out[(a, b)] = (a.max(b)..dim).map(|k| l_inv[(k, a)] * l_inv[(k, b)]).sum();
        }
    }
    Ok(out)
}
