//! Mass properties of points, rods, laminae, solids, meshes, composites and mechanisms.
//!
//! Equation numbers refer to the syllabus (`seeds/000`, chapter 3), see THEORY.md.

pub mod error;
pub mod properties;

pub use error::MassError;
pub use properties::MassProperties;
