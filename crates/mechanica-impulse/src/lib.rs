//! Impulse dynamics: impulses, collisions with restitution and friction, fixation and
//! Lagrange's impulse equations (syllabus 5c–d and 7h–k, see THEORY.md).
//!
//! - [`point`]: impulses on point masses and point collisions (5.10–5.23);
//! - [`body`]: rigid bodies through their mobility, with infinite mass, locked axes,
//!   degenerate inertia and hinges (7.61–7.71, 7.87*–7.91*, 7.107);
//! - [`contact_space`]: one frictional impact given the contact mobility W, by the
//!   impulse-parameterised process with Newton, Poisson or Stronge restitution (7.94–7.99);
//! - [`contact`]: two bodies meeting at a point (7.72–7.99);
//! - [`fixation`]: bringing a body point to rest (7.100–7.108).

pub mod body;
pub mod contact;
pub mod contact_space;
pub mod error;
pub mod fixation;
pub mod point;

pub use body::{BodyResponse, RigidBody};
pub use contact::{TwoBodyImpact, resolve_contact};
pub use contact_space::{
    ContactImpulse, ContactLaw, ContactMode, ImpactOptions, RestitutionLaw, resolve_in_contact_space,
};
pub use error::ImpulseError;
pub use fixation::{Fixation, fix_point};
