//! Loads of a mechanism: uniform gravity, a rotating base frame, joint and point springs,
//! constant forces, and the joint limits of equilibrium searches.

use super::{mech_mechanism_t, mechanism_mut};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::status::*;
use crate::ffi::types::mech_vec3_t;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::{Unit, Vector3};
use mechanica_mechanism::potentials::{ConstantForce, JointSpring, PointSpring};
use mechanica_mechanism::{Anchor, RotatingFrame};

/// Sets uniform gravity g (m/s², base-frame components); it replaces any earlier value.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite component; MECH_STATUS_INVALID_ARGUMENT
/// when the base frame rotates (mech_mechanism_set_rotating_frame) about an axis that g is not
/// parallel to.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_gravity(
    mechanism: *mut mech_mechanism_t,
    gravity: mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.set_gravity(gravity.into())?;
        Ok(())
    })
}

/// Makes the base frame turn at `rate` rad/s about the unit `axis` (base-frame components)
/// through its origin, so that U* includes the centrifugal potential and the modes the
/// Coriolis coupling (§8e); rate 0 removes the rotation.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// an axis that is not a unit vector (|‖a‖ − 1| > 1e-9) or gravity that is not along the axis.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_rotating_frame(
    mechanism: *mut mech_mechanism_t,
    axis: mech_vec3_t,
    rate: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        let axis: Vector3<f64> = axis.into();
        finite(&rate, "rate")?;
        finite(axis.as_slice(), "axis")?;
        if (axis.norm() - 1.0).abs() > 1e-9 {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "axis must be a unit vector",
            ));
        }
        let frame = (rate != 0.0).then(|| RotatingFrame {
            axis: Unit::new_unchecked(axis),
            rate,
        });
        m.set_rotating_frame(frame)?;
        Ok(())
    })
}

/// Adds the potential U = ½ k (q_i − rest)² on coordinate i = `coordinate`, with stiffness k =
/// `stiffness` (N/m or N·m/rad per the coordinate) and rest value `rest`. Not allowed on the
/// rotation-vector coordinates of spherical and free joints.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a coordinate out of range or of a rotation vector, or a negative stiffness.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_joint_spring(
    mechanism: *mut mech_mechanism_t,
    coordinate: usize,
    stiffness: f64,
    rest: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(JointSpring {
            coordinate,
            stiffness,
            rest,
        })?;
        Ok(())
    })
}

/// The ground, as a body index for mech_mechanism_add_point_spring.
pub const MECH_GROUND: i64 = -1;

/// The anchor of a spring or damper end: MECH_GROUND or a body index (INVALID_ARGUMENT below
/// −1).
pub(crate) fn anchor(body: i64, point: mech_vec3_t) -> Result<Anchor, FfiError> {
    let body = match body {
        MECH_GROUND => None,
        b if b >= 0 => Some(b as usize),
        b => {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("body index {b} is negative"),
            ));
        }
    };
    Ok(Anchor {
        body,
        point: point.into(),
    })
}

/// Adds a spring U = ½ k (|x_a − x_b| − rest_length)² (k = `stiffness` in N/m, `rest_length`
/// in m) between the point `point_a` of body `body_a` and `point_b` of `body_b` (body
/// coordinates, m; MECH_GROUND and base-frame coordinates for the ground).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a body index below MECH_GROUND or out of range, a negative stiffness or rest length.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_point_spring(
    mechanism: *mut mech_mechanism_t,
    body_a: i64,
    point_a: mech_vec3_t,
    body_b: i64,
    point_b: mech_vec3_t,
    stiffness: f64,
    rest_length: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(PointSpring {
            a: anchor(body_a, point_a)?,
            b: anchor(body_b, point_b)?,
            stiffness,
            rest_length,
        })?;
        Ok(())
    })
}

/// Adds a constant force `force` (N, base-frame components) at the point `point` (m, body
/// coordinates) of body `body`: U = −F·x.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a body out of range.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_add_force(
    mechanism: *mut mech_mechanism_t,
    body: usize,
    point: mech_vec3_t,
    force: mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.add_potential(ConstantForce {
            body,
            point: point.into(),
            force: force.into(),
        })?;
        Ok(())
    })
}

/// Limits coordinate `coordinate` to [lower, upper] (infinite bounds allowed) in equilibrium
/// searches; the coordinates resting on a limit are counted in
/// mech_equilibrium_report_t::at_limit. Not allowed on the rotation-vector coordinates of
/// spherical and free joints.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for a coordinate out of range or of a rotation vector,
/// a NaN bound or lower > upper.
///
/// # Safety
/// `mechanism` must be a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_set_limits(
    mechanism: *mut mech_mechanism_t,
    coordinate: usize,
    lower: f64,
    upper: f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        m.set_limits(coordinate, lower, upper)?;
        Ok(())
    })
}
