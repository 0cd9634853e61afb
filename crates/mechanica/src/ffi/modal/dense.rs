//! Dense solves of det(λA + B) = 0 on caller column-major matrices: the options, the pencil
//! check, the solve into a result handle, and the certified count of modes below a shift.

use super::result::mech_modal_result_t;
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::handle::Handle;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_modal::faer::MatRef;
use mechanica_modal::{PencilProblem, Refinement, Residuals, Selection, SolveOptions, count_below, solve};

/// Which modes a solve returns (int32_t; see MECH_MODAL_SELECTION_*).
pub type mech_modal_selection_t = i32;
/// Every finite mode, plus the infinite (massless) ones when A is singular.
pub const MECH_MODAL_SELECTION_ALL: mech_modal_selection_t = 0;
/// The `count` finite modes of lowest ω² (unstable modes count as lowest).
pub const MECH_MODAL_SELECTION_LOWEST: mech_modal_selection_t = 1;
/// The finite modes with `lower` ≤ ω² ≤ `upper`.
pub const MECH_MODAL_SELECTION_INTERVAL: mech_modal_selection_t = 2;

/// The selections of [`mech_modal_selection_t`], before their parameters are read.
#[derive(Clone, Copy)]
enum SelectionKind {
    All,
    Lowest,
    Interval,
}

c_enum!(SelectionKind,
    MECH_MODAL_SELECTION_ALL => SelectionKind::All,
    MECH_MODAL_SELECTION_LOWEST => SelectionKind::Lowest,
    MECH_MODAL_SELECTION_INTERVAL => SelectionKind::Interval,
);

/// Low-mode refinement policy (int32_t; see MECH_MODAL_REFINEMENT_*).
pub type mech_modal_refinement_t = i32;
/// Refine modes whose reduction bound guarantees fewer than 8 digits (stiff problems).
pub const MECH_MODAL_REFINEMENT_AUTO: mech_modal_refinement_t = 0;
/// Never refine.
pub const MECH_MODAL_REFINEMENT_OFF: mech_modal_refinement_t = 1;
/// Refine every simple finite mode.
pub const MECH_MODAL_REFINEMENT_ALWAYS: mech_modal_refinement_t = 2;

c_enum!(Refinement,
    MECH_MODAL_REFINEMENT_AUTO => Refinement::Auto,
    MECH_MODAL_REFINEMENT_OFF => Refinement::Off,
    MECH_MODAL_REFINEMENT_ALWAYS => Refinement::Always,
);

/// How the accuracy report measures residuals (int32_t; see MECH_MODAL_RESIDUALS_*).
pub type mech_modal_residuals_t = i32;
/// A X, B X and XᵀAX formed in full: exact backward errors and orthogonality (5n²m flops).
pub const MECH_MODAL_RESIDUALS_EXACT: mech_modal_residuals_t = 0;
/// Gaussian sketches (O(32·n²) flops): each backward error and the orthogonality error (then a
/// bound on ‖XᵀAX − I‖_F) is an upper bound that fails with probability ≤ 1e-12.
pub const MECH_MODAL_RESIDUALS_SKETCHED: mech_modal_residuals_t = 1;

c_enum!(Residuals,
    MECH_MODAL_RESIDUALS_EXACT => Residuals::Exact,
    MECH_MODAL_RESIDUALS_SKETCHED => Residuals::Sketched,
);

/// Options of mech_modal_solve. The pointer is required (NULL gives MECH_STATUS_NULL_POINTER);
/// mech_modal_options_default writes the defaults: every mode, with shapes, automatic
/// refinement.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct mech_modal_options_t {
    /// A MECH_MODAL_SELECTION_* value.
    pub selection: mech_modal_selection_t,
    /// Number of modes for MECH_MODAL_SELECTION_LOWEST (ignored otherwise).
    pub count: usize,
    /// Lower end of ω² (rad²/s²) for MECH_MODAL_SELECTION_INTERVAL (ignored otherwise).
    pub lower: f64,
    /// Upper end of ω² for MECH_MODAL_SELECTION_INTERVAL (ignored otherwise).
    pub upper: f64,
    /// 1: compute mode shapes; 0: values only.
    pub vectors: i32,
    /// A MECH_MODAL_REFINEMENT_* value.
    pub refinement: mech_modal_refinement_t,
}

impl From<&SolveOptions> for mech_modal_options_t {
    fn from(o: &SolveOptions) -> Self {
        let (selection, count, lower, upper) = match o.selection {
            Selection::All => (MECH_MODAL_SELECTION_ALL, 0, 0.0, 0.0),
            Selection::Lowest(count) => (MECH_MODAL_SELECTION_LOWEST, count, 0.0, 0.0),
            Selection::Interval { lower, upper } => (MECH_MODAL_SELECTION_INTERVAL, 0, lower, upper),
        };
        Self {
            selection,
            count,
            lower,
            upper,
            vectors: i32::from(o.vectors),
            refinement: match o.refinement {
                Refinement::Auto => MECH_MODAL_REFINEMENT_AUTO,
                Refinement::Off => MECH_MODAL_REFINEMENT_OFF,
                Refinement::Always => MECH_MODAL_REFINEMENT_ALWAYS,
            },
        }
    }
}

/// Writes the default options of mech_modal_solve to `options_out`: MECH_MODAL_SELECTION_ALL
/// (count, lower and upper 0), vectors = 1, MECH_MODAL_REFINEMENT_AUTO.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `options_out` must point to a writable mech_modal_options_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_options_default(options_out: *mut mech_modal_options_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write((&SolveOptions::default()).into()) };
        Ok(())
    })
}

/// The Rust options of C options and a residual measure: BAD_ENUM for an unknown selection or
/// refinement, NON_FINITE for a NaN or infinite interval end, INVALID_ARGUMENT for `vectors`
/// other than 0 and 1.
fn solve_options(o: &mech_modal_options_t, residuals: Residuals) -> Result<SolveOptions, FfiError> {
    let kind: SelectionKind = enum_value(o.selection, "options.selection")?;
    let refinement = enum_value(o.refinement, "options.refinement")?;
    let selection = match kind {
        SelectionKind::All => Selection::All,
        SelectionKind::Lowest => Selection::Lowest(o.count),
        SelectionKind::Interval => {
            finite(&o.lower, "options.lower")?;
            finite(&o.upper, "options.upper")?;
            Selection::Interval {
                lower: o.lower,
                upper: o.upper,
            }
        }
    };
    let vectors = match o.vectors {
        0 => false,
        1 => true,
        other => {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("options.vectors must be 0 or 1, got {other}"),
            ));
        }
    };
    Ok(SolveOptions {
        selection,
        vectors,
        refinement,
        residuals,
    })
}

/// Reads the pencil (A, B) of order n from caller column-major arrays: BAD_DIMENSION for n = 0
/// or n·n overflowing, NON_FINITE, INVALID_ARGUMENT for an asymmetric matrix.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles.
pub(super) unsafe fn read_pencil(n: usize, a: *const f64, b: *const f64) -> Result<PencilProblem, FfiError> {
    let len = square_len(n, "n")?;
    // SAFETY: caller's contract.
    let (a, b) = unsafe { (read_slice(a, len, "a")?, read_slice(b, len, "b")?) };
    Ok(PencilProblem::new(
        MatRef::from_column_major_slice(a, n, n),
        MatRef::from_column_major_slice(b, n, n),
    )?)
}

/// Checks that the n×n column-major matrices `a` (mass) and `b` (stiffness) form a valid
/// symmetric pencil for det(λA + B) = 0: finite, and symmetric within 64 ulps of max|entry|.
///
/// Errors: MECH_STATUS_BAD_DIMENSION for n = 0 or n·n overflowing; MECH_STATUS_NON_FINITE for
/// a NaN or infinite entry; MECH_STATUS_INVALID_ARGUMENT for an asymmetric matrix.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_check_pencil(n: usize, a: *const f64, b: *const f64) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        unsafe { read_pencil(n, a, b) }?;
        Ok(())
    })
}

/// Solves det(λA + B) = 0 (8.89) for the n×n column-major mass matrix `a` (symmetric positive
/// semidefinite) and stiffness matrix `b` (symmetric), with the given options, and writes a new
/// result handle to `*out`; the caller owns it and frees it with mech_modal_result_destroy. The
/// result carries its accuracy report (mech_modal_result_accuracy): backward errors,
/// A-orthogonality, per-mode error bounds and a Sturm inertia check; the residuals are measured
/// exactly (see mech_modal_solve_with_residuals).
///
/// Errors: MECH_STATUS_BAD_DIMENSION for n = 0 or n·n overflowing; MECH_STATUS_BAD_ENUM for an
/// unknown selection or refinement; MECH_STATUS_NON_FINITE for a NaN or infinite entry or
/// interval end; MECH_STATUS_NOT_POSITIVE_DEFINITE when A is indefinite; MECH_STATUS_SINGULAR
/// when det(λA + B) ≡ 0; MECH_STATUS_INVALID_ARGUMENT for an asymmetric matrix, a bad interval,
/// `vectors` not 0/1 or more modes than exist; MECH_STATUS_NOT_CONVERGED when the eigensolver
/// fails to converge; MECH_STATUS_OUT_OF_RANGE when an ω² or a bound exceeds the largest
/// double.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles; `options` to a readable
/// mech_modal_options_t; `out` to a writable pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_solve(
    n: usize,
    a: *const f64,
    b: *const f64,
    options: *const mech_modal_options_t,
    out: *mut *mut mech_modal_result_t,
) -> mech_status_t {
    // SAFETY: the same contract.
    unsafe { mech_modal_solve_with_residuals(n, a, b, options, MECH_MODAL_RESIDUALS_EXACT, out) }
}

/// mech_modal_solve with a choice of how the accuracy report measures residuals:
/// MECH_MODAL_RESIDUALS_EXACT (what mech_modal_solve does) or MECH_MODAL_RESIDUALS_SKETCHED
/// (probabilistic upper bounds at O(n²) cost, for large all-pairs solves).
///
/// Errors: as mech_modal_solve, and MECH_STATUS_BAD_ENUM for an unknown `residuals`.
///
/// # Safety
/// As mech_modal_solve.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_solve_with_residuals(
    n: usize,
    a: *const f64,
    b: *const f64,
    options: *const mech_modal_options_t,
    residuals: mech_modal_residuals_t,
    out: *mut *mut mech_modal_result_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(out, "out")?;
        let residuals = enum_value(residuals, "residuals")?;
        // SAFETY: caller's contract.
        let opts = unsafe { read(options, "options") }?;
        let options = solve_options(&opts, residuals)?;
        // SAFETY: caller's contract.
        let problem = unsafe { read_pencil(n, a, b) }?;
        let solution = solve(&problem, &options)?;
        let result = mech_modal_result_t { n, problem, solution };
        // SAFETY: `out` was checked writable by the caller's contract.
        unsafe { out.write(result.into_raw()) };
        Ok(())
    })
}

/// Returns to the system the working matrices that dense solves keep for the next solve (up to
/// five n×n matrices of the largest recent order; see the README's known limits). The next
/// dense solve allocates afresh. Safe to call at any time, from any thread.
#[unsafe(no_mangle)]
pub extern "C" fn mech_modal_release_scratch() {
    mechanica_modal::release_scratch();
}

/// Writes to `*below` the number of modes with ω² < `shift` (rad²/s²), certified by the inertia
/// of an LBLᵀ factorization of B − shift·A (Sylvester's law; A must be positive definite for the
/// count to equal the number of modes), formed on the pencil scaled by a power of two so that
/// any finite pencil and shift work. The count is exact for B − shift·A up to its rounding: it
/// can be off only for modes within about n·u·(‖B‖ + |shift|·‖A‖)·‖A⁻¹‖ of the shift. The n×n
/// matrices are column-major.
///
/// Errors: as mech_modal_check_pencil, and MECH_STATUS_NON_FINITE for a NaN or infinite shift.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles; `below` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_count_below(
    n: usize,
    a: *const f64,
    b: *const f64,
    shift: f64,
    below: *mut usize,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(below, "below")?;
        finite(&shift, "shift")?;
        // SAFETY: caller's contract.
        let problem = unsafe { read_pencil(n, a, b) }?;
        let count = count_below(&problem, shift)?;
        // SAFETY: checked writable.
        unsafe { out.write(count.below) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_options_convert_back_to_the_solver_defaults() {
        let mut written = mech_modal_options_t {
            selection: -1,
            count: 7,
            lower: 1.0,
            upper: 2.0,
            vectors: -1,
            refinement: -1,
        };
        // SAFETY: `written` is a writable options struct.
        assert_eq!(unsafe { mech_modal_options_default(&mut written) }, MECH_STATUS_OK);
        let back = solve_options(&written, Residuals::Exact).expect("the defaults are valid");
        assert_eq!(back, SolveOptions::default());
    }
}
