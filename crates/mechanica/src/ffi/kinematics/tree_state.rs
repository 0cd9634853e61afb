//! The state of a finalized kinematic tree (coordinates, velocities, accelerations, the motion
//! of its base) and the body poses, velocities and accelerations computed from it.

use super::tree::mech_tree_t;
use crate::ffi::boundary::boundary;
use crate::ffi::handle::Handle;
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Matrix3;
use mechanica_kinematics::rotation;
use mechanica_kinematics::tree::BaseState;

/// Sets the coordinates q and velocities q̇ (each `n` = dof doubles, SI units per joint type;
/// pass n = 0 and NULL for a tree without coordinates) of a finalized tree and computes all
/// body poses, velocities and Jacobian columns.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized; MECH_STATUS_BAD_DIMENSION
/// when n ≠ dof; MECH_STATUS_NON_FINITE for a NaN or infinite entry (the state is then left
/// unset, and queries fail until a valid state is set).
///
/// # Safety
/// `tree` must be a live handle; `q` and `q_dot` must point to `n` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_state(
    tree: *mut mech_tree_t,
    q: *const f64,
    q_dot: *const f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let (q, qd) = unsafe { (read_slice(q, n, "q")?, read_slice(q_dot, n, "q_dot")?) };
        let (kt, ws) = t.built()?;
        kt.update_positions(ws, q)?;
        kt.update_velocities(ws, qd)?;
        Ok(())
    })
}

/// The prescribed motion of a tree's base frame 0 at the current time, all in world
/// components, SI units: a moving (rheonomic) base makes the drag velocity of a point x equal
/// to v₀ + ω₀ × (x − p₀) and splits T = T₀ + T₁ + T₂ (9.7–9.10).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_base_state_t {
    /// Rotation R_W0 of the base frame (a rotation matrix, column-major).
    pub rotation: mech_mat3_t,
    /// Origin p_W0 of the base frame.
    pub position: mech_vec3_t,
    /// Angular velocity ω₀ of the base.
    pub omega: mech_vec3_t,
    /// Velocity v₀ of the base origin.
    pub velocity: mech_vec3_t,
    /// Angular acceleration ω̇₀ of the base.
    pub omega_dot: mech_vec3_t,
    /// Acceleration a₀ of the base origin.
    pub acceleration: mech_vec3_t,
}

/// Prescribes the motion of the base frame of a finalized tree (the default is a base at rest
/// with R_W0 = I, p_W0 = 0). It applies from the next mech_tree_set_state on: setting the base
/// discards the computed state, so queries fail with MECH_STATUS_INVALID_ARGUMENT until the
/// state is set again. Pass the same ω₀ and v₀ to mech_tree_energy_split for the drag field.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT
/// when `base->rotation` is not a rotation (orthonormal to rounding, determinant +1) or the tree
/// is not finalized. Nothing changes on error.
///
/// # Safety
/// `tree` must be a live handle; `base` must point to a readable mech_base_state_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_base(tree: *mut mech_tree_t, base: *const mech_base_state_t) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let b = unsafe { read(base, "base") }?;
        for (v, what) in [
            (&b.position, "base.position"),
            (&b.omega, "base.omega"),
            (&b.velocity, "base.velocity"),
            (&b.omega_dot, "base.omega_dot"),
            (&b.acceleration, "base.acceleration"),
        ] {
            finite(v, what)?;
        }
        finite(&b.rotation, "base.rotation")?;
        let rotation = rotation::rotation_from_matrix(&Matrix3::from(b.rotation))?;
        let (_, ws) = t.built()?;
        ws.set_base(BaseState {
            rotation,
            position: b.position.into(),
            omega: b.omega.into(),
            velocity: b.velocity.into(),
            omega_dot: b.omega_dot.into(),
            acceleration: b.acceleration.into(),
        })?;
        Ok(())
    })
}

/// Sets the accelerations q̈ (`n` = dof doubles) after mech_tree_set_state and computes the body
/// accelerations (including the base's, see mech_tree_set_base).
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized or no state is set;
/// MECH_STATUS_BAD_DIMENSION when n ≠ dof; MECH_STATUS_NON_FINITE for a NaN or infinite entry.
///
/// # Safety
/// `tree` must be a live handle; `q_ddot` must point to `n` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_set_accelerations(
    tree: *mut mech_tree_t,
    q_ddot: *const f64,
    n: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let qdd = unsafe { read_slice(q_ddot, n, "q_ddot") }?;
        let (kt, ws) = t.built()?;
        kt.update_accelerations(ws, qdd)?;
        Ok(())
    })
}

/// The pose of `body` at the state of the last mech_tree_set_state: its rotation R_WB
/// (column-major, body → world) into `rotation_out` and its origin position p_WB (m, world) into
/// `position_out`.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the tree is not finalized, no state is set or
/// `body` is out of range.
///
/// # Safety
/// `tree` must be a live handle; `rotation_out` and `position_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_pose(
    tree: *mut mech_tree_t,
    body: usize,
    rotation_out: *mut mech_mat3_t,
    position_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        let r_out = Out::new(rotation_out, "rotation_out")?;
        let p_out = Out::new(position_out, "position_out")?;
        let (_, ws) = t.built()?;
        let r = ws.rotation(body)?;
        let p = ws.position(body)?;
        // SAFETY: caller's contract.
        unsafe {
            r_out.write((*r.matrix()).into());
            p_out.write(p.into());
        }
        Ok(())
    })
}

/// The angular velocity of `body` (rad/s) into `omega_out` and the velocity (m/s) of its point
/// with body coordinates `point` (m) into `velocity_out`, both in world components, at the state
/// of the last mech_tree_set_state.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite `point`; MECH_STATUS_INVALID_ARGUMENT
/// when the tree is not finalized, no state is set or `body` is out of range.
///
/// # Safety
/// `tree` must be a live handle; `point` readable; `omega_out` and `velocity_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_velocity(
    tree: *mut mech_tree_t,
    body: usize,
    point: *const mech_vec3_t,
    omega_out: *mut mech_vec3_t,
    velocity_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let p = unsafe { read_vec3(point, "point") }?;
        let w_out = Out::new(omega_out, "omega_out")?;
        let v_out = Out::new(velocity_out, "velocity_out")?;
        let (_, ws) = t.built()?;
        let w = ws.angular_velocity(body)?;
        let v = ws.point_velocity(body, &p)?;
        // SAFETY: caller's contract.
        unsafe {
            w_out.write(w.into());
            v_out.write(v.into());
        }
        Ok(())
    })
}

/// The angular acceleration of `body` (rad/s²) into `omega_dot_out` and the acceleration (m/s²)
/// of its point with body coordinates `point` (m) into `acceleration_out`, both in world
/// components, after mech_tree_set_accelerations.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite `point`; MECH_STATUS_INVALID_ARGUMENT
/// when the tree is not finalized, the accelerations are not set or `body` is out of range.
///
/// # Safety
/// `tree` must be a live handle; `point` readable; both outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_tree_body_acceleration(
    tree: *mut mech_tree_t,
    body: usize,
    point: *const mech_vec3_t,
    omega_dot_out: *mut mech_vec3_t,
    acceleration_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let t = unsafe { mech_tree_t::borrow_mut(tree, "tree") }?;
        // SAFETY: caller's contract.
        let p = unsafe { read_vec3(point, "point") }?;
        let w_out = Out::new(omega_dot_out, "omega_dot_out")?;
        let a_out = Out::new(acceleration_out, "acceleration_out")?;
        let (_, ws) = t.built()?;
        let w = ws.angular_acceleration(body)?;
        let a = ws.point_acceleration(body, &p)?;
        // SAFETY: caller's contract.
        unsafe {
            w_out.write(w.into());
            a_out.write(a.into());
        }
        Ok(())
    })
}
