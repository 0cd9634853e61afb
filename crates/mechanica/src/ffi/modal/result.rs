//! The opaque result of a dense solve and its accessors, which copy into caller buffers.

use super::column_major;
use super::mode::{mech_modal_mode_t, mode_to_c};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::handle::Handle;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_modal::{Method, ModalSolution, PencilProblem};

/// Summary of the accuracy report of a solve.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_accuracy_t {
    /// ‖A‖_F, or the largest double where the norm exceeds it (a pencil near 1e308).
    pub norm_a: f64,
    /// ‖B‖_F, or the largest double where the norm exceeds it.
    pub norm_b: f64,
    /// Largest backward error η of the pairs, or −1 for values only.
    pub max_backward_error: f64,
    /// max |(XᵀAX − I)_ij| over the finite modes, or −1 for values only.
    pub orthogonality_error: f64,
    /// Largest error bound of the modes (0 when there are none).
    pub max_error_bound: f64,
    /// Number of modes refined with extended-precision residuals.
    pub refined_modes: usize,
    /// 1 when a Sturm (LBLᵀ inertia) check was made.
    pub inertia_checked: i32,
    /// 1 when that check agreed with the computed spectrum.
    pub inertia_consistent: i32,
    /// The check's shift s (ω², rad²/s²).
    pub inertia_shift: f64,
    /// Modes with ω² < s by the inertia of B − sA.
    pub inertia_below: usize,
    /// Modes with ω² < s among the computed ones.
    pub computed_below: usize,
    /// Number of massless directions condensed out (infinite modes).
    pub massless: usize,
}

/// The opaque result of mech_modal_solve. Free it with mech_modal_result_destroy.
pub struct mech_modal_result_t {
    pub(super) n: usize,
    pub(super) problem: PencilProblem,
    pub(super) solution: ModalSolution,
}

impl Handle for mech_modal_result_t {}

/// Frees a result of mech_modal_solve. NULL is accepted and ignored.
///
/// # Safety
/// `result` must be NULL or a handle from mech_modal_solve not yet destroyed; it is invalid
/// afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_destroy(result: *mut mech_modal_result_t) {
    // SAFETY: caller's contract.
    unsafe { mech_modal_result_t::destroy(result) }
}

/// Writes the number of modes of the result to `*modes` and the order n of the pencil to `*dim`.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `result` must be a live handle; `modes` and `dim` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_size(
    result: *const mech_modal_result_t,
    modes: *mut usize,
    dim: *mut usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
        let (m_out, d_out) = (Out::new(modes, "modes")?, Out::new(dim, "dim")?);
        // SAFETY: checked writable.
        unsafe {
            m_out.write(r.solution.modes.len());
            d_out.write(r.n);
        }
        Ok(())
    })
}

/// Copies λ_k = −ω²_k (rad²/s²) of every mode, ascending in ω², into `lambda`; exactly the
/// number of modes (mech_modal_result_size) is written.
///
/// Errors: MECH_STATUS_BUFFER_TOO_SMALL when `capacity` is below the number of modes.
///
/// # Safety
/// `result` must be a live handle; `lambda` must have `capacity` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_eigenvalues(
    result: *const mech_modal_result_t,
    lambda: *mut f64,
    capacity: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
        let m = r.solution.modes.len();
        let out = OutSlice::buffer(lambda, capacity, m, "lambda")?;
        let values: Vec<f64> = r.solution.modes.iter().map(|mode| mode.lambda).collect();
        // SAFETY: checked for m writable elements.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// Copies the scalar record of every mode (λ, ω², rate, error bound, backward error, kind,
/// group and multiplicity), ascending in ω², into `modes`.
///
/// Errors: MECH_STATUS_BUFFER_TOO_SMALL when `capacity` is below the number of modes.
///
/// # Safety
/// `result` must be a live handle; `modes` must have `capacity` writable elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_modes(
    result: *const mech_modal_result_t,
    modes: *mut mech_modal_mode_t,
    capacity: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
        let s = &r.solution;
        let out = OutSlice::buffer(modes, capacity, s.modes.len(), "modes")?;
        let values: Vec<mech_modal_mode_t> = s.modes.iter().map(|m| mode_to_c(m, &s.groups)).collect();
        // SAFETY: checked for the number of modes.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// Copies the mode shapes as an n × (number of modes) column-major matrix into `x`, column k
/// belonging to mode k. Finite modes are A-orthonormal (XᵀAX = I to the reported
/// orthogonality error); infinite ones are unit null vectors of A.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when the solve computed values only;
/// MECH_STATUS_BUFFER_TOO_SMALL when `capacity` < n·modes.
///
/// # Safety
/// `result` must be a live handle; `x` must have `capacity` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_vectors(
    result: *const mech_modal_result_t,
    x: *mut f64,
    capacity: usize,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
        let Some(v) = r.solution.vectors.as_ref() else {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "the solve computed values only (options.vectors = 0)",
            ));
        };
        let len = v.nrows() * v.ncols();
        let out = OutSlice::buffer(x, capacity, len, "x")?;
        let values = column_major(v.as_ref(), v.ncols());
        // SAFETY: checked for len writable elements.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// Copies the accuracy summary of the solve into `*accuracy`: norms, the largest backward
/// error and error bound, the A-orthogonality error, the refined modes and the Sturm inertia
/// check that certifies no mode below its shift was missed.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `result` must be a live handle; `accuracy` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_accuracy(
    result: *const mech_modal_result_t,
    accuracy: *mut mech_modal_accuracy_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
        let out = Out::new(accuracy, "accuracy")?;
        let rep = &r.solution.accuracy;
        let check = rep.inertia_check;
        let summary = mech_modal_accuracy_t {
            norm_a: rep.norm_a,
            norm_b: rep.norm_b,
            max_backward_error: rep.max_backward_error.unwrap_or(-1.0),
            orthogonality_error: rep.orthogonality_error.unwrap_or(-1.0),
            max_error_bound: rep.error_bounds.iter().copied().fold(0.0, f64::max),
            refined_modes: rep.refinement_steps.iter().filter(|&&s| s > 0).count(),
            inertia_checked: i32::from(check.is_some()),
            inertia_consistent: i32::from(check.is_some_and(|c| c.consistent)),
            inertia_shift: check.map_or(0.0, |c| c.count.shift),
            inertia_below: check.map_or(0, |c| c.count.below),
            computed_below: check.map_or(0, |c| c.computed_below),
            massless: match r.solution.method {
                Method::CondensedReduction { massless } => massless,
                Method::CholeskyReduction => 0,
            },
        };
        // SAFETY: checked writable.
        unsafe { out.write(summary) };
        Ok(())
    })
}
