//! 3-D values at the C boundary: conversions between the C structs of [`super::types`] and
//! nalgebra, and the checked readers of 3-D inputs (finite vectors, angle triples, rotation
//! matrices) shared by every capability module.

use super::boundary::FfiError;
use super::status::MECH_STATUS_NULL_POINTER;
use super::types::*;
use super::validate::{finite, read, read_slice};
use mechanica_kinematics::nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};
use mechanica_kinematics::rotation;

impl From<mech_vec3_t> for Vector3<f64> {
    fn from(v: mech_vec3_t) -> Self {
        Vector3::new(v.x, v.y, v.z)
    }
}
impl From<Vector3<f64>> for mech_vec3_t {
    fn from(v: Vector3<f64>) -> Self {
        mech_vec3_t { x: v.x, y: v.y, z: v.z }
    }
}
impl From<mech_mat3_t> for Matrix3<f64> {
    fn from(m: mech_mat3_t) -> Self {
        Matrix3::from_column_slice(&m.m)
    }
}
impl From<Matrix3<f64>> for mech_mat3_t {
    fn from(m: Matrix3<f64>) -> Self {
        let mut out = mech_mat3_t::default();
        out.m.copy_from_slice(m.as_slice());
        out
    }
}
impl From<mech_quat_t> for Quaternion<f64> {
    fn from(q: mech_quat_t) -> Self {
        Quaternion::new(q.w, q.x, q.y, q.z)
    }
}
impl From<UnitQuaternion<f64>> for mech_quat_t {
    fn from(q: UnitQuaternion<f64>) -> Self {
        mech_quat_t {
            w: q.w,
            x: q.i,
            y: q.j,
            z: q.k,
        }
    }
}

/// Reads a required 3-vector: NULL_POINTER, MISALIGNED_POINTER or NON_FINITE (naming `what`)
/// unless it is a readable vector of finite numbers.
///
/// # Safety
/// A non-NULL, aligned `ptr` must point to a readable mech_vec3_t.
pub(crate) unsafe fn read_vec3(ptr: *const mech_vec3_t, what: &str) -> Result<Vector3<f64>, FfiError> {
    // SAFETY: caller's contract.
    let v = unsafe { read(ptr, what) }?;
    finite(&v, what)?;
    Ok(v.into())
}

/// Reads three finite doubles (Euler angles or their rates).
///
/// # Safety
/// A non-NULL, aligned `ptr` must point to 3 readable doubles.
pub(crate) unsafe fn read_triple(ptr: *const f64, what: &str) -> Result<[f64; 3], FfiError> {
    if ptr.is_null() {
        return Err(FfiError::new(MECH_STATUS_NULL_POINTER, format!("{what} is NULL")));
    }
    // SAFETY: non-NULL; 3 readable doubles by the caller's contract.
    let s = unsafe { read_slice(ptr, 3, what) }?;
    finite(s, what)?;
    Ok([s[0], s[1], s[2]])
}

/// Reads a rotation matrix argument: finite (NON_FINITE), orthogonal with det = +1 within
/// 1e-12 (INVALID_ARGUMENT otherwise).
///
/// # Safety
/// A non-NULL, aligned `ptr` must point to a readable mech_mat3_t.
pub(crate) unsafe fn read_rotation(ptr: *const mech_mat3_t, what: &str) -> Result<Rotation3<f64>, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    finite(&m, what)?;
    Ok(rotation::rotation_from_matrix(&Matrix3::from(m))?)
}
