//! The error type of the motion crate.

use mechanica_dynamics::DynamicsError;
use mechanica_impulse::ImpulseError;
use thiserror::Error;

/// Why one integration step could not be completed.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StepFailure {
    /// The dynamics could not be evaluated (singular mass matrix, non-finite acceleration, …).
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// The state or an intermediate stage became NaN or infinite.
    #[error("the {what} is not finite")]
    NonFinite {
        /// Which quantity.
        what: &'static str,
    },
    /// The applied-force callback returned a NaN or infinite entry.
    #[error("the applied force τ[{index}] = {value} is not finite")]
    NonFiniteForce {
        /// The coordinate.
        index: usize,
        /// The value returned.
        value: f64,
    },
    /// The mass matrix is not positive definite, so p = A q̇ cannot be inverted.
    #[error("the mass matrix is not positive definite")]
    SingularMassMatrix,
    /// The implicit equations of a step were not solved to rounding level.
    #[error("{what} did not converge after {iterations} iterations (last correction {correction:e})")]
    NotConverged {
        /// Which iteration.
        what: &'static str,
        /// Iterations done.
        iterations: usize,
        /// The last correction, ∞-norm.
        correction: f64,
    },
    /// RATTLE's simplified Newton iteration did not bring ‖f(q₁)‖₂ down to the rounding level
    /// of f (M.17).
    #[error(
        "the constraints were not met after {iterations} Newton iterations (‖f‖₂ = {residual:e}, tolerance {tolerance:e})"
    )]
    ConstraintNotMet {
        /// Newton iterations done.
        iterations: usize,
        /// ‖f(q₁)‖₂ at the last iterate.
        residual: f64,
        /// The tolerance: the rounding level of f at q₁.
        tolerance: f64,
    },
    /// J A⁻¹ Jᵀ is not positive definite: the constraints' Jacobian J has dependent rows
    /// (redundant constraints) at the start of a step.
    #[error("the constraints' Jacobian has dependent rows (J A⁻¹ Jᵀ is singular)")]
    SingularConstraints,
    /// The adaptive step size fell to the rounding level of t.
    #[error("the step size {step:e} fell below the rounding level of t")]
    StepSizeUnderflow {
        /// The rejected step size, s.
        step: f64,
    },
    /// The run took more steps than its limit.
    #[error("more than {limit} steps")]
    TooManySteps {
        /// The limit of [`crate::Options::max_steps`].
        limit: usize,
    },
    /// A contact stays closed after its impact (its gap is ≤ 0 and closing again): resting or
    /// sliding contact, or impacts accumulating in finite time (M.23). Neither is modelled.
    #[error(
        "contact {contact} stays closed (gap {gap:e} m, closing at {rate:e} m/s): sustained contact and accumulating impacts are not modelled"
    )]
    SustainedContact {
        /// The contact's index.
        contact: usize,
        /// Its gap g, m.
        gap: f64,
        /// Its rate ġ, m/s.
        rate: f64,
    },
    /// The run met more impacts than its limit.
    #[error("more than {limit} impacts")]
    TooManyImpacts {
        /// The limit of [`crate::Options::max_impacts`].
        limit: usize,
    },
    /// The impact at a located contact event could not be resolved.
    #[error("the impact could not be resolved: {0}")]
    Impact(Box<ImpulseError>),
}

/// Everything that can go wrong while integrating the equations of motion.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MotionError {
    /// The dynamics could not be set up or evaluated at the initial state.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// A quantity computed from a finite input overflowed f64.
    #[error("the {what} is not finite")]
    NonFiniteResult {
        /// What overflowed.
        what: &'static str,
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
    /// An input entry is NaN or infinite.
    #[error("{what}[{index}] is not finite ({value})")]
    NonFiniteInput {
        /// Which input.
        what: &'static str,
        /// The entry.
        index: usize,
        /// The value.
        value: f64,
    },
    /// An option or argument is outside its range.
    #[error("{what} must be {requirement}, got {value}")]
    OutOfRange {
        /// Which parameter.
        what: &'static str,
        /// The requirement.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// A coordinate index is out of range.
    #[error("{what}: coordinate {index} does not exist (the mechanism has {dof} coordinates)")]
    NoSuchCoordinate {
        /// Which input.
        what: &'static str,
        /// The index given.
        index: usize,
        /// Number of coordinates.
        dof: usize,
    },
    /// The run would write more output samples than [`crate::MAX_SAMPLES`].
    #[error("t_end / output interval asks for {requested:e} samples; the limit is {limit}")]
    TooManySamples {
        /// (t_end − t) / interval + 1.
        requested: f64,
        /// The limit.
        limit: usize,
    },
    /// A unilateral contact is not valid for this mechanism.
    #[error("contact {index}: {reason}")]
    InvalidContact {
        /// The contact's index.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// A step failed: the run stopped at `t` with the last good state.
    #[error("the integration stopped at t = {t}: {cause}")]
    StepFailed {
        /// The time reached, s.
        t: f64,
        /// The last good coordinates (in the reporting chart, see [`crate::chart`]).
        q: Vec<f64>,
        /// The last good velocities.
        q_dot: Vec<f64>,
        /// Why the step failed.
        cause: StepFailure,
    },
}

/// Ok when `values` has `expected` entries, all finite.
pub(crate) fn check_vector(values: &[f64], expected: usize, what: &'static str) -> Result<(), MotionError> {
    if values.len() != expected {
        return Err(MotionError::WrongLength {
            what,
            expected,
            got: values.len(),
        });
    }
    match values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, &value)) => Err(MotionError::NonFiniteInput { what, index, value }),
        None => Ok(()),
    }
}

/// Ok when every value is finite, [`StepFailure::NonFinite`] naming `what` otherwise.
pub(crate) fn check_finite(values: &[f64], what: &'static str) -> Result<(), StepFailure> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(StepFailure::NonFinite { what })
    }
}
