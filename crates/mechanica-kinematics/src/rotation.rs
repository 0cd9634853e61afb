//! Rotation matrices, quaternions and the angular velocity Ω = Ṙ Rᵀ (2.7–2.12).

use crate::KinematicsError;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Tolerance on ‖RᵀR − I‖_F for accepting a matrix as a rotation: a few hundred ulps,
/// enough for matrices that went through a handful of products, small enough to reject
/// anything that is visibly not orthogonal.
pub const ROTATION_TOLERANCE: f64 = 1e-12;

/// The skew-symmetric matrix Ω with Ω x = ω × x (2.11).
pub fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// Checks that `r` is finite and orthogonal with det = +1 (1.14) and returns it as a rotation.
pub fn rotation_from_matrix(r: &Matrix3<f64>) -> Result<Rotation3<f64>, KinematicsError> {
    if let Some(value) = r.iter().copied().find(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what: "rotation matrix entry",
            value,
        });
    }
    let orthogonality_error = (r.transpose() * r - Matrix3::identity()).norm();
    let determinant = r.determinant();
    if orthogonality_error > ROTATION_TOLERANCE || determinant <= 0.0 {
        return Err(KinematicsError::NotARotation {
            orthogonality_error,
            determinant,
        });
    }
    Ok(Rotation3::from_matrix_unchecked(*r))
}

/// The unit quaternion of a rotation matrix (checked as in [`rotation_from_matrix`]).
pub fn quaternion_from_matrix(r: &Matrix3<f64>) -> Result<UnitQuaternion<f64>, KinematicsError> {
    rotation_from_matrix(r).map(|rot| UnitQuaternion::from_rotation_matrix(&rot))
}

/// The angular velocity ω, expressed in the fixed frame, from R and Ṙ: Ω = Ṙ Rᵀ (2.7–2.12).
///
/// Ω is skew-symmetric for an exact rotation; the symmetric part that rounding leaves is
/// discarded by averaging the two off-diagonal entries.
pub fn angular_velocity_from_rate(r: &Rotation3<f64>, r_dot: &Matrix3<f64>) -> Result<Vector3<f64>, KinematicsError> {
    if let Some(value) = r_dot.iter().copied().find(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what: "rotation rate entry",
            value,
        });
    }
    let omega = r_dot * r.matrix().transpose();
    Ok(Vector3::new(
        0.5 * (omega[(2, 1)] - omega[(1, 2)]),
        0.5 * (omega[(0, 2)] - omega[(2, 0)]),
        0.5 * (omega[(1, 0)] - omega[(0, 1)]),
    ))
}

/// How a quaternion that is not exactly of unit length is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuaternionNorm {
    /// Accept only |‖q‖ − 1| ≤ [`ROTATION_TOLERANCE`]; anything else is an error.
    RequireUnit,
    /// Divide by ‖q‖ (any non-zero finite q), e.g. to repair drift after integration.
    Normalize,
}

/// The unit quaternion of `q = (w, x, y, z)` under the given norm policy.
pub fn unit_quaternion(
    w: f64,
    x: f64,
    y: f64,
    z: f64,
    policy: QuaternionNorm,
) -> Result<UnitQuaternion<f64>, KinematicsError> {
    if let Some(value) = [w, x, y, z].into_iter().find(|v| !v.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what: "quaternion component",
            value,
        });
    }
    let q = nalgebra::Quaternion::new(w, x, y, z);
    let norm = q.norm();
    let acceptable = match policy {
        QuaternionNorm::RequireUnit => (norm - 1.0).abs() <= ROTATION_TOLERANCE,
        QuaternionNorm::Normalize => norm > 0.0 && norm.is_finite(),
    };
    if !acceptable {
        return Err(KinematicsError::NotAUnitQuaternion { norm });
    }
    Ok(UnitQuaternion::new_normalize(q))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skew_is_the_cross_product() {
        let w = Vector3::new(0.3, -1.2, 2.5);
        let x = Vector3::new(-0.7, 0.4, 1.1);
        assert!((skew(&w) * x - w.cross(&x)).norm() < 1e-15);
    }

    #[test]
    fn angular_velocity_of_a_steady_spin_about_z() {
        // R(t) = Rz(w t); Ṙ = w Ω_z R, so ω = (0, 0, w).
        let w = 1.7;
        let t = 0.4;
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), w * t);
        let r_dot = skew(&Vector3::new(0.0, 0.0, w)) * r.matrix();
        let omega = angular_velocity_from_rate(&r, &r_dot).expect("finite input");
        assert!((omega - Vector3::new(0.0, 0.0, w)).norm() < 1e-15);
    }

    #[test]
    fn a_reflection_is_not_a_rotation() {
        let m = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        assert!(matches!(
            quaternion_from_matrix(&m),
            Err(KinematicsError::NotARotation { .. })
        ));
    }

    #[test]
    fn quaternion_norm_policies() {
        let half = std::f64::consts::FRAC_1_SQRT_2;
        let q = unit_quaternion(half, 0.0, 0.0, half, QuaternionNorm::RequireUnit).expect("unit");
        let r = q.to_rotation_matrix();
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        assert!(matches!(
            unit_quaternion(2.0, 0.0, 0.0, 0.0, QuaternionNorm::RequireUnit),
            Err(KinematicsError::NotAUnitQuaternion { .. })
        ));
        let q = unit_quaternion(2.0, 0.0, 0.0, 0.0, QuaternionNorm::Normalize).expect("normalizable");
        assert_eq!(q.w, 1.0);
        assert!(unit_quaternion(0.0, 0.0, 0.0, 0.0, QuaternionNorm::Normalize).is_err());
    }

    #[test]
    fn nan_is_rejected() {
        let mut m = Matrix3::identity();
        m[(1, 2)] = f64::NAN;
        assert!(matches!(
            rotation_from_matrix(&m),
            Err(KinematicsError::NonFinite { .. })
        ));
    }
}
