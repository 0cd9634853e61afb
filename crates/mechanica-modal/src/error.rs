//! The error type of the modal crate.

use thiserror::Error;

/// What was wrong with which matrix input, or which step of a solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModalError {
    /// A matrix is not square, or A and B differ in size.
    #[error("{what} has shape {rows}×{cols}, expected {expected}×{expected}")]
    BadShape {
        /// Which matrix.
        what: &'static str,
        /// Its row count.
        rows: usize,
        /// Its column count.
        cols: usize,
        /// The size it should have.
        expected: usize,
    },
    /// An entry is NaN or infinite.
    #[error("{what}[{row}, {col}] is not finite: {value}")]
    NonFinite {
        /// Which matrix.
        what: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix that must be symmetric is not, beyond the stated tolerance.
    #[error(
        "{what} is not symmetric: |{what}[{row}, {col}] − {what}[{col}, {row}]| = {difference:.3e} > {tolerance:.3e}"
    )]
    NotSymmetric {
        /// Which matrix.
        what: &'static str,
        /// Row of the worst entry.
        row: usize,
        /// Column of the worst entry.
        col: usize,
        /// The asymmetry found.
        difference: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
    },
}
