//! The error type of the impulse crate.

use thiserror::Error;

/// What was wrong with which impact input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ImpulseError {
    /// A number that must be finite was NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A mass that must be positive was zero or negative.
    #[error("{what} must be positive, got {value}")]
    NonPositiveMass {
        /// Which mass.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An inverse mass that must be ≥ 0 was negative.
    #[error("{what} must be non-negative (0 means infinite mass), got {value}")]
    NegativeInverseMass {
        /// Which inverse mass.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An inertia tensor (or its inverse) was not symmetric positive semidefinite.
    #[error("{what} is not symmetric positive semidefinite: {detail} = {value}")]
    InvalidInertia {
        /// Which tensor.
        what: &'static str,
        /// Which test failed ("asymmetry" or "smallest eigenvalue").
        detail: &'static str,
        /// The measured asymmetry or eigenvalue.
        value: f64,
    },
    /// The coefficient of restitution is outside [0, 1].
    #[error("restitution coefficient must lie in [0, 1], got {0}")]
    RestitutionOutOfRange(f64),
    /// The coefficient of friction is negative (NaN is reported as NonFinite; +∞ is allowed).
    #[error("friction coefficient must be ≥ 0 (or +inf), got {0}")]
    NegativeFriction(f64),
    /// The impact options ask for something meaningless: a relative tolerance outside
    /// (0, [`crate::MAX_IMPACT_TOLERANCE`]], or no integration step at all.
    #[error("impact options: {what} must lie in {range}, got {value}")]
    InvalidOption {
        /// The option.
        what: &'static str,
        /// Its allowed range, in words.
        range: &'static str,
        /// The value given.
        value: f64,
    },
    /// A direction that must be a unit vector (contact normal, hinge axis) is not.
    #[error("{what} must be a unit vector, but its length is {norm}")]
    NotUnit {
        /// Which vector.
        what: &'static str,
        /// Its Euclidean length.
        norm: f64,
    },
    /// An impulse would excite a rotation about an axis with zero moment of inertia (a rod's
    /// own axis, any axis of a point mass): the contact point is off that axis.
    #[error(
        "{what}: the impulsive moment excites the zero-inertia axis ({}, {}, {}) (moment component {moment})",
        axis[0], axis[1], axis[2]
    )]
    ZeroInertiaAxisExcited {
        /// Which body or call.
        what: &'static str,
        /// The unit axis with zero moment of inertia, world frame.
        axis: [f64; 3],
        /// The component of the (unit-impulse) moment along that axis.
        moment: f64,
    },
    /// The pre-impact velocity violates a hinge constraint of the body.
    #[error("{what}: the velocity violates the hinge constraint by {residual} m/s (tolerance {tolerance})")]
    ConstraintViolated {
        /// Which body.
        what: &'static str,
        /// The norm of the constraint velocity C·(v, ω).
        residual: f64,
        /// The accepted tolerance.
        tolerance: f64,
    },
    /// The problem has no solution at this input: e.g. both bodies are immovable along the
    /// contact normal while approaching, or a fixation is asked of an immovable point.
    #[error("{what}: singular ({value})")]
    Singular {
        /// What could not be solved.
        what: &'static str,
        /// The measured quantity (pivot, residual) that shows it.
        value: f64,
    },
    /// The impact process did not terminate: the normal velocity stops increasing with the
    /// normal impulse (frictional jam, Painlevé-type), or the step budget ran out.
    #[error("impact process did not terminate: {reason} (after {steps} steps, normal impulse {normal_impulse})")]
    NotConverged {
        /// Why it stopped.
        reason: &'static str,
        /// Integration steps and segments taken.
        steps: usize,
        /// Normal impulse accumulated when it stopped (N·s).
        normal_impulse: f64,
    },
    /// A matrix or vector argument had the wrong size.
    #[error("{what} has the wrong size: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which argument.
        what: &'static str,
        /// Expected number of entries (or rows, as the message says).
        expected: usize,
        /// Actual number.
        got: usize,
    },
    /// The mass matrix A(q) of a mechanism is singular or only semidefinite at this
    /// configuration: coordinate `coordinate` adds (almost) no inertia beyond the earlier
    /// coordinates (a rod spinning about its own axis, a point mass on a spherical joint, a
    /// massless leaf link), so Lagrange's impulse equations (7.117) have no unique solution.
    #[error(
        "mass matrix is singular at coordinate {coordinate}: Cholesky pivot {pivot} vs diagonal {diagonal} \
         (a rod, point mass or massless link leaves this coordinate without inertia)"
    )]
    SingularMassMatrix {
        /// The coordinate (column of A) whose pivot vanished.
        coordinate: usize,
        /// The Cholesky pivot found for it.
        pivot: f64,
        /// The diagonal entry A_kk it is compared with.
        diagonal: f64,
    },
    /// A body index does not name a body of the tree.
    #[error("{what}: body index {body} is out of range (the tree has {bodies} bodies)")]
    BodyOutOfRange {
        /// Which input held the index.
        what: &'static str,
        /// The offending index.
        body: usize,
        /// Number of bodies of the tree.
        bodies: usize,
    },
    /// A contact that cannot move along its normal (W_nn = 0) is approaching: no finite
    /// impulse can stop it (e.g. a contact on the fixed base, or two points of one rigid body).
    #[error("contact {contact} is immovable along its normal (W_nn = {w_nn}) while approaching at {u_n} m/s")]
    ContactImmovable {
        /// Index of the contact.
        contact: usize,
        /// Its normal entry of the Delassus matrix.
        w_nn: f64,
        /// Its normal velocity before the impact (negative: approaching).
        u_n: f64,
    },
    /// The input of one contact (or point impulse) of a list was invalid.
    #[error("contact {contact}: {source}")]
    InContact {
        /// Index of the contact (or impulse) in the list.
        contact: usize,
        /// What was wrong with it.
        source: Box<ImpulseError>,
    },
    /// A result would be NaN or infinite although every input is finite: it overflows the
    /// range of f64 (inputs of extreme magnitude).
    #[error("the {quantity} is not representable: it overflows the range of f64 (inputs of extreme magnitude)")]
    NonFiniteResult {
        /// Which output overflowed.
        quantity: &'static str,
    },
    /// The kinematic tree rejected a computation (workspace not updated, wrong lengths...).
    #[error(transparent)]
    Kinematics(#[from] mechanica_kinematics::KinematicsError),
    /// The mass crate rejected a computation (wrong number of body mass properties...).
    #[error(transparent)]
    Mass(#[from] mechanica_mass::MassError),
}

/// Fails with [`ImpulseError::NonFinite`] if `value` is NaN or ±∞.
pub(crate) fn check_finite(what: &'static str, value: f64) -> Result<(), ImpulseError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ImpulseError::NonFinite { what, value })
    }
}

/// Fails with [`ImpulseError::NonFiniteResult`] naming `quantity` if any of the computed
/// `values` is NaN or ±∞.
pub(crate) fn check_result<'a>(
    quantity: &'static str,
    mut values: impl Iterator<Item = &'a f64>,
) -> Result<(), ImpulseError> {
    if values.all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ImpulseError::NonFiniteResult { quantity })
    }
}

/// Fails with [`ImpulseError::NonFinite`] if any entry of `values` is NaN or ±∞.
pub(crate) fn check_all_finite<'a>(
    what: &'static str,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), ImpulseError> {
    for &value in values {
        check_finite(what, value)?;
    }
    Ok(())
}
