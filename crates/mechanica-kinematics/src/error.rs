//! The error type of the kinematics crate.

use thiserror::Error;

/// What was wrong with which kinematic input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// A number that must be finite was NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An entry of an array (a coordinate, a velocity, a body's data) was NaN or infinite.
    #[error("{what}[{index}] is not finite: {value}")]
    NonFiniteEntry {
        /// Which array held the value.
        what: &'static str,
        /// Index of the offending entry (coordinate index, or body index for body data).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix that must be a rotation is not orthogonal with det = +1.
    #[error("matrix is not a rotation: ‖RᵀR − I‖ = {orthogonality_error:.3e}, det = {determinant}")]
    NotARotation {
        /// Frobenius norm of RᵀR − I.
        orthogonality_error: f64,
        /// The determinant of the matrix.
        determinant: f64,
    },
    /// A quaternion that must have unit length does not (or is zero when normalising).
    #[error("quaternion is not usable as a rotation: norm = {norm}")]
    NotAUnitQuaternion {
        /// Its Euclidean norm.
        norm: f64,
    },
    /// An axis that must be a unit vector is not (zero axes have norm 0).
    #[error("{what} is not a unit vector: norm = {norm}")]
    NotAUnitAxis {
        /// Which axis.
        what: &'static str,
        /// Its Euclidean norm.
        norm: f64,
    },
    /// The joint axis of a body in a kinematic tree is zero or not of unit length.
    #[error("joint axis of body {body} is not a unit vector: norm = {norm}")]
    JointAxisNotUnit {
        /// The body whose joint holds the axis.
        body: usize,
        /// Its Euclidean norm.
        norm: f64,
    },
    /// Euler rates cannot be recovered from ω at a gimbal lock of the sequence.
    #[error(
        "Euler-rate inversion is singular for {sequence}: |{measure}| = {distance:.3e} ≤ {tolerance:.1e} (gimbal lock)"
    )]
    EulerRateSingular {
        /// The Euler sequence.
        sequence: &'static str,
        /// The quantity that vanishes at the lock: "cos(second angle)" or "sin(second angle)".
        measure: &'static str,
        /// Its value.
        distance: f64,
        /// The tolerance below which the inversion is refused.
        tolerance: f64,
    },
    /// A kinematic tree was built with no body.
    #[error("the kinematic tree has no bodies")]
    EmptyTree,
    /// A body names a parent index that does not exist.
    #[error("body {body} names parent {parent}, but the tree has only {bodies} bodies")]
    ParentOutOfRange {
        /// The body.
        body: usize,
        /// The parent index it names.
        parent: usize,
        /// The number of bodies.
        bodies: usize,
    },
    /// No body is attached to the base.
    #[error("the kinematic tree has no root (no body is attached to the base)")]
    NoRoot,
    /// More than one body is attached to the base (a forest, i.e. a disconnected tree).
    #[error("the kinematic tree has more than one root: bodies {first} and {second} are both attached to the base")]
    MultipleRoots {
        /// The first root found.
        first: usize,
        /// The second root found.
        second: usize,
    },
    /// Following parents from a body never reaches the root: the body lies on a cycle or
    /// hangs below one, disconnected from the root.
    #[error("body {body} is on or below a cycle of parent links and is not connected to the root")]
    Cycle {
        /// A body on the cycle or in the disconnected part.
        body: usize,
    },
    /// An array has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    WrongLength {
        /// Which array.
        what: &'static str,
        /// The length required.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A body index does not exist.
    #[error("body index {body} is out of range (the tree has {bodies} bodies)")]
    BodyOutOfRange {
        /// The index given.
        body: usize,
        /// The number of bodies.
        bodies: usize,
    },
    /// A result would be NaN or infinite although every input is finite: it overflows the
    /// range of f64 (inputs of extreme magnitude).
    #[error("the {quantity} is not representable: it overflows the range of f64 (inputs of extreme magnitude)")]
    NonFiniteResult {
        /// Which output overflowed.
        quantity: &'static str,
    },
    /// A rotation vector so long that one rounding of its length exceeds a radian: the
    /// rotation it stands for is not determined by any computation in f64.
    #[error(
        "{what} has length {angle:e} rad, above {limit:e} rad: one rounding of the angle exceeds a radian there, so the rotation is not determined"
    )]
    RotationAngleUnresolved {
        /// Which rotation vector.
        what: &'static str,
        /// Its length |φ| (rad).
        angle: f64,
        /// The largest accepted length, [`crate::rotation::ROTATION_VECTOR_LIMIT`].
        limit: f64,
    },
    /// A workspace was used with a tree it was not made for, or before the stage it needs
    /// (positions before velocities before accelerations) was computed.
    #[error("workspace not ready: {what}")]
    WorkspaceNotReady {
        /// What was missing.
        what: &'static str,
    },
}
