//! Whole mechanisms (chapter 8): potentials with exact gradients and Hessians on a kinematic
//! tree, equilibrium, stability, and the small-oscillation modes of the mechanism. Equation
//! numbers such as (8.85) are the syllabus numbering, listed in `docs/theory.md`. Units are SI.
//!
//! - [`Mechanism`]: a kinematic tree (kinematics crate) with body mass properties (mass crate),
//!   gravity, an optional steadily rotating base frame ([`RotatingFrame`], §8e) and
//!   [`potentials`]. It evaluates U*(q) = U − T₀ with its exact gradient and Hessian
//!   B = ∂²U*/∂q∂q (8.85), the mass matrix A(q) (8.28) and the gyroscopic matrix G(q).
//! - [`equilibrium`]: Newton's method on grad U* = 0 (8.74) with a line search on ‖grad U*‖ and
//!   joint limits.
//! - [`modes`]: stability from the inertia of the pencil (A, B) and the modes of the mechanism
//!   through the modal crate, with body displacements, effective masses and, in a rotating
//!   frame, the gyroscopic (quadratic) eigenproblem.

mod arithmetic;
mod assembly_error;
pub mod configuration;
pub mod equilibrium;
pub mod error;
pub mod mechanism;
pub mod modes;
pub mod potentials;

pub use configuration::Configuration;
pub use equilibrium::{Equilibrium, EquilibriumOptions, Seek, find_equilibria, find_equilibrium};
pub use error::MechanismError;
pub use mechanism::{Mechanism, RotatingFrame};
pub use modes::{
    BodyDisplacement, GyroscopicModes, MechanismModes, Stability, mechanism_modes, mechanism_modes_with_locks,
};
pub use potentials::{Anchor, PointForce, Potential, PotentialSum};
