//! C entry points of the kinematics crate.

use super::boundary::{FfiError, boundary};
use super::status::*;
use super::types::*;
use super::validate::*;
use mechanica_kinematics::KinematicsError;
use mechanica_kinematics::nalgebra::Matrix3;
use mechanica_kinematics::rotation::{self, QuaternionNorm};

impl From<KinematicsError> for FfiError {
    fn from(error: KinematicsError) -> Self {
        let status = match error {
            KinematicsError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            KinematicsError::NotARotation { .. } | KinematicsError::NotAUnitQuaternion { .. } => {
                MECH_STATUS_INVALID_ARGUMENT
            }
        };
        FfiError::new(status, error.to_string())
    }
}

/// Converts a rotation matrix (column-major) into a unit quaternion.
///
/// Fails with MECH_STATUS_INVALID_ARGUMENT when `rotation` is not orthogonal with det = +1
/// within 1e-12 (‖RᵀR − I‖_F).
///
/// # Safety
/// `rotation` must point to a readable mech_mat3_t and `quaternion_out` to a writable mech_quat_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_quat_from_rotation_matrix(
    rotation: *const mech_mat3_t,
    quaternion_out: *mut mech_quat_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { read(rotation, "rotation") }?;
        let out = Out::new(quaternion_out, "quaternion_out")?;
        finite(&r, "rotation")?;
        let q = rotation::quaternion_from_matrix(&Matrix3::from(r))?;
        // SAFETY: caller's contract.
        unsafe { out.write(q.into()) };
        Ok(())
    })
}

/// The angular velocity ω (in the fixed frame) of a body with orientation R and rate Ṙ,
/// from Ω = Ṙ Rᵀ (syllabus 2.7–2.12). Both matrices are column-major.
///
/// # Safety
/// `rotation` and `rotation_rate` must point to readable mech_mat3_t values and `omega_out` to a
/// writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_angular_velocity_from_rate(
    rotation: *const mech_mat3_t,
    rotation_rate: *const mech_mat3_t,
    omega_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (r, r_dot) = unsafe { (read(rotation, "rotation")?, read(rotation_rate, "rotation_rate")?) };
        let out = Out::new(omega_out, "omega_out")?;
        finite(&r, "rotation")?;
        finite(&r_dot, "rotation_rate")?;
        let r = rotation::rotation_from_matrix(&Matrix3::from(r))?;
        let omega = rotation::angular_velocity_from_rate(&r, &Matrix3::from(r_dot))?;
        // SAFETY: caller's contract.
        unsafe { out.write(omega.into()) };
        Ok(())
    })
}

/// How mech_rotation_matrix_from_quat treats a quaternion that is not of unit length.
pub type mech_quat_norm_t = i32;
/// Accept only quaternions with |‖q‖ − 1| ≤ 1e-12; others give MECH_STATUS_INVALID_ARGUMENT.
pub const MECH_QUAT_REQUIRE_UNIT: mech_quat_norm_t = 0;
/// Normalise any non-zero quaternion first (zero gives MECH_STATUS_INVALID_ARGUMENT).
pub const MECH_QUAT_NORMALIZE: mech_quat_norm_t = 1;

impl CEnum for QuaternionNorm {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_QUAT_REQUIRE_UNIT => Some(QuaternionNorm::RequireUnit),
            MECH_QUAT_NORMALIZE => Some(QuaternionNorm::Normalize),
            _ => None,
        }
    }
}

/// The rotation matrix (column-major) of the quaternion `quaternion`, under the norm policy
/// `norm` (a mech_quat_norm_t value; unknown values give MECH_STATUS_BAD_ENUM).
///
/// # Safety
/// `quaternion` must point to a readable mech_quat_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_matrix_from_quat(
    quaternion: *const mech_quat_t,
    norm: mech_quat_norm_t,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let q = unsafe { read(quaternion, "quaternion") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let policy: QuaternionNorm = enum_value(norm, "norm")?;
        let unit = rotation::unit_quaternion(q.w, q.x, q.y, q.z, policy)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*unit.to_rotation_matrix().matrix()).into()) };
        Ok(())
    })
}
