//! Impulse dynamics: impulses, collisions with restitution and friction, fixation and
//! Lagrange's impulse equations (syllabus §5c–d and §7h–k). Equation numbers such as (7.94) are
//! the syllabus numbering, listed in `docs/theory.md`. Units are SI (kg, m, s; impulses in N·s,
//! energies in J).
//!
//! - [`point`]: impulses on point masses and point collisions (5.10–5.23);
//! - [`body`]: rigid bodies through their mobility, with infinite mass, locked axes,
//!   degenerate inertia and hinges (7.61–7.71, 7.87*–7.91*, 7.107);
//! - [`contact_space`]: one frictional impact given the contact mobility W, by the
//!   impulse-parameterised process with Newton, Poisson or Stronge restitution (7.94–7.99);
//! - [`contact`]: two bodies meeting at a point (7.72–7.99);
//! - [`fixation`]: bringing a body point to rest (7.100–7.108);
//! - [`mechanism`]: Lagrange's impulse equations A(q) Δq̇ = Q_S of a kinematic tree (7.115–7.117);
//! - [`mechanism_contact`]: contacts of a mechanism, the Delassus matrix W = J A⁻¹ Jᵀ and the
//!   single frictional contact by the impulse process;
//! - [`multi_contact`]: simultaneous frictional impacts at several contacts;
//! - [`showcase`]: Kane's double pendulum striking a rough floor under each restitution law.
//!
//! Every function that returns a `Result` checks its results: an impulse, velocity or energy
//! that overflows f64 is [`ImpulseError::NonFiniteResult`] naming it, never a NaN or an
//! infinity.

pub mod body;
mod compensated;
pub mod contact;
mod contact_frame;
pub mod contact_space;
pub mod error;
pub mod fixation;
pub mod mechanism;
pub mod mechanism_contact;
pub mod multi_contact;
pub mod point;
mod process;
pub mod showcase;
mod tangent_block;

pub use body::{BodyResponse, RigidBody};
pub use contact::{TwoBodyImpact, resolve_contact};
pub use contact_space::{
    ContactImpulse, ContactLaw, ContactMode, ImpactOptions, MAX_IMPACT_TOLERANCE, RestitutionLaw,
    resolve_in_contact_space,
};
pub use error::ImpulseError;
pub use fixation::{Fixation, fix_point};
pub use mechanism::{BodyPoint, GeneralizedImpulseResponse, MechanismInertia, PointImpulse, apply_point_impulses};
pub use mechanism_contact::{
    ContactOutcome, ContactSpace, ImpactModel, MechanismContact, MechanismImpact, resolve_single_contact,
};
pub use multi_contact::{MultiContactOptions, resolve_contacts};
