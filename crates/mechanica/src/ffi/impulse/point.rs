//! Impulses on point masses and collisions of two point masses.

use crate::ffi::boundary::boundary;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_impulse::point::{collide_collinear, collide_points, impulse_on_point};

/// The outcome of a collinear collision of two point masses (syllabus 5.16–5.23).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_collinear_impact_t {
    /// Velocity of point 1 after the impact (m/s).
    pub v1_after: f64,
    /// Velocity of point 2 after the impact (m/s).
    pub v2_after: f64,
    /// Impulse on point 2 (N·s); point 1 receives its negative.
    pub impulse_on_2: f64,
    /// Kinetic-energy change T⁺ − T⁻ (J), ≤ 0 for restitution ≤ 1 (5.23).
    pub energy_change: f64,
}

/// Collides point 1 (mass `m1` in kg, velocity `v1` in m/s) with point 2 (`m2`, `v2`) on one
/// line with Newton's restitution coefficient `restitution` ∈ [0, 1] (5.16–5.23), writing the
/// velocities after, the impulse and the energy change to `out`. Points that do not approach
/// (v1 ≤ v2) receive no impulse.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0 or a restitution outside [0, 1].
///
/// # Safety
/// `out` must point to a writable mech_collinear_impact_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_collide_collinear(
    m1: f64,
    v1: f64,
    m2: f64,
    v2: f64,
    restitution: f64,
    out: *mut mech_collinear_impact_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(out, "out")?;
        let r = collide_collinear(m1, v1, m2, v2, restitution)?;
        let value = mech_collinear_impact_t {
            v1_after: r.v1_after,
            v2_after: r.v2_after,
            impulse_on_2: r.impulse_on_2,
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The response of a point mass to an impulse (5.13, 7.106).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_point_impulse_t {
    /// Velocity just after, V = v + S/m (m/s).
    pub velocity_after: mech_vec3_t,
    /// ΔT = ½ S·(V + v) (J).
    pub energy_change: f64,
}

/// Applies the impulse `impulse` (N·s) to a point of mass `mass` (kg) moving at `velocity`
/// (m/s), all vectors in one frame (5.10–5.15): the momentum jumps by the impulse; the position
/// does not change. Writes the velocity after and the energy change to `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0.
///
/// # Safety
/// `velocity` and `impulse` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_on_point(
    mass: f64,
    velocity: *const mech_vec3_t,
    impulse: *const mech_vec3_t,
    out: *mut mech_point_impulse_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (v, s) = unsafe { (read(velocity, "velocity")?, read(impulse, "impulse")?) };
        let out = Out::new(out, "out")?;
        let r = impulse_on_point(mass, &v.into(), &s.into())?;
        let value = mech_point_impulse_t {
            velocity_after: r.v_after.into(),
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// The outcome of a 3-D collision of two smooth point masses along a normal.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_point_impact_t {
    /// Velocity of point 1 after the impact (m/s).
    pub velocity_after_1: mech_vec3_t,
    /// Velocity of point 2 after the impact (m/s).
    pub velocity_after_2: mech_vec3_t,
    /// Impulse on point 2, along the normal (N·s); point 1 receives its negative.
    pub impulse_on_2: mech_vec3_t,
    /// Kinetic-energy change (J), −½(1 − λ²) μ (approach speed)² (5.23).
    pub energy_change: f64,
}

/// Collides two smooth point masses (spheres; masses `m1`, `m2` in kg, velocities `v1`, `v2` in
/// m/s) along the unit `normal` pointing from point 1 to point 2, with restitution λ ∈ [0, 1]
/// (5.16–5.23 on the normal components), all vectors in one frame. Points that do not approach
/// receive no impulse. Written to `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0, a restitution outside [0, 1] or a non-unit normal.
///
/// # Safety
/// `v1`, `v2` and `normal` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_collide_points(
    m1: f64,
    v1: *const mech_vec3_t,
    m2: f64,
    v2: *const mech_vec3_t,
    normal: *const mech_vec3_t,
    restitution: f64,
    out: *mut mech_point_impact_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (a, b, n) = unsafe { (read(v1, "v1")?, read(v2, "v2")?, read(normal, "normal")?) };
        let out = Out::new(out, "out")?;
        let r = collide_points(m1, &a.into(), m2, &b.into(), &n.into(), restitution)?;
        let value = mech_point_impact_t {
            velocity_after_1: r.v1_after.into(),
            velocity_after_2: r.v2_after.into(),
            impulse_on_2: r.impulse_on_2.into(),
            energy_change: r.energy_change,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}
