//! C entry points of the impulse-dynamics crate: impulses on points and bodies, point
//! collisions, fixation, two-body frictional impacts (syllabus 5c–d, 7h–j) and impacts of
//! mechanisms (7.115–7.117).
//!
//! Bodies cross the boundary as plain data in *inverse* form ([`mech_impulse_body_t`]):
//! inverse mass and inverse central inertia in world axes, so an infinite mass or a locked
//! axis is a zero, plus an optional hinge. All vectors are in the world frame W.
//!
//! Mechanisms act through the kinematic tree handle at the state set by mech_tree_set_state,
//! with one ::mech_mass_properties_t per body (body frame).

use super::boundary::FfiError;
use super::c_enum::c_enum;
use super::status::*;
use mechanica_impulse::{ContactMode, ImpulseError, RestitutionLaw};

mod body;
mod contact;
mod mechanism;
mod mechanism_contact;
mod point;

pub use body::*;
pub use contact::*;
pub use mechanism::*;
pub use mechanism_contact::*;
pub use point::*;

impl From<ImpulseError> for FfiError {
    fn from(error: ImpulseError) -> Self {
        let status = match error {
            ImpulseError::InContact { contact, source } => {
                let inner = FfiError::from(*source);
                return FfiError::new(inner.status, format!("contact {contact}: {}", inner.message));
            }
            ImpulseError::Kinematics(e) => return FfiError::from(e),
            ImpulseError::Mass(e) => return FfiError::from(e),
            ImpulseError::SingularMassMatrix { .. } => MECH_STATUS_NOT_POSITIVE_DEFINITE,
            ImpulseError::BodyOutOfRange { .. } => MECH_STATUS_INVALID_ARGUMENT,
            ImpulseError::ContactImmovable { .. } => MECH_STATUS_SINGULAR,
            ImpulseError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            ImpulseError::NonFiniteResult { .. } => MECH_STATUS_OUT_OF_RANGE,
            ImpulseError::NonPositiveMass { .. }
            | ImpulseError::NegativeInverseMass { .. }
            | ImpulseError::RestitutionOutOfRange(_)
            | ImpulseError::NegativeFriction(_)
            | ImpulseError::InvalidOption { .. }
            | ImpulseError::NotUnit { .. }
            | ImpulseError::ZeroInertiaAxisExcited { .. }
            | ImpulseError::ConstraintViolated { .. } => MECH_STATUS_INVALID_ARGUMENT,
            ImpulseError::InvalidInertia { .. } => MECH_STATUS_NOT_POSITIVE_DEFINITE,
            ImpulseError::Singular { .. } => MECH_STATUS_SINGULAR,
            ImpulseError::NotConverged { .. } => MECH_STATUS_NOT_CONVERGED,
            ImpulseError::DimensionMismatch { .. } => MECH_STATUS_BAD_DIMENSION,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// Which relation ends restitution in a frictional impact (int32).
pub type mech_restitution_law_t = i32;
/// Newton's kinematic law u_n⁺ = −e u_n⁻ (7.94); may gain energy with friction (Kane's paradox).
pub const MECH_RESTITUTION_NEWTON: mech_restitution_law_t = 0;
/// Poisson's kinetic law: restitution impulse = e × compression impulse.
pub const MECH_RESTITUTION_POISSON: mech_restitution_law_t = 1;
/// Stronge's energetic law: restitution work = −e² × compression work; never gains energy.
/// The recommended default.
pub const MECH_RESTITUTION_STRONGE: mech_restitution_law_t = 2;

c_enum!(RestitutionLaw,
    MECH_RESTITUTION_NEWTON => RestitutionLaw::Newton,
    MECH_RESTITUTION_POISSON => RestitutionLaw::Poisson,
    MECH_RESTITUTION_STRONGE => RestitutionLaw::Stronge,
);

/// The contact mode of an impact (int32), as reported in ::mech_impact_result_t and
/// ::mech_mechanism_contact_result_t.
pub type mech_contact_mode_t = i32;
/// No impulse: the contact was separating or grazing.
pub const MECH_CONTACT_NO_IMPACT: mech_contact_mode_t = 0;
/// Smooth contact (friction 0).
pub const MECH_CONTACT_FRICTIONLESS: mech_contact_mode_t = 1;
/// The contact stuck from the start (or friction = +inf).
pub const MECH_CONTACT_STICK: mech_contact_mode_t = 2;
/// The contact slipped throughout (possibly swerving in 3-D).
pub const MECH_CONTACT_SLIP: mech_contact_mode_t = 3;
/// The slip halted and the contact stuck for the rest of the impact.
pub const MECH_CONTACT_SLIP_THEN_STICK: mech_contact_mode_t = 4;
/// The slip halted and resumed in a new direction (reversal).
pub const MECH_CONTACT_REVERSED: mech_contact_mode_t = 5;

/// The C value of a contact mode.
pub(crate) fn mode_to_c(mode: ContactMode) -> mech_contact_mode_t {
    match mode {
        ContactMode::NoImpact => MECH_CONTACT_NO_IMPACT,
        ContactMode::Frictionless => MECH_CONTACT_FRICTIONLESS,
        ContactMode::Stick => MECH_CONTACT_STICK,
        ContactMode::Slip => MECH_CONTACT_SLIP,
        ContactMode::SlipThenStick => MECH_CONTACT_SLIP_THEN_STICK,
        ContactMode::Reversed => MECH_CONTACT_REVERSED,
    }
}
