//! C entry points of the impulse-dynamics crate.

use super::boundary::{FfiError, boundary};
use super::status::*;
use super::validate::*;
use mechanica_impulse::ImpulseError;
use mechanica_impulse::point::collide_collinear;

impl From<ImpulseError> for FfiError {
    fn from(error: ImpulseError) -> Self {
        let status = match error {
            ImpulseError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            ImpulseError::NonPositiveMass { .. } | ImpulseError::RestitutionOutOfRange(_) => {
                MECH_STATUS_INVALID_ARGUMENT
            }
        };
        FfiError::new(status, error.to_string())
    }
}

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

/// Collides point 1 (mass `m1`, velocity `v1`) with point 2 (mass `m2`, velocity `v2`) on one
/// line with Newton's restitution coefficient `restitution` ∈ [0, 1]. Points that do not
/// approach (v1 ≤ v2) receive no impulse.
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
