//! Two-body point impacts with restitution and Coulomb friction.

use super::body::{body_from_c, mech_impulse_body_t};
use super::{mech_contact_mode_t, mech_restitution_law_t, mode_to_c};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::enum_value;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_impulse::{ContactLaw, ImpactOptions, RestitutionLaw, resolve_contact};
use mechanica_kinematics::nalgebra::Vector3;

/// A point contact between body 1 and body 2 and its material law.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_impulse_contact_t {
    /// The contact point R (world frame, m).
    pub point: mech_vec3_t,
    /// The unit normal pointing from body 1 into body 2 (|n| = 1 within 1e-9).
    pub normal: mech_vec3_t,
    /// Coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient f ≥ 0; +INFINITY means the contact cannot slip.
    pub friction: f64,
    /// A MECH_RESTITUTION_* value.
    pub law: mech_restitution_law_t,
    /// Relative tolerance of the 3-D swerving-slip integration (0 < tolerance ≤ 1e-2, e.g. 1e-10).
    pub tolerance: f64,
}

/// The outcome of a two-body point impact (world frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_impact_result_t {
    /// Impulse P on body 2 (body 1 receives −P) (N·s).
    pub impulse: mech_vec3_t,
    /// Normal impulse P·n ≥ 0 (N·s).
    pub normal_impulse: f64,
    /// Tangential (friction) impulse P − (P·n) n (N·s).
    pub tangential_impulse: mech_vec3_t,
    /// Normal impulse at the end of compression (N·s).
    pub compression_impulse: f64,
    /// Relative velocity of the contact point (body 2 minus body 1) after the impact (m/s).
    pub relative_velocity_after: mech_vec3_t,
    /// A MECH_CONTACT_* value.
    pub mode: mech_contact_mode_t,
    /// Body 1 centre-of-mass velocity after (m/s).
    pub velocity_after_1: mech_vec3_t,
    /// Body 1 angular velocity after (rad/s).
    pub angular_velocity_after_1: mech_vec3_t,
    /// Body 2 centre-of-mass velocity after (m/s).
    pub velocity_after_2: mech_vec3_t,
    /// Body 2 angular velocity after (rad/s).
    pub angular_velocity_after_2: mech_vec3_t,
    /// Total kinetic-energy change ΔT = P·(u⁻ + ½ W P) (J).
    pub energy_change: f64,
    /// A bound on the error of the impulse (N·s) against the exact impact process: the
    /// swerving-slip integration, the slip-halting cut-off and the rounding of every
    /// closed-form segment through the conditioning of the contact mobility; a few ulps of
    /// |impulse| when nothing was integrated.
    pub integration_error: f64,
    /// Integration steps plus closed-form segments used.
    pub steps: u64,
}

/// Resolves the impact of `body1` and `body2` at `contact` (7.72–7.99): smooth or rough
/// (isotropic Coulomb, with stick, slip, halting, reversal and 3-D swerving slip) with the
/// selected restitution law, and writes the impulse, the velocities after, the energy change
/// and the estimated error of the impulse (`integration_error`) to `out`.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_BAD_ENUM for an
/// unknown law or constraint; MECH_STATUS_INVALID_ARGUMENT for a non-unit normal, restitution
/// outside [0, 1], negative friction, a tolerance outside (0, 1e-2] or an invalid body (see
/// mech_impulse_apply); MECH_STATUS_SINGULAR when neither body can move along the normal;
/// MECH_STATUS_NOT_CONVERGED for a frictional jam, including a contact that self-locks (friction
/// holds it at rest, so the normal velocity stays zero) under MECH_RESTITUTION_NEWTON or
/// MECH_RESTITUTION_STRONGE with restitution > 0 (under MECH_RESTITUTION_POISSON the impact
/// ends at (1 + e) times the compression impulse with the contact at rest);
/// MECH_STATUS_OUT_OF_RANGE when the impulse or a velocity overflows.
///
/// # Safety
/// `body1`, `body2` and `contact` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_impulse_resolve_contact(
    body1: *const mech_impulse_body_t,
    body2: *const mech_impulse_body_t,
    contact: *const mech_impulse_contact_t,
    out: *mut mech_impact_result_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (b1, b2, c) = unsafe { (read(body1, "body1")?, read(body2, "body2")?, read(contact, "contact")?) };
        let out = Out::new(out, "out")?;
        let body1 = body_from_c(&b1, "body1")?;
        let body2 = body_from_c(&b2, "body2")?;
        finite(&c.point, "contact.point")?;
        finite(&c.normal, "contact.normal")?;
        finite(&c.restitution, "contact.restitution")?;
        finite(&c.tolerance, "contact.tolerance")?;
        let law: RestitutionLaw = enum_value(c.law, "contact.law")?;
        let law = ContactLaw::new(c.restitution, c.friction, law)?;
        if c.tolerance <= 0.0 {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("contact.tolerance must be positive, got {}", c.tolerance),
            ));
        }
        let options = ImpactOptions {
            tolerance: c.tolerance,
            ..ImpactOptions::default()
        };
        let point: Vector3<f64> = c.point.into();
        let r = resolve_contact(&body1, &body2, &point, &c.normal.into(), &law, &options)?;
        let value = mech_impact_result_t {
            impulse: r.contact.impulse_w.into(),
            normal_impulse: r.contact.normal_impulse,
            tangential_impulse: r.contact.tangential_impulse_w.into(),
            compression_impulse: r.contact.compression_impulse,
            relative_velocity_after: r.contact.u_after_w.into(),
            mode: mode_to_c(r.contact.mode),
            velocity_after_1: r.body1.v_wc_after.into(),
            angular_velocity_after_1: r.body1.w_w_after.into(),
            velocity_after_2: r.body2.v_wc_after.into(),
            angular_velocity_after_2: r.body2.w_w_after.into(),
            energy_change: r.contact.energy_change,
            integration_error: r.contact.integration_error,
            steps: r.contact.steps as u64,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}
