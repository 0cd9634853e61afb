//! C entry points of the modal-analysis crate: det(λA + B) = 0 (8.89) on caller matrices, dense
//! (an opaque result handle with accessors that copy into caller buffers) and sparse (lowest
//! modes into caller buffers), and the free response of a dense result.

use super::boundary::FfiError;
use super::status::*;
use mechanica_modal::ModalError;
use mechanica_modal::faer::MatRef;

mod dense;
mod mode;
mod response;
mod result;
mod sparse;

pub use dense::*;
pub use mode::*;
pub use response::*;
pub use result::*;
pub use sparse::*;

impl From<ModalError> for FfiError {
    fn from(error: ModalError) -> Self {
        let status = match error {
            ModalError::BadShape { .. } | ModalError::BadLength { .. } | ModalError::IndexOutOfRange { .. } => {
                MECH_STATUS_BAD_DIMENSION
            }
            ModalError::NoDefiniteShift { .. } | ModalError::MassNotSemidefinite { .. } => {
                MECH_STATUS_NOT_POSITIVE_DEFINITE
            }
            ModalError::LanczosNoConvergence { .. } => MECH_STATUS_NOT_CONVERGED,
            ModalError::Factorization { .. } => MECH_STATUS_BAD_DIMENSION,
            ModalError::Io { .. } => MECH_STATUS_IO_ERROR,
            ModalError::MatrixMarket { .. } => MECH_STATUS_PARSE_ERROR,
            ModalError::NonFinite { .. } | ModalError::NonFiniteValue { .. } | ModalError::BadShift(_) => {
                MECH_STATUS_NON_FINITE
            }
            ModalError::NotSymmetric { .. }
            | ModalError::BadInterval { .. }
            | ModalError::BadTolerance(_)
            | ModalError::TooManyModes { .. }
            | ModalError::IncompleteSolution { .. }
            | ModalError::ResponseOverflow { .. } => MECH_STATUS_INVALID_ARGUMENT,
            ModalError::IndefiniteMass { .. } => MECH_STATUS_NOT_POSITIVE_DEFINITE,
            ModalError::SingularPencil { .. } => MECH_STATUS_SINGULAR,
            ModalError::NoConvergence { .. } => MECH_STATUS_NOT_CONVERGED,
            ModalError::OutOfRange { .. } => MECH_STATUS_OUT_OF_RANGE,
            // A variant added after this layer was written: its message still says what was wrong.
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// The first `columns` columns of `m` as one column-major array of m.nrows()·columns entries;
/// columns beyond m.ncols() are zero.
pub(crate) fn column_major(m: MatRef<'_, f64>, columns: usize) -> Vec<f64> {
    (0..columns)
        .flat_map(|j| (0..m.nrows()).map(move |i| if j < m.ncols() { m[(i, j)] } else { 0.0 }))
        .collect()
}
