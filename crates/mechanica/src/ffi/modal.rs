//! C entry points of the modal-analysis crate.

use super::boundary::{FfiError, boundary};
use super::status::*;
use super::validate::*;
use mechanica_modal::faer::MatRef;
use mechanica_modal::{ModalError, PencilProblem};

impl From<ModalError> for FfiError {
    fn from(error: ModalError) -> Self {
        let status = match error {
            ModalError::BadShape { .. } => MECH_STATUS_BAD_DIMENSION,
            ModalError::NonFinite { .. } => MECH_STATUS_NON_FINITE,
            ModalError::NotSymmetric { .. } => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// Checks that the n×n column-major matrices `a` (mass) and `b` (stiffness) form a valid
/// symmetric pencil for det(λA + B) = 0: finite, and symmetric within 64 ulps of max|entry|.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_check_pencil(n: usize, a: *const f64, b: *const f64) -> mech_status_t {
    boundary(|| {
        let len = square_len(n, "n")?;
        // SAFETY: caller's contract.
        let (a, b) = unsafe { (read_slice(a, len, "a")?, read_slice(b, len, "b")?) };
        PencilProblem::new(
            MatRef::from_column_major_slice(a, n, n),
            MatRef::from_column_major_slice(b, n, n),
        )?;
        Ok(())
    })
}
