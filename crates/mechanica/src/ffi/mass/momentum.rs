//! Momenta and kinetic energy of one moving body.

use super::{mech_mass_properties_t, read_properties};
use crate::ffi::boundary::boundary;
use crate::ffi::spatial::read_vec3;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;

/// The angular momentum D_A = J₀ ω + (x₀ − a) × m v₀ (kg·m²/s, syllabus 3.5–3.7) about the point
/// `point` (m; fixed or moving, only its position enters) of a body whose `properties` are given
/// in the inertial frame at this instant, moving with centre velocity `com_velocity` (m/s) and
/// angular velocity `omega` (rad/s), both in that frame. Written to `angular_momentum_out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0 or a tensor not symmetric within 1e-9·Σ|J_kk|; MECH_STATUS_OUT_OF_RANGE when the angular momentum overflows.
///
/// # Safety
/// The inputs must be readable and `angular_momentum_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_angular_momentum(
    properties: *const mech_mass_properties_t,
    point: *const mech_vec3_t,
    com_velocity: *const mech_vec3_t,
    omega: *const mech_vec3_t,
    angular_momentum_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (a, v, w) = unsafe {
            (
                read_vec3(point, "point")?,
                read_vec3(com_velocity, "com_velocity")?,
                read_vec3(omega, "omega")?,
            )
        };
        let out = Out::new(angular_momentum_out, "angular_momentum_out")?;
        let d = props.angular_momentum_about(&a, &v, &w);
        finite_result(d.as_slice(), "angular momentum")?;
        // SAFETY: caller's contract.
        unsafe { out.write(d.into()) };
        Ok(())
    })
}

/// The kinetic energy T = ½ m v₀·v₀ + ½ ω·J₀ ω (J, syllabus 3.37) into `energy_out` and the
/// momentum p = m v₀ (kg·m/s, 3.4) into `momentum_out` (may be NULL) of a body moving with
/// centre velocity `com_velocity` (m/s) and angular velocity `omega` (rad/s), both in the frame
/// of `properties`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT for
/// a mass ≤ 0 or a tensor not symmetric within 1e-9·Σ|J_kk|; MECH_STATUS_OUT_OF_RANGE when the energy or the momentum overflows.
///
/// # Safety
/// The inputs must be readable, `energy_out` writable, `momentum_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mass_kinetic_energy(
    properties: *const mech_mass_properties_t,
    com_velocity: *const mech_vec3_t,
    omega: *const mech_vec3_t,
    energy_out: *mut f64,
    momentum_out: *mut mech_vec3_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let props = unsafe { read_properties(properties, "properties") }?;
        // SAFETY: caller's contract.
        let (v, w) = unsafe { (read_vec3(com_velocity, "com_velocity")?, read_vec3(omega, "omega")?) };
        let energy = Out::new(energy_out, "energy_out")?;
        let momentum = Out::optional(momentum_out, "momentum_out")?;
        let t = props.kinetic_energy(&v, &w);
        finite_result(&t, "kinetic energy")?;
        let p = props.linear_momentum(&v);
        if momentum.is_some() {
            finite_result(p.as_slice(), "momentum")?;
        }
        // SAFETY: caller's contract.
        unsafe {
            energy.write(t);
            if let Some(out) = momentum {
                out.write(p.into());
            }
        }
        Ok(())
    })
}
