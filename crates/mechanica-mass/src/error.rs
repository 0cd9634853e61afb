//! The error type of the mass crate.

use thiserror::Error;

/// What was wrong with which mass-properties input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MassError {
    /// A number that must be finite was NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A mass that must be positive was zero or negative.
    #[error("mass must be positive, got {0}")]
    NonPositiveMass(f64),
}
