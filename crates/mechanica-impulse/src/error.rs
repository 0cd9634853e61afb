//! The error type of the impulse crate.

use thiserror::Error;

/// What was wrong with which impact input.
#[derive(Debug, Clone, PartialEq, Error)]
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
    /// The coefficient of restitution is outside [0, 1].
    #[error("restitution coefficient must lie in [0, 1], got {0}")]
    RestitutionOutOfRange(f64),
}
