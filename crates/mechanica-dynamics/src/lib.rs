//! Equations of motion of a mechanism (Lagrange's equations (7.60), EB1911 §22 (11)):
//!
//!   A(q) q̈ + c(q, q̇) + g(q) = τ + Σ Q_loads,
//!
//! on the kinematic tree of `mechanica-kinematics` with the mass properties of
//! `mechanica-mass` and the potentials of `mechanica-mechanism`. Equation numbers refer to
//! `docs/theory.md`. Units are SI; vectors are world (base-frame) components.
//!
//! - [`Dynamics`]: a [`mechanica_mechanism::Mechanism`] with [`Damper`]s (Rayleigh
//!   dissipation, FM 4.62–4.66) and [`VelocityPotential`]s (FM 4.90; the charged point of
//!   [`ChargedPoint`] is the worked example).
//! - [`Dynamics::inverse_dynamics`] ([`inverse`]): τ by the recursive Newton–Euler algorithm,
//!   with c, g and each load's generalized force apart, and the wrench every joint transmits
//!   ([`JointReaction`], FM 4.61).
//! - [`Dynamics::forward_dynamics`] ([`forward`]): q̈ by the articulated-body algorithm, checked
//!   by the inverse dynamics; [`Dynamics::forward_dynamics_crba`] by A(q) and Cholesky, with
//!   the conditioning of A.
//! - [`Dynamics::rnea_into`] and [`Dynamics::aba_into`]: the same without reports, allocating
//!   nothing, for simulators' inner loops.
//! - [`ConstrainedDynamics`] ([`constraints`]): loop closures and prescribed coordinates by
//!   Lagrange multipliers, with reactions, projections and constrained equilibria.

mod articulated;
pub mod constraints;
pub mod crba;
pub mod damped_modes;
pub mod dissipation;
pub mod error;
pub mod forward;
pub mod free_body;
pub mod inverse;
pub mod loads;
pub mod model;
pub mod spatial;
pub mod velocity_potential;

pub use constraints::{
    Baumgarte, ConstrainedDynamics, ConstrainedEquilibrium, ConstrainedEquilibriumOptions, ConstrainedForward,
    Constraint, ConstraintDrift, ConstraintReaction, PositionProjection, ProjectionMetric, ProjectionOptions,
    VelocityProjection,
};
pub use damped_modes::DampedModes;
pub use dissipation::Damper;
pub use error::DynamicsError;
pub use forward::{ForwardDynamics, ForwardMethod};
pub use inverse::{Frame, InverseDynamics, JointReaction};
pub use loads::{LoadKind, LoadTerm};
pub use model::{Dynamics, State};
pub use spatial::Wrench;
pub use velocity_potential::{ChargedPoint, ElectromagneticField, FieldPotentials, UniformFields, VelocityPotential};
