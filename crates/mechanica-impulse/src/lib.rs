//! Impulse dynamics: impulses, collisions with restitution and friction, fixation and
//! Lagrange's impulse equations (syllabus 5c–d and 7h–k, see THEORY.md).

pub mod error;
pub mod point;

pub use error::ImpulseError;
