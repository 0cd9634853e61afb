//! The error type of the mechanism crate.

use thiserror::Error;

/// Everything that can go wrong while building or analysing a mechanism.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MechanismError {
    /// A kinematic computation failed (bad coordinates, wrong lengths, ...).
    #[error(transparent)]
    Kinematics(#[from] mechanica_kinematics::KinematicsError),
    /// A mass-properties computation failed.
    #[error(transparent)]
    Mass(#[from] mechanica_mass::MassError),
    /// The modal solver rejected the pencil (A, B) or failed.
    #[error(transparent)]
    Modal(#[from] mechanica_modal::ModalError),
    /// A number that must be finite is NaN or infinite.
    #[error("{what} is not finite ({value})")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An input has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    WrongLength {
        /// Which input.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A body index is out of range.
    #[error("{what}: body {body} does not exist (the tree has {bodies} bodies)")]
    NoSuchBody {
        /// Which input.
        what: &'static str,
        /// The index given.
        body: usize,
        /// Number of bodies.
        bodies: usize,
    },
    /// A coordinate index is out of range.
    #[error("{what}: coordinate {index} does not exist (the tree has {dof} coordinates)")]
    NoSuchCoordinate {
        /// Which input.
        what: &'static str,
        /// The index given.
        index: usize,
        /// Number of coordinates.
        dof: usize,
    },
    /// A parameter is outside its physical range.
    #[error("{what} must be {requirement}, got {value}")]
    OutOfRange {
        /// Which parameter.
        what: &'static str,
        /// The requirement, e.g. "≥ 0".
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// A spring with a rest length has zero current length: its direction, hence its Hessian,
    /// is undefined.
    #[error("{name} has zero length; its force direction is undefined")]
    ZeroLengthSpring {
        /// Name of the spring.
        name: String,
    },
    /// Second derivatives in rotation-vector coordinates (spherical and free joints) are exact
    /// only at φ = 0; rebase the tree first (the equilibrium and mode routines do this).
    #[error("body {body}: its rotation-vector coordinates are not zero; rebase the tree before asking for a Hessian")]
    NotRebased {
        /// The body whose spherical or free joint has φ ≠ 0.
        body: usize,
    },
    /// Gravity not along the rotation axis makes U* time dependent: no relative equilibrium.
    #[error("gravity must be parallel to the rotation axis of a rotating frame (angle {angle_deg}°)")]
    GravityNotAlongAxis {
        /// Angle between gravity and the axis, degrees.
        angle_deg: f64,
    },
    /// A joint limit pair is inverted or the start point lies outside it.
    #[error("coordinate {index}: limits [{lower}, {upper}] are invalid")]
    BadLimits {
        /// Coordinate index.
        index: usize,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// The equilibrium search did not reach the tolerance; the best point is reported.
    #[error(
        "equilibrium search did not converge in {iterations} iterations: best |grad U*| = {gradient_norm:.3e} (tolerance {tolerance:.3e}) at q = {best_q:?}"
    )]
    NoEquilibrium {
        /// Iterations performed.
        iterations: usize,
        /// ‖grad U*‖ at the best point.
        gradient_norm: f64,
        /// The tolerance asked for.
        tolerance: f64,
        /// The best point found.
        best_q: Vec<f64>,
    },
    /// A user potential reported a failure.
    #[error("potential {name}: {message}")]
    Potential {
        /// Name of the potential.
        name: String,
        /// What went wrong.
        message: String,
    },
    /// A numerical factorisation or eigen-decomposition failed.
    #[error("{0}")]
    Numerical(&'static str),
}

/// Checks that `value` is finite.
pub(crate) fn check_finite(value: f64, what: &'static str) -> Result<f64, MechanismError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MechanismError::NonFinite { what, value })
    }
}

/// Checks that every entry of `values` is finite.
pub(crate) fn check_all_finite<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    what: &'static str,
) -> Result<(), MechanismError> {
    for &v in values {
        check_finite(v, what)?;
    }
    Ok(())
}
