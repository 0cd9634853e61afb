//! Principal moments and a canonical right-handed principal frame (3.20–3.21).
//!
//! Repeated moments leave the eigenvectors undetermined; instead of returning whatever an
//! eigen-solver produced, this module picks a canonical frame:
//! - three equal moments (sphere, cube): the identity frame;
//! - two equal moments (a symmetric top): the symmetry axis u is taken from the rank-one
//!   matrix J − I_pair·I = (I_u − I_pair) u uᵀ, and the other two axes from the coordinate axis
//!   least aligned with u, projected onto the plane ⟂ u;
//! - distinct moments: the eigenvectors, each with its largest component made positive.

use crate::MassError;
use crate::MassProperties;
use crate::error::{check_all_finite, check_result};
use crate::validity::{InertiaIssue, ValidityTolerance, symmetric_part};
use mechanica_kinematics::scaling::power_of_two_above;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Default relative tolerance (to the largest |moment|) below which two moments count as equal.
pub const DEFAULT_REPEATED_TOLERANCE: f64 = 1e-10;

/// How many principal moments coincide.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Multiplicity {
    /// Three distinct moments: the frame is unique up to the sign convention.
    Distinct,
    /// The two smallest moments are equal (an oblate top, e.g. a disc).
    SmallestPair,
    /// The two largest moments are equal (a prolate top, e.g. a rod or long cylinder).
    LargestPair,
    /// All three moments are equal (sphere, cube): the identity frame is returned.
    Triple,
}

/// Principal moments and axes of an inertia tensor J expressed in a frame F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrincipalAxes {
    /// Principal moments I₁ ≤ I₂ ≤ I₃ (3.20), kg·m².
    pub moments: Vector3<f64>,
    /// R_FP: its columns are the principal axes, expressed in F, in the order of `moments`,
    /// forming a right-handed frame, so that J = R diag(moments) Rᵀ.
    pub r_fp: Rotation3<f64>,
    /// Which moments were treated as repeated.
    pub multiplicity: Multiplicity,
    /// The accuracy of the result: ‖Rᵀ J R − diag(moments)‖_F / ‖J‖_F (0 for J = 0).
    pub relative_residual: f64,
}

/// Makes the component of largest magnitude positive (the first one on ties).
fn canonical_sign(v: Vector3<f64>) -> Vector3<f64> {
    let k = v.iamax();
    if v[k] < 0.0 { -v } else { v }
}

/// Principal axes of `j` with [`DEFAULT_REPEATED_TOLERANCE`] (see
/// [`principal_axes_with_tolerance`]).
pub fn principal_axes(j: &Matrix3<f64>) -> Result<PrincipalAxes, MassError> {
    principal_axes_with_tolerance(j, DEFAULT_REPEATED_TOLERANCE)
}

/// Principal axes of the tensor `j`; moments closer than `relative_tolerance` × the largest
/// |moment| are treated as equal (see the module documentation).
///
/// `j` must be symmetric within the validity tolerance, |J_ij − J_ji| ≤ 1e-9·Σ|J_kk|
/// ([`ValidityTolerance::default`]); its symmetric part is decomposed. The decomposition runs
/// on J/2^k, 2^k the power of two above its largest entry, and the moments are scaled back, so
/// every finite tensor works whose moments are representable.
///
/// Errors: [`MassError::NonFinite`] for a NaN or infinite entry; [`MassError::InvalidInertia`]
/// with [`InertiaIssue::NotSymmetric`] for a tensor outside the symmetry tolerance;
/// [`MassError::NonFiniteResult`] when a moment exceeds f64::MAX.
pub fn principal_axes_with_tolerance(j: &Matrix3<f64>, relative_tolerance: f64) -> Result<PrincipalAxes, MassError> {
    check_all_finite(j.iter(), "inertia tensor")?;
    require_symmetric(j)?;
    let scale = power_of_two_above(j.amax());
    let scaled = j / scale;
    let mut axes = scaled_principal_axes(&symmetric_part(&scaled), relative_tolerance);
    axes.moments *= scale;
    check_result(axes.moments.iter(), "principal moments")?;
    Ok(axes)
}

/// Fails with [`InertiaIssue::NotSymmetric`] (the largest difference) when the finite tensor
/// `j` is not symmetric within the validity tolerance, |J_ij − J_ji| ≤ 1e-9·Σ|J_kk|
/// ([`ValidityTolerance::default`]); the test runs on J/2^k, so it never overflows.
pub fn require_symmetric(j: &Matrix3<f64>) -> Result<(), MassError> {
    let scale = power_of_two_above(j.amax());
    check_symmetry(&(j / scale), scale)
}

/// Fails with [`InertiaIssue::NotSymmetric`] (the largest difference, in the units of the
/// unscaled tensor) when the scaled tensor `j` is not symmetric within the validity tolerance.
fn check_symmetry(j: &Matrix3<f64>, scale: f64) -> Result<(), MassError> {
    let tolerance = ValidityTolerance::default().relative * (0..3).map(|i| j[(i, i)].abs()).sum::<f64>();
    let mut worst: Option<(usize, usize, f64)> = None;
    for (row, col) in [(0, 1), (0, 2), (1, 2)] {
        let difference = j[(row, col)] - j[(col, row)];
        if difference.abs() > tolerance && worst.is_none_or(|w| difference.abs() > w.2.abs()) {
            worst = Some((row, col, difference));
        }
    }
    match worst {
        Some((row, col, difference)) => Err(MassError::InvalidInertia(vec![InertiaIssue::NotSymmetric {
            row,
            col,
            difference: difference * scale,
        }])),
        None => Ok(()),
    }
}

/// The principal axes of a symmetric tensor with entries of order one.
fn scaled_principal_axes(j: &Matrix3<f64>, relative_tolerance: f64) -> PrincipalAxes {
    let eig = crate::validity::symmetric_eigen(j);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let l = Vector3::new(
        eig.eigenvalues[order[0]],
        eig.eigenvalues[order[1]],
        eig.eigenvalues[order[2]],
    );
    let tol = relative_tolerance.max(0.0) * l[0].abs().max(l[2].abs());
    let (low_pair, high_pair) = (l[1] - l[0] <= tol, l[2] - l[1] <= tol);
    let (multiplicity, columns) = if low_pair && high_pair {
        (Multiplicity::Triple, [Vector3::x(), Vector3::y(), Vector3::z()])
    } else if low_pair || high_pair {
        symmetric_top_frame(j, &l, low_pair)
    } else {
        let a = canonical_sign(eig.eigenvectors.column(order[0]).into_owned());
        let b = canonical_sign(eig.eigenvectors.column(order[1]).into_owned());
        // Re-orthogonalise b against a before completing the right-handed frame.
        let b = (b - a * a.dot(&b)).normalize();
        (Multiplicity::Distinct, [a, b, a.cross(&b)])
    };
    let r = Matrix3::from_columns(&columns);
    let d = r.transpose() * j * r;
    let moments = rayleigh_moments(&d, multiplicity);
    let norm = j.norm();
    let relative_residual = if norm > 0.0 {
        (d - Matrix3::from_diagonal(&moments)).norm() / norm
    } else {
        0.0
    };
    PrincipalAxes {
        moments,
        r_fp: Rotation3::from_matrix_unchecked(r),
        multiplicity,
        relative_residual,
    }
}

/// The frame of a symmetric top with sorted eigenvalues `l`: the symmetry axis u from the
/// rank-one J − I_pair·I, the others from the coordinate axis least aligned with u.
fn symmetric_top_frame(j: &Matrix3<f64>, l: &Vector3<f64>, low_pair: bool) -> (Multiplicity, [Vector3<f64>; 3]) {
    let (pair_value, multiplicity) = if low_pair {
        (0.5 * (l[0] + l[1]), Multiplicity::SmallestPair)
    } else {
        (0.5 * (l[1] + l[2]), Multiplicity::LargestPair)
    };
    let m = j - Matrix3::identity() * pair_value;
    let (mut best, mut best_norm) = (0, -1.0);
    for c in 0..3 {
        let n = m.column(c).norm_squared();
        if n > best_norm {
            best = c;
            best_norm = n;
        }
    }
    let u = canonical_sign(m.column(best).normalize());
    let k = u.iamin();
    let e_k = Vector3::ith(k, 1.0);
    let v = (e_k - u * u[k]).normalize();
    let w = u.cross(&v);
    if low_pair {
        (multiplicity, [v, w, u])
    } else {
        (multiplicity, [u, v, w])
    }
}

/// The moments as the Rayleigh quotients on the diagonal of `d` = Rᵀ J R, made equal within
/// a repeated pair or triple.
fn rayleigh_moments(d: &Matrix3<f64>, multiplicity: Multiplicity) -> Vector3<f64> {
    let mut moments = Vector3::new(d[(0, 0)], d[(1, 1)], d[(2, 2)]);
    match multiplicity {
        Multiplicity::Triple => {
            // The median of the three Rayleigh quotients: exact for an exactly isotropic tensor.
            let mut m = [moments[0], moments[1], moments[2]];
            m.sort_by(f64::total_cmp);
            moments = Vector3::repeat(m[1]);
        }
        Multiplicity::SmallestPair => {
            let p = 0.5 * (moments[0] + moments[1]);
            moments[0] = p;
            moments[1] = p;
        }
        Multiplicity::LargestPair => {
            let p = 0.5 * (moments[1] + moments[2]);
            moments[1] = p;
            moments[2] = p;
        }
        Multiplicity::Distinct => {}
    }
    moments
}

impl MassProperties {
    /// Principal moments and the canonical principal frame of the central inertia tensor
    /// (3.20–3.21), see [`principal_axes`].
    pub fn principal_axes(&self) -> Result<PrincipalAxes, MassError> {
        principal_axes(&self.inertia_c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;
    use proptest::prelude::*;

    fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::new(a, b, c))
    }

    fn is_right_handed_orthonormal(r: &Matrix3<f64>) -> bool {
        (r.transpose() * r - Matrix3::identity()).norm() <= 1e-14 && (r.determinant() - 1.0).abs() <= 1e-14
    }

    #[test]
    fn sphere_and_cube_give_the_identity_frame() {
        let p = principal_axes(&diag(0.4, 0.4, 0.4)).expect("finite");
        assert_eq!(p.multiplicity, Multiplicity::Triple);
        assert_eq!(*p.r_fp.matrix(), Matrix3::identity());
        assert_eq!(p.moments, Vector3::repeat(0.4));
        // A cube's tensor rotated arbitrarily is still a multiple of the identity up to rounding.
        let q = UnitQuaternion::from_euler_angles(0.7, 0.2, -1.3);
        let r = q.to_rotation_matrix();
        let j = r.matrix() * diag(1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0) * r.matrix().transpose();
        let p = principal_axes(&j).expect("finite");
        assert_eq!(p.multiplicity, Multiplicity::Triple);
        assert_eq!(*p.r_fp.matrix(), Matrix3::identity());
    }

    #[test]
    fn symmetric_top_gives_its_symmetry_axis() {
        // Disc-like (oblate): the symmetry axis has the largest moment and is the third column.
        let q = UnitQuaternion::from_euler_angles(0.3, -0.9, 2.1);
        let r = q.to_rotation_matrix();
        let axis = r.matrix().column(2).into_owned();
        let j = r.matrix() * diag(1.0, 1.0, 2.0) * r.matrix().transpose();
        let p = principal_axes(&j).expect("finite");
        assert_eq!(p.multiplicity, Multiplicity::SmallestPair);
        let got = p.r_fp.matrix().column(2).into_owned();
        assert!(
            (got - canonical_sign(axis)).norm() <= 4.0 * f64::EPSILON,
            "{got} vs {axis}"
        );
        assert!(is_right_handed_orthonormal(p.r_fp.matrix()));
        // Unrotated: the frame is exactly the identity.
        let p = principal_axes(&diag(1.0, 1.0, 2.0)).expect("finite");
        assert_eq!(*p.r_fp.matrix(), Matrix3::identity());
        // Prolate (rod along y): the symmetry axis is the first column.
        let p = principal_axes(&diag(1.0, 0.0, 1.0)).expect("finite");
        assert_eq!(p.multiplicity, Multiplicity::LargestPair);
        assert_eq!(p.r_fp.matrix().column(0).into_owned(), Vector3::y());
        assert_eq!(p.moments, Vector3::new(0.0, 1.0, 1.0));
    }

    proptest! {
        #[test]
        fn random_tensors_are_diagonalised_by_a_sorted_right_handed_frame(
            a in 0.1f64..10.0, b in 0.1f64..10.0, c in 0.1f64..10.0,
            r1 in -3.0f64..3.0, r2 in -1.5f64..1.5, r3 in -3.0f64..3.0,
        ) {
            let r = UnitQuaternion::from_euler_angles(r1, r2, r3).to_rotation_matrix();
            let j = r.matrix() * diag(a, b, c) * r.matrix().transpose();
            let p = principal_axes(&j).expect("finite");
            prop_assert!(is_right_handed_orthonormal(p.r_fp.matrix()));
            prop_assert!(p.moments[0] <= p.moments[1] && p.moments[1] <= p.moments[2]);
            let mut expected = [a, b, c];
            expected.sort_by(f64::total_cmp);
            for k in 0..3 {
                prop_assert!((p.moments[k] - expected[k]).abs() <= 1e-13 * c.max(a).max(b));
            }
            let rebuilt = p.r_fp.matrix() * Matrix3::from_diagonal(&p.moments) * p.r_fp.matrix().transpose();
            // The residual reported is an honest measure of the reconstruction error.
            prop_assert!((rebuilt - j).norm() <= 2.0 * p.relative_residual * j.norm() + 1e-14 * j.norm());
            prop_assert!(p.relative_residual <= 1e-12);
        }
    }
}
