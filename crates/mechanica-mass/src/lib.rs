//! Mass properties of points, rods, laminae, solids, meshes, composites and mechanisms.
//!
//! Equation numbers such as (3.27) are the syllabus numbering (mostly chapter 3), listed in
//! `docs/theory.md`. Units are SI (kg, m, kg·m²).
//!
//! - [`properties`]: the [`MassProperties`] value, composition, holes, transformation, Steiner;
//! - [`principal`]: principal moments and a canonical principal frame;
//! - [`validity`]: the physical validity check and repair;
//! - [`primitives`]: closed forms for points, rods, laminae and solids;
//! - [`mesh`], [`topology`] and [`io`]: triangle meshes, their edge checks and file formats;
//! - [`weld`] and [`crack`]: welding near-coincident vertices, and telling cracks from open
//!   boundaries;
//! - [`mechanism`]: the mass matrix A(q) of a kinematic tree (composite-rigid-body recursion);
//! - [`momenta`]: momentum, angular momentum and kinetic energy of a rigid body.
//!
//! Every function that returns a `Result` checks its results: a mass, moment, tensor or
//! matrix entry that is not representable is [`MassError::NonFiniteResult`] (overflow) or
//! [`MassError::MassUnderflow`] (a mass from a density that rounds to zero), never a NaN, an
//! infinity or a zero mass.

pub mod crack;
pub mod error;
#[cfg(feature = "io")]
pub mod io;
pub mod mechanism;
pub mod mesh;
mod mesh_integrals;
pub mod momenta;
mod parallel;
pub mod primitives;
pub mod principal;
pub mod properties;
pub mod tessellation;
pub mod topology;
pub mod validity;
pub mod weld;

pub use error::MassError;
pub use mesh::{MeshMassProperties, MeshOptions, TopologySource, TriangleMesh, mesh_mass_properties};
pub use primitives::Amount;
pub use principal::PrincipalAxes;
pub use properties::MassProperties;
pub use validity::{InertiaClass, InertiaIssue, ValidityTolerance};
pub use weld::{DEFAULT_WELD_TOLERANCE, WeldReport, weld_vertices};
