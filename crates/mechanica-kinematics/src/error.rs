//! The error type of the kinematics crate.

use thiserror::Error;

/// What was wrong with which kinematic input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum KinematicsError {
    /// A number that must be finite was NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
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
}
