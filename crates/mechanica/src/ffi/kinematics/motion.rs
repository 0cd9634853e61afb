//! Rigid motion x = R X + c of a body and the motion of a point relative to a moving frame:
//! velocity and acceleration fields, and the drag / Coriolis / relative decomposition.

use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_kinematics::nalgebra::Matrix3;
use mechanica_kinematics::relative_motion::{self, RelativeMotion};
use mechanica_kinematics::rigid_motion::RigidMotion;
use mechanica_kinematics::rotation;

/// The state of a rigid motion x = R X + c (syllabus 1.5) at one instant, all in fixed (world)
/// components, SI units.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_rigid_motion_t {
    /// Orientation R (body → world), column-major; must be a rotation.
    pub rotation: mech_mat3_t,
    /// Position c of the reference point.
    pub c: mech_vec3_t,
    /// Velocity ċ of the reference point.
    pub c_dot: mech_vec3_t,
    /// Acceleration c̈ of the reference point.
    pub c_ddot: mech_vec3_t,
    /// Angular velocity ω.
    pub omega: mech_vec3_t,
    /// Angular acceleration ω̇.
    pub omega_dot: mech_vec3_t,
}

/// Reads and validates a rigid motion: every entry finite (NON_FINITE) and a rotation within
/// ‖RᵀR − I‖_F ≤ 1e-12 (INVALID_ARGUMENT).
///
/// # Safety
/// A non-NULL, aligned `ptr` must point to a readable mech_rigid_motion_t.
unsafe fn read_motion(ptr: *const mech_rigid_motion_t, what: &str) -> Result<RigidMotion, FfiError> {
    // SAFETY: caller's contract.
    let m = unsafe { read(ptr, what) }?;
    finite(&m.rotation, "motion rotation")?;
    let rotation = rotation::rotation_from_matrix(&Matrix3::from(m.rotation))?;
    for (v, name) in [
        (&m.c, "motion c"),
        (&m.c_dot, "motion c_dot"),
        (&m.c_ddot, "motion c_ddot"),
        (&m.omega, "motion omega"),
        (&m.omega_dot, "motion omega_dot"),
    ] {
        finite(v, name)?;
    }
    Ok(RigidMotion::new(
        rotation,
        m.c.into(),
        m.c_dot.into(),
        m.c_ddot.into(),
        m.omega.into(),
        m.omega_dot.into(),
    )?)
}

/// The velocity v = ω × (x − c) + ċ (m/s, syllabus 2.13) of the body point at world position
/// `x` (m) in the rigid motion `motion`, written to `velocity_out` (world components).
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input or a velocity that overflows;
/// MECH_STATUS_INVALID_ARGUMENT when `motion->rotation` is not a rotation within
/// ‖RᵀR − I‖_F ≤ 1e-12.
///
/// # Safety
/// `motion` must point to a readable mech_rigid_motion_t, `x` to a readable mech_vec3_t and
/// `velocity_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_velocity_field(
    motion: *const mech_rigid_motion_t,
    x: *const mech_vec3_t,
    velocity_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, x) = unsafe { (read_motion(motion, "motion")?, read_vec3(x, "x")?) };
        let out = Out::new(velocity_out, "velocity_out")?;
        let v = m.velocity_at(&x);
        finite(&[v.x, v.y, v.z][..], "velocity (overflow)")?;
        // SAFETY: caller's contract.
        unsafe { out.write(v.into()) };
        Ok(())
    })
}

/// The acceleration a = ω̇ × (x − c) + ω × (ω × (x − c)) + c̈ (m/s², syllabus 2.18) of the body
/// point at world position `x` (m) in the rigid motion `motion`, written to `acceleration_out`
/// (world components).
///
/// Errors: as mech_velocity_field (for an acceleration that overflows).
///
/// # Safety
/// `motion` must point to a readable mech_rigid_motion_t, `x` to a readable mech_vec3_t and
/// `acceleration_out` to a writable mech_vec3_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_acceleration_field(
    motion: *const mech_rigid_motion_t,
    x: *const mech_vec3_t,
    acceleration_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, x) = unsafe { (read_motion(motion, "motion")?, read_vec3(x, "x")?) };
        let out = Out::new(acceleration_out, "acceleration_out")?;
        let a = m.acceleration_at(&x);
        finite(&[a.x, a.y, a.z][..], "acceleration (overflow)")?;
        // SAFETY: caller's contract.
        unsafe { out.write(a.into()) };
        Ok(())
    })
}

/// A point's absolute motion decomposed relative to a moving frame (world components, SI units,
/// syllabus 2.22–2.32): v = v_drag + v_rel, a = a_drag + a_coriolis + a_rel.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_relative_decomposition_t {
    /// Position x = R ξ + c.
    pub position: mech_vec3_t,
    /// Drag velocity ω × (x − c) + ċ.
    pub v_drag: mech_vec3_t,
    /// Relative velocity R ξ̇.
    pub v_rel: mech_vec3_t,
    /// Drag acceleration ω̇ × (x − c) + ω × (ω × (x − c)) + c̈.
    pub a_drag: mech_vec3_t,
    /// Coriolis acceleration 2 ω × v_rel.
    pub a_coriolis: mech_vec3_t,
    /// Relative acceleration R ξ̈.
    pub a_rel: mech_vec3_t,
}

/// Decomposes the motion of a point with relative position, velocity and acceleration `xi`,
/// `xi_dot`, `xi_ddot` (moving-frame components, SI units) in the moving frame `frame` into drag,
/// Coriolis and relative parts (syllabus 2.22–2.32), written to `decomposition_out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT when
/// `frame->rotation` is not a rotation within ‖RᵀR − I‖_F ≤ 1e-12.
///
/// # Safety
/// `frame` must point to a readable mech_rigid_motion_t, `xi`, `xi_dot`, `xi_ddot` to readable
/// mech_vec3_t values and `decomposition_out` to a writable mech_relative_decomposition_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_relative_motion_decompose(
    frame: *const mech_rigid_motion_t,
    xi: *const mech_vec3_t,
    xi_dot: *const mech_vec3_t,
    xi_ddot: *const mech_vec3_t,
    decomposition_out: *mut mech_relative_decomposition_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (m, rel) = unsafe {
            (
                read_motion(frame, "frame")?,
                RelativeMotion {
                    xi: read_vec3(xi, "xi")?,
                    xi_dot: read_vec3(xi_dot, "xi_dot")?,
                    xi_ddot: read_vec3(xi_ddot, "xi_ddot")?,
                },
            )
        };
        let out = Out::new(decomposition_out, "decomposition_out")?;
        let d = relative_motion::decompose(&m, &rel)?;
        let value = mech_relative_decomposition_t {
            position: d.position.into(),
            v_drag: d.v_drag.into(),
            v_rel: d.v_rel.into(),
            a_drag: d.a_drag.into(),
            a_coriolis: d.a_coriolis.into(),
            a_rel: d.a_rel.into(),
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> mech_vec3_t {
        mech_vec3_t { x, y, z }
    }

    #[test]
    fn a_velocity_or_acceleration_that_overflows_is_an_error_and_writes_nothing() {
        // ω × (x − c) with |ω| = |x − c| = 1e200 is 1e400: finite inputs, no finite result.
        let motion = mech_rigid_motion_t {
            rotation: mech_mat3_t {
                m: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            },
            c: v(0.0, 0.0, 0.0),
            c_dot: v(0.0, 0.0, 0.0),
            c_ddot: v(0.0, 0.0, 0.0),
            omega: v(0.0, 0.0, 1e200),
            omega_dot: v(0.0, 0.0, 0.0),
        };
        let x = v(1e200, 0.0, 0.0);
        let sentinel = v(7.0, 7.0, 7.0);
        let (mut velocity, mut acceleration) = (sentinel, sentinel);
        // SAFETY: all pointers are to live locals.
        let (s1, s2) = unsafe {
            (
                mech_velocity_field(&motion, &x, &mut velocity),
                mech_acceleration_field(&motion, &x, &mut acceleration),
            )
        };
        assert_eq!((s1, s2), (MECH_STATUS_NON_FINITE, MECH_STATUS_NON_FINITE));
        assert_eq!((velocity, acceleration), (sentinel, sentinel));
        // With |ω| = 1e100 the velocity ω × x = (0, 1e300, 0) is finite and is written.
        let slow = mech_rigid_motion_t {
            omega: v(0.0, 0.0, 1e100),
            ..motion
        };
        // SAFETY: as above.
        let s = unsafe { mech_velocity_field(&slow, &x, &mut velocity) };
        assert_eq!(s, MECH_STATUS_OK);
        assert_eq!(velocity.y, 1e300);
    }
}
