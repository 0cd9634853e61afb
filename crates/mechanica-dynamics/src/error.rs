//! The error type of the dynamics crate.

use thiserror::Error;

/// Everything that can go wrong while computing the equations of motion.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum DynamicsError {
    /// The mechanism (tree, potentials, mass matrix) could not be evaluated.
    #[error(transparent)]
    Mechanism(#[from] mechanica_mechanism::MechanismError),
    /// A kinematic computation failed (bad coordinates, overflow).
    #[error(transparent)]
    Kinematics(#[from] mechanica_kinematics::KinematicsError),
    /// A mass computation failed.
    #[error(transparent)]
    Mass(#[from] mechanica_mass::MassError),
    /// The modal solver failed on the damped problem.
    #[error(transparent)]
    Modal(#[from] mechanica_modal::ModalError),
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
    /// A computed quantity overflowed f64 or became NaN.
    #[error("{what} is not finite: the inputs are too large for f64")]
    NonFiniteResult {
        /// Which quantity.
        what: &'static str,
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
    /// The articulated inertia of a joint is singular: the subtree it carries has no mass or
    /// inertia along some of the joint's directions, so q̈ is not determined.
    #[error(
        "the articulated inertia of body {body}'s joint (coordinates {first_coordinate}..) is singular \
         (pivot {pivot:e} against {scale:e}): the subtree it moves has no inertia along the joint"
    )]
    SingularArticulatedInertia {
        /// The body whose joint has no inertia.
        body: usize,
        /// Its first coordinate.
        first_coordinate: usize,
        /// The failing pivot.
        pivot: f64,
        /// The size of the joint's articulated inertia.
        scale: f64,
    },
    /// The mass matrix A(q) is not positive definite (massless coordinates).
    #[error(
        "the mass matrix is not positive definite to working precision: its Cholesky factorization fails at coordinate {pivot} (diagonal entry {value:e})"
    )]
    SingularMassMatrix {
        /// The coordinate whose pivot failed.
        pivot: usize,
        /// That coordinate's diagonal entry A_kk (the failed pivot is A_kk less the
        /// contributions of the earlier coordinates, at or below rounding level).
        value: f64,
    },
    /// A dissipation element cannot be evaluated at this state.
    #[error("{name}: {reason}")]
    Dissipation {
        /// The damper's name.
        name: String,
        /// What went wrong.
        reason: &'static str,
    },
    /// The constraint Jacobian is rank deficient at q: some constraints are redundant.
    #[error(
        "constraint {constraint} ({name}) is redundant at this configuration: its row of J A⁻¹ Jᵀ has pivot \
         {pivot:e} against {scale:e}"
    )]
    RedundantConstraint {
        /// The index of the first constraint equation found dependent on the earlier ones.
        constraint: usize,
        /// The constraint's name.
        name: String,
        /// The failing pivot.
        pivot: f64,
        /// The size of the matrix.
        scale: f64,
    },
    /// A fixed-step integration would need more steps than its documented cap.
    #[error("{what} needs {steps:e} steps, more than the cap of {cap}")]
    TooManySteps {
        /// Which integration.
        what: &'static str,
        /// The steps it would need.
        steps: f64,
        /// The cap.
        cap: u64,
    },
    /// An iterative solve did not converge.
    #[error("{what} did not converge after {iterations} iterations (residual {residual:e})")]
    NotConverged {
        /// Which solve.
        what: &'static str,
        /// Iterations done.
        iterations: usize,
        /// The last residual.
        residual: f64,
    },
}

/// Ok when every entry of `values` is finite; [`DynamicsError::NonFiniteInput`] otherwise.
pub(crate) fn check_input(values: &[f64], what: &'static str) -> Result<(), DynamicsError> {
    match values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((index, &value)) => Err(DynamicsError::NonFiniteInput { what, index, value }),
        None => Ok(()),
    }
}

/// Ok when `values` has `expected` entries, all finite.
pub(crate) fn check_vector(values: &[f64], expected: usize, what: &'static str) -> Result<(), DynamicsError> {
    if values.len() != expected {
        return Err(DynamicsError::WrongLength {
            what,
            expected,
            got: values.len(),
        });
    }
    check_input(values, what)
}

/// Ok when every value is finite; [`DynamicsError::NonFiniteResult`] naming `what` otherwise.
pub(crate) fn check_result<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    what: &'static str,
) -> Result<(), DynamicsError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(DynamicsError::NonFiniteResult { what })
    }
}
