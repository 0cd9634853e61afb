//! Rotations: conversions between rotation matrices, unit quaternions, rotation vectors and
//! axis–angle pairs, angular velocity from Ṙ, and the repair of a drifted rotation matrix.

use crate::ffi::boundary::boundary;
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::spatial::{read_rotation, read_vec3};
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Matrix3;
use mechanica_kinematics::rotation::{self, QuaternionNorm};

/// Converts the rotation matrix `rotation` (column-major, R maps body to fixed components) into
/// the unit quaternion of the same rotation, written to `quaternion_out` with w ≥ 0 (Shepperd's
/// method: accurate to a few ulps for every rotation, half turns included).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT
/// when `rotation` is not orthogonal with det = +1 within ‖RᵀR − I‖_F ≤ 1e-12.
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

/// The angular velocity ω (rad/s, fixed-frame components) of a body with orientation R =
/// `rotation` and rate Ṙ = `rotation_rate` (1/s), from the skew matrix Ω = Ṙ Rᵀ (syllabus
/// 2.7–2.12), written to `omega_out`. Both matrices are column-major. The symmetric part that
/// rounding leaves in Ṙ Rᵀ is discarded by averaging the two off-diagonal entries.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT
/// when `rotation` is not a rotation within ‖RᵀR − I‖_F ≤ 1e-12; MECH_STATUS_OUT_OF_RANGE when
/// ω overflows.
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

c_enum!(QuaternionNorm,
    MECH_QUAT_REQUIRE_UNIT => QuaternionNorm::RequireUnit,
    MECH_QUAT_NORMALIZE => QuaternionNorm::Normalize,
);

/// The rotation matrix R = (w² − v·v) I + 2 v vᵀ + 2 w [v]× (column-major) of the quaternion
/// `quaternion` = (w, v), under the norm policy `norm` (a mech_quat_norm_t), written to
/// `rotation_out`.
///
/// Errors: MECH_STATUS_BAD_ENUM for an unknown `norm`; MECH_STATUS_NON_FINITE for a NaN or
/// infinite component; MECH_STATUS_INVALID_ARGUMENT for a quaternion the policy refuses
/// (non-unit under MECH_QUAT_REQUIRE_UNIT, zero under MECH_QUAT_NORMALIZE).
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

/// The rotation matrix exp([φ]×) (column-major) of the rotation vector φ = `rotation_vector`
/// (rad; the rotation by |φ| about φ/|φ|), by Rodrigues' formula, written to `rotation_out`.
/// |φ| is computed on φ scaled by a power of two (no overflow or underflow). Exact to rounding
/// for every |φ| up to 2⁵³ rad, including |φ| → 0 and |φ| ≥ π.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite component; MECH_STATUS_INVALID_ARGUMENT
/// for |φ| > 2⁵³ rad (9.0e15), where one rounding of |φ| exceeds a radian and the rotation is
/// not determined by φ.
///
/// # Safety
/// `rotation_vector` must point to a readable mech_vec3_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_exp(
    rotation_vector: *const mech_vec3_t,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let phi = unsafe { read_vec3(rotation_vector, "rotation_vector") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let r = rotation::exp_map(&phi)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*r.matrix()).into()) };
        Ok(())
    })
}

/// The rotation vector φ (rad, |φ| ≤ π) with exp([φ]×) = `rotation` (column-major): the
/// logarithm map, written to `rotation_vector_out`. Accurate to a few ulps of |φ| near the
/// identity and near half turns; at exactly |φ| = π either sign is valid and one is returned.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT
/// when `rotation` is not a rotation within ‖RᵀR − I‖_F ≤ 1e-12.
///
/// # Safety
/// `rotation` must point to a readable mech_mat3_t and `rotation_vector_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_log(
    rotation: *const mech_mat3_t,
    rotation_vector_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { read_rotation(rotation, "rotation") }?;
        let out = Out::new(rotation_vector_out, "rotation_vector_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write(rotation::log_map(&r).into()) };
        Ok(())
    })
}

/// The rotation matrix (column-major) of the rotation by `angle` (rad, right-handed) about the
/// unit vector `axis`, written to `rotation_out`. Every finite angle is reduced modulo 2π
/// exactly: the result is the rotation by the angle the double holds (beyond 2⁵³ rad adjacent
/// doubles are more than a radian apart, so only an exactly known angle is meaningful there).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT
/// for a zero or non-unit axis (|‖a‖ − 1| > 1e-12).
///
/// # Safety
/// `axis` must point to a readable mech_vec3_t and `rotation_out` to a writable mech_mat3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_from_axis_angle(
    axis: *const mech_vec3_t,
    angle: f64,
    rotation_out: *mut mech_mat3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let a = unsafe { read_vec3(axis, "axis") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        finite(&angle, "angle")?;
        let r = rotation::rotation_from_axis_angle(&a, angle)?;
        // SAFETY: caller's contract.
        unsafe { out.write((*r.matrix()).into()) };
        Ok(())
    })
}

/// The rotation nearest in the Frobenius norm to a drifted matrix `matrix` (column-major): its
/// orthogonal polar factor U Vᵀ from the SVD matrix = U Σ Vᵀ, written to `rotation_out`;
/// `correction_out` receives the size of the repair ‖matrix − rotation‖_F.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT for
/// det(matrix) ≤ 0 (a reflection or a singular matrix is not a drifted rotation);
/// MECH_STATUS_OUT_OF_RANGE when the correction exceeds the largest double.
///
/// # Safety
/// `matrix` must point to a readable mech_mat3_t, `rotation_out` to a writable mech_mat3_t and
/// `correction_out` to a writable double.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_rotation_orthonormalize(
    matrix: *const mech_mat3_t,
    rotation_out: *mut mech_mat3_t,
    correction_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { read(matrix, "matrix") }?;
        let out = Out::new(rotation_out, "rotation_out")?;
        let corr = Out::new(correction_out, "correction_out")?;
        finite(&m, "matrix")?;
        let fixed = rotation::orthonormalize_matrix(&Matrix3::from(m))?;
        // SAFETY: caller's contract.
        unsafe {
            out.write((*fixed.rotation.matrix()).into());
            corr.write(fixed.correction);
        }
        Ok(())
    })
}
