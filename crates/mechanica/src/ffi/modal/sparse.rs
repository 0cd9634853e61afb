//! Sparse solves of det(λA + B) = 0 on caller matrices in compressed sparse columns: the lowest
//! modes by shift-invert block Lanczos, certified by a sparse inertia count.

use super::column_major;
use super::mode::{mech_modal_mode_t, mode_to_c};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_modal::faer::sparse::Triplet;
use mechanica_modal::{SparseModalSolution, SparsePencil, SparseSolveOptions, solve_sparse};

/// Accuracy and cost summary of mech_modal_sparse_lowest and mech_modal_sparse_solve.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_sparse_report_t {
    /// The shift σ of the factored B − σA (every mode lies above it); −HUGE_VAL on the dense path.
    pub shift: f64,
    /// Largest backward error η of the returned pairs.
    pub max_backward_error: f64,
    /// max |(XᵀAX − I)_ij| of the returned mode shapes.
    pub orthogonality_error: f64,
    /// The shift τ of the inertia (Sturm) check.
    pub inertia_shift: f64,
    /// Modes with ω² < τ by the inertia of B − τA.
    pub inertia_below: usize,
    /// Modes with ω² < τ among the computed ones.
    pub computed_below: usize,
    /// 1 when the two counts agree (no mode below τ missed).
    pub inertia_consistent: i32,
    /// Applications of (B − σA)⁻¹A.
    pub operator_applications: usize,
    /// Stored entries of the Cholesky factor of B − σA.
    pub factor_nnz: usize,
}

/// One caller CSC matrix (0-based, both triangles; see [`read_csc`]).
#[derive(Clone, Copy)]
struct CscInput {
    col_ptr: *const usize,
    row_idx: *const usize,
    values: *const f64,
}

impl CscInput {
    fn new(col_ptr: *const usize, row_idx: *const usize, values: *const f64) -> Self {
        Self {
            col_ptr,
            row_idx,
            values,
        }
    }
}

/// Reads one n×n CSC matrix (both triangles) into triplets, checking the column pointers
/// (INVALID_ARGUMENT unless they start at 0 and do not decrease).
///
/// # Safety
/// `m.col_ptr` must point to n + 1 readable size_t; `m.row_idx` and `m.values` to col_ptr[n]
/// elements.
unsafe fn read_csc(n: usize, m: CscInput, what: &str) -> Result<Vec<Triplet<usize, usize, f64>>, FfiError> {
    let len = n
        .checked_add(1)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, "n + 1 overflows"))?;
    // SAFETY: caller's contract.
    let ptr = unsafe { read_slice(m.col_ptr, len, what) }?;
    if ptr[0] != 0 || ptr.windows(2).any(|w| w[1] < w[0]) {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what}: column pointers must start at 0 and not decrease"),
        ));
    }
    let nnz = ptr[n];
    // SAFETY: caller's contract.
    let (rows, vals) = unsafe { (read_slice(m.row_idx, nnz, what)?, read_slice(m.values, nnz, what)?) };
    let mut out = Vec::with_capacity(nnz);
    for j in 0..n {
        for p in ptr[j]..ptr[j + 1] {
            out.push(Triplet::new(rows[p], j, vals[p]));
        }
    }
    Ok(out)
}

/// Reads both CSC matrices and runs the sparse solver.
///
/// # Safety
/// As [`read_csc`] for each matrix.
unsafe fn solve_csc(
    n: usize,
    a: CscInput,
    b: CscInput,
    options: &SparseSolveOptions,
) -> Result<SparseModalSolution, FfiError> {
    // SAFETY: caller's contract.
    let (a, b) = unsafe { (read_csc(n, a, "a")?, read_csc(n, b, "b")?) };
    let pencil = SparsePencil::from_triplets(n, &a, &b)?;
    Ok(solve_sparse(&pencil, options)?)
}

/// The n × count mode shapes, column-major; NOT_CONVERGED if fewer than `count` came back.
fn shapes_of(sol: &SparseModalSolution, n: usize, count: usize) -> Result<Vec<f64>, FfiError> {
    let shapes = column_major(sol.vectors.as_ref(), sol.vectors.ncols());
    if sol.modes.len() != count || shapes.len() != n * count {
        return Err(FfiError::new(
            MECH_STATUS_NOT_CONVERGED,
            "fewer modes than requested were found",
        ));
    }
    Ok(shapes)
}

/// The C summary of a sparse solve.
fn sparse_report(sol: &SparseModalSolution) -> mech_modal_sparse_report_t {
    let r = &sol.report;
    mech_modal_sparse_report_t {
        shift: r.shift,
        max_backward_error: r.max_backward_error,
        orthogonality_error: r.orthogonality_error,
        inertia_shift: r.inertia.map_or(0.0, |c| c.count.shift),
        inertia_below: r.inertia.map_or(0, |c| c.count.below),
        computed_below: r.computed_below,
        inertia_consistent: i32::from(r.consistent),
        operator_applications: r.operator_applications,
        factor_nnz: r.factor_nnz,
    }
}

/// Fails with BAD_DIMENSION for a pencil of order 0.
fn check_order(n: usize) -> Result<(), FfiError> {
    if n == 0 {
        return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "n: dimension is 0"));
    }
    Ok(())
}

/// The `count` lowest modes of det(λA + B) = 0 for sparse n×n A (mass, positive semidefinite)
/// and B (stiffness) in compressed sparse columns (0-based, both triangles stored; duplicates are
/// summed): shift-invert block Lanczos on a sparse Cholesky factorization, certified by a sparse
/// inertia count. Writes ω²_k (rad²/s²) ascending into `omega_sq_out` (count), their error
/// bounds into `error_bound_out` (count, may be NULL), the A-orthonormal shapes as an n × count
/// column-major matrix into `vectors_out` (may be NULL) and the accuracy summary into
/// `report_out` (may be NULL). Exactly `count` modes are returned: when `count` cuts through a
/// repeated eigenvalue, only part of its eigenspace is (ask for more to get the whole group).
/// Copies of a repeated eigenvalue missed by the first Lanczos run are found by the inertia
/// count and recovered by deflated reruns; a result is never returned uncertified. Each pair
/// converges until its Ritz residual ‖K⁻¹Ax − θx‖_A ≤ 1e-12·θ (K = B − σA, θ = 1/(ω² − σ)), so
/// its backward error is at most about 1e-12·√κ(A)·‖K‖₂/‖B‖_F (κ(A) the condition number of
/// A); the eigenvalue errors are quadratic in that residual.
///
/// Errors: MECH_STATUS_BAD_DIMENSION for n = 0 or an index ≥ n; MECH_STATUS_NON_FINITE;
/// MECH_STATUS_INVALID_ARGUMENT for asymmetry, bad column pointers or count ∉ [1, n];
/// MECH_STATUS_NOT_POSITIVE_DEFINITE when no shift below the spectrum was found (A indefinite);
/// MECH_STATUS_NOT_CONVERGED (also when the reruns run out); MECH_STATUS_OUT_OF_RANGE when
/// ‖A‖_F or ‖B‖_F exceeds the largest double. Nothing is written on error.
///
/// # Safety
/// Each `*_col_ptr` must point to n + 1 readable size_t, each `*_row_idx` / `*_values` to
/// `*_col_ptr[n]` elements; outputs NULL (where allowed) or writable for the sizes above.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mech_modal_sparse_lowest(
    n: usize,
    a_col_ptr: *const usize,
    a_row_idx: *const usize,
    a_values: *const f64,
    b_col_ptr: *const usize,
    b_row_idx: *const usize,
    b_values: *const f64,
    count: usize,
    omega_sq_out: *mut f64,
    error_bound_out: *mut f64,
    vectors_out: *mut f64,
    report_out: *mut mech_modal_sparse_report_t,
) -> mech_status_t {
    boundary(|| {
        check_order(n)?;
        let w_out = OutSlice::new(omega_sq_out, count, "omega_sq_out")?;
        let e_out = OutSlice::optional(error_bound_out, count, "error_bound_out")?;
        let x_out = OutSlice::optional(vectors_out, product(n, count, "n·count")?, "vectors_out")?;
        let r_out = Out::optional(report_out, "report_out")?;
        let a = CscInput::new(a_col_ptr, a_row_idx, a_values);
        let b = CscInput::new(b_col_ptr, b_row_idx, b_values);
        let options = SparseSolveOptions {
            count,
            ..SparseSolveOptions::default()
        };
        // SAFETY: caller's contract.
        let sol = unsafe { solve_csc(n, a, b, &options) }?;
        let omega: Vec<f64> = sol.modes.iter().map(|m| m.omega_sq).collect();
        let bounds: Vec<f64> = sol.modes.iter().map(|m| m.error_bound).collect();
        let shapes = shapes_of(&sol, n, count)?;
        let report = sparse_report(&sol);
        // SAFETY: checked writable for the sizes above (caller's contract).
        unsafe {
            w_out.write(&omega);
            if let Some(e) = e_out {
                e.write(&bounds);
            }
            if let Some(x) = x_out {
                x.write(&shapes);
            }
            if let Some(o) = r_out {
                o.write(report);
            }
        }
        Ok(())
    })
}

/// Options of mech_modal_sparse_solve. The pointer is required (NULL gives
/// MECH_STATUS_NULL_POINTER), as `count` has no meaningful default. Zero fields other than
/// `count` take the defaults, so a zero-initialised struct with `count` set is the default
/// solve of mech_modal_sparse_lowest; mech_modal_sparse_options_default writes the defaults
/// explicitly.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_sparse_options_t {
    /// Number of lowest modes wanted (1 ≤ count ≤ n).
    pub count: usize,
    /// Each wanted pair converges until its Ritz residual ‖K⁻¹Ax − θx‖_A ≤ tolerance·θ
    /// (in (0, 1)); 0: 1e-12.
    pub tolerance: f64,
    /// Block size of the block Lanczos iteration (an eigenvalue of up to this multiplicity is
    /// seen in one run); 0: 2.
    pub block_size: usize,
    /// Lanczos runs allowed (the first plus deflated reruns for modes the inertia count shows
    /// missing); 0: the default (6). When exhausted: MECH_STATUS_NOT_CONVERGED.
    pub max_runs: usize,
    /// 1: `shift` is the factorization shift σ (below the lowest mode); 0: automatic.
    pub shift_given: i32,
    /// σ (rad²/s²) when `shift_given` is 1.
    pub shift: f64,
}

impl From<&SparseSolveOptions> for mech_modal_sparse_options_t {
    fn from(o: &SparseSolveOptions) -> Self {
        Self {
            count: o.count,
            tolerance: o.tolerance,
            block_size: o.block_size,
            max_runs: o.max_runs,
            shift_given: i32::from(o.shift.is_some()),
            shift: o.shift.unwrap_or(0.0),
        }
    }
}

/// Writes the default options of mech_modal_sparse_solve to `options_out`: count 10, tolerance
/// 1e-12, block size 2, 6 Lanczos runs, automatic shift (shift_given = 0, shift = 0). Set
/// `count` to the number of modes wanted before solving.
///
/// Errors: none beyond the pointer checks.
///
/// # Safety
/// `options_out` must point to a writable mech_modal_sparse_options_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_sparse_options_default(
    options_out: *mut mech_modal_sparse_options_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write((&SparseSolveOptions::default()).into()) };
        Ok(())
    })
}

/// What a sparse solve did beyond mech_modal_sparse_report_t (a separate struct, so that the
/// report's layout never changes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_sparse_details_t {
    /// Lanczos runs (1, plus one per deflated rerun for missed copies of a repeated eigenvalue).
    pub lanczos_runs: usize,
    /// Thick restarts over all runs.
    pub restarts: usize,
    /// Shifts tried until B − σA was positive definite.
    pub shift_attempts: usize,
    /// Multiplicity of the count-th mode's eigenvalue: larger than the copies returned when
    /// `count` cuts through a repeated eigenvalue (every copy lies below the certified shift).
    pub kth_group_multiplicity: usize,
    /// Wall time of the factorization of B − σA (s).
    pub factor_seconds: f64,
    /// Wall time of the Lanczos runs (s).
    pub lanczos_seconds: f64,
    /// Wall time of Rayleigh–Ritz and the residual bounds (s).
    pub refine_seconds: f64,
    /// Wall time of the inertia count (s; partly overlapped with Lanczos on a second thread).
    pub inertia_seconds: f64,
}

/// The C details of a sparse solve.
fn sparse_details(sol: &SparseModalSolution) -> mech_modal_sparse_details_t {
    let r = &sol.report;
    mech_modal_sparse_details_t {
        lanczos_runs: r.lanczos_runs,
        restarts: r.restarts,
        shift_attempts: r.shift_attempts,
        kth_group_multiplicity: r.kth_group_multiplicity,
        factor_seconds: r.timings.factor.as_secs_f64(),
        lanczos_seconds: r.timings.lanczos.as_secs_f64(),
        refine_seconds: r.timings.refine.as_secs_f64(),
        inertia_seconds: r.timings.inertia.as_secs_f64(),
    }
}

/// [`SparseSolveOptions`] from the C options: zero fields take the defaults; a non-finite or
/// out-of-range tolerance or shift, or a `shift_given` other than 0 and 1, is refused.
fn sparse_options(o: &mech_modal_sparse_options_t) -> Result<SparseSolveOptions, FfiError> {
    let defaults = SparseSolveOptions::default();
    if !o.tolerance.is_finite() || (o.shift_given == 1 && !o.shift.is_finite()) {
        return Err(FfiError::new(
            MECH_STATUS_NON_FINITE,
            "tolerance or shift is not finite",
        ));
    }
    let shift = match o.shift_given {
        0 => None,
        1 => Some(o.shift),
        other => {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                format!("shift_given is {other}, expected 0 or 1"),
            ));
        }
    };
    let nonzero = |value: usize, default: usize| if value == 0 { default } else { value };
    Ok(SparseSolveOptions {
        count: o.count,
        shift,
        tolerance: if o.tolerance == 0.0 {
            defaults.tolerance
        } else {
            o.tolerance
        },
        block_size: nonzero(o.block_size, defaults.block_size),
        max_runs: nonzero(o.max_runs, defaults.max_runs),
        ..defaults
    })
}

/// The `options->count` lowest modes of det(λA + B) = 0 for sparse A and B in compressed sparse
/// columns, as mech_modal_sparse_lowest, with options (tolerance, block size, runs, shift) and
/// the full record of each mode: `modes_out` (count) receives λ, ω², the rate, the error bound,
/// the backward error, the MECH_MODAL_KIND_* classification (zero when |ω²| is within its
/// bound or within what the rounding of A and B can change), the group index and the group's
/// multiplicity. `vectors_out` (n × count, column-major, may be NULL), `report_out` (the
/// accuracy summary) and `details_out` (may be NULL) as named.
///
/// Errors: as mech_modal_sparse_lowest, plus MECH_STATUS_INVALID_ARGUMENT for a tolerance
/// outside [0, 1) or shift_given ∉ {0, 1}, MECH_STATUS_NON_FINITE for a non-finite tolerance or
/// given shift. Nothing is written on error.
///
/// # Safety
/// As mech_modal_sparse_lowest; `options` must point to a readable struct.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mech_modal_sparse_solve(
    n: usize,
    a_col_ptr: *const usize,
    a_row_idx: *const usize,
    a_values: *const f64,
    b_col_ptr: *const usize,
    b_row_idx: *const usize,
    b_values: *const f64,
    options: *const mech_modal_sparse_options_t,
    modes_out: *mut mech_modal_mode_t,
    vectors_out: *mut f64,
    report_out: *mut mech_modal_sparse_report_t,
    details_out: *mut mech_modal_sparse_details_t,
) -> mech_status_t {
    boundary(|| {
        check_order(n)?;
        // SAFETY: caller's contract.
        let c_options = unsafe { read(options, "options") }?;
        let options = sparse_options(&c_options)?;
        let count = options.count;
        let m_out = OutSlice::new(modes_out, count, "modes_out")?;
        let x_out = OutSlice::optional(vectors_out, product(n, count, "n·count")?, "vectors_out")?;
        let r_out = Out::optional(report_out, "report_out")?;
        let d_out = Out::optional(details_out, "details_out")?;
        let a = CscInput::new(a_col_ptr, a_row_idx, a_values);
        let b = CscInput::new(b_col_ptr, b_row_idx, b_values);
        // SAFETY: caller's contract.
        let sol = unsafe { solve_csc(n, a, b, &options) }?;
        let shapes = shapes_of(&sol, n, count)?;
        let modes: Vec<mech_modal_mode_t> = sol.modes.iter().map(|m| mode_to_c(m, &sol.groups)).collect();
        // SAFETY: checked writable for the sizes above (caller's contract).
        unsafe {
            m_out.write(&modes);
            if let Some(x) = x_out {
                x.write(&shapes);
            }
            if let Some(o) = r_out {
                o.write(sparse_report(&sol));
            }
            if let Some(o) = d_out {
                o.write(sparse_details(&sol));
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_options_convert_back_to_the_solver_defaults() {
        let mut written = mech_modal_sparse_options_t::default();
        // SAFETY: `written` is a writable options struct.
        assert_eq!(
            unsafe { mech_modal_sparse_options_default(&mut written) },
            MECH_STATUS_OK
        );
        assert_eq!(sparse_options(&written), Ok(SparseSolveOptions::default()));
        assert_eq!(written.count, 10);
        assert_eq!(written.shift_given, 0);
    }
}
