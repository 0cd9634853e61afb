//! C entry points of the modal-analysis crate: det(λA + B) = 0 (8.89) on caller matrices,
//! an opaque result handle, and accessors that copy into caller buffers.

use super::boundary::{FfiError, boundary};
use super::c_enum::*;
use super::status::*;
use super::validate::*;
use mechanica_modal::faer::MatRef;
use mechanica_modal::faer::sparse::Triplet;
use mechanica_modal::{
    FreeResponse, Method, ModalError, ModalSolution, Mode, ModeGroup, ModeKind, PencilProblem, Refinement, Residuals,
    Selection, SolveOptions, SparseModalSolution, SparseOptions, SparsePencil, count_below, solve, solve_sparse,
};

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
        };
        FfiError::new(status, error.to_string())
    }
}

/// Which modes a solve returns (int32_t; see MECH_MODAL_SELECTION_*).
pub type mech_modal_selection_t = i32;
/// Every finite mode, plus the infinite (massless) ones when A is singular.
pub const MECH_MODAL_SELECTION_ALL: mech_modal_selection_t = 0;
/// The `count` finite modes of lowest ω² (unstable modes count as lowest).
pub const MECH_MODAL_SELECTION_LOWEST: mech_modal_selection_t = 1;
/// The finite modes with `lower` ≤ ω² ≤ `upper`.
pub const MECH_MODAL_SELECTION_INTERVAL: mech_modal_selection_t = 2;

/// Low-mode refinement policy (int32_t; see MECH_MODAL_REFINEMENT_*).
pub type mech_modal_refinement_t = i32;
/// Refine modes whose reduction bound guarantees fewer than 8 digits (stiff problems).
pub const MECH_MODAL_REFINEMENT_AUTO: mech_modal_refinement_t = 0;
/// Never refine.
pub const MECH_MODAL_REFINEMENT_OFF: mech_modal_refinement_t = 1;
/// Refine every simple finite mode.
pub const MECH_MODAL_REFINEMENT_ALWAYS: mech_modal_refinement_t = 2;

/// Classification of a mode (int32_t; see MECH_MODAL_KIND_*).
pub type mech_modal_kind_t = i32;
/// λ < 0: oscillates at ω = √(−λ) rad/s.
pub const MECH_MODAL_KIND_OSCILLATORY: mech_modal_kind_t = 0;
/// |λ| within its error bound: rigid-body (zero-frequency) mode.
pub const MECH_MODAL_KIND_ZERO: mech_modal_kind_t = 1;
/// λ > 0: unstable equilibrium, growth rate √λ (1/s).
pub const MECH_MODAL_KIND_UNSTABLE: mech_modal_kind_t = 2;
/// Massless direction (A x = 0): infinite frequency.
pub const MECH_MODAL_KIND_INFINITE: mech_modal_kind_t = 3;

/// How the accuracy report measures residuals (int32_t; see MECH_MODAL_RESIDUALS_*).
pub type mech_modal_residuals_t = i32;
/// A X, B X and XᵀAX formed in full: exact backward errors and orthogonality (5n²m flops).
pub const MECH_MODAL_RESIDUALS_EXACT: mech_modal_residuals_t = 0;
/// Gaussian sketches (O(32·n²) flops): each backward error and the orthogonality error (then a
/// bound on ‖XᵀAX − I‖_F) is an upper bound that fails with probability ≤ 1e-12.
pub const MECH_MODAL_RESIDUALS_SKETCHED: mech_modal_residuals_t = 1;

impl CEnum for Residuals {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_MODAL_RESIDUALS_EXACT => Some(Residuals::Exact),
            MECH_MODAL_RESIDUALS_SKETCHED => Some(Residuals::Sketched),
            _ => None,
        }
    }
}

struct SelectionTag(i32);
impl CEnum for SelectionTag {
    fn from_c(raw: i32) -> Option<Self> {
        matches!(
            raw,
            MECH_MODAL_SELECTION_ALL | MECH_MODAL_SELECTION_LOWEST | MECH_MODAL_SELECTION_INTERVAL
        )
        .then_some(SelectionTag(raw))
    }
}

impl CEnum for Refinement {
    fn from_c(raw: i32) -> Option<Self> {
        match raw {
            MECH_MODAL_REFINEMENT_AUTO => Some(Refinement::Auto),
            MECH_MODAL_REFINEMENT_OFF => Some(Refinement::Off),
            MECH_MODAL_REFINEMENT_ALWAYS => Some(Refinement::Always),
            _ => None,
        }
    }
}

/// Options of mech_modal_solve.
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

/// Scalar data of one mode.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_mode_t {
    /// λ of det(λA + B) = 0 (= −ω²); −HUGE_VAL for an infinite mode.
    pub lambda: f64,
    /// ω² = −λ (rad²/s²); +HUGE_VAL for an infinite mode.
    pub omega_sq: f64,
    /// ω (rad/s) for an oscillatory mode, the growth rate √λ (1/s) for an unstable one, 0 for a
    /// zero mode, +HUGE_VAL for an infinite one.
    pub rate: f64,
    /// Bound on |ω²_computed − ω²_exact|.
    pub error_bound: f64,
    /// Backward error η of the pair, or −1 when not available (values only, infinite mode).
    pub backward_error: f64,
    /// A MECH_MODAL_KIND_* value.
    pub kind: mech_modal_kind_t,
    /// Index of the mode's group of equal frequencies (modes of a group are consecutive).
    pub group: usize,
    /// Multiplicity of that group.
    pub multiplicity: usize,
}

/// Summary of the accuracy report of a solve.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_accuracy_t {
    /// ‖A‖_F.
    pub norm_a: f64,
    /// ‖B‖_F.
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
    n: usize,
    problem: PencilProblem,
    solution: ModalSolution,
}

/// Reads the pencil (A, B) of order n from caller column-major arrays.
///
/// # Safety
/// `a` and `b` must each point to n·n readable doubles.
unsafe fn read_pencil(n: usize, a: *const f64, b: *const f64) -> Result<PencilProblem, FfiError> {
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
/// semidefinite) and stiffness matrix `b` (symmetric), with the given options, and stores a new
/// result handle in `*out`. Errors: MECH_STATUS_NOT_POSITIVE_DEFINITE when A is indefinite,
/// MECH_STATUS_SINGULAR when det(λA + B) ≡ 0, MECH_STATUS_INVALID_ARGUMENT for an asymmetric
/// matrix, a bad interval, `vectors` not 0/1 or more modes than exist.
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
/// (probabilistic upper bounds at O(n²) cost, for large all-pairs solves). Errors as
/// mech_modal_solve, and MECH_STATUS_BAD_ENUM for an unknown `residuals`.
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
        let SelectionTag(tag) = enum_value(opts.selection, "options.selection")?;
        let refinement = enum_value(opts.refinement, "options.refinement")?;
        let selection = match tag {
            MECH_MODAL_SELECTION_LOWEST => Selection::Lowest(opts.count),
            MECH_MODAL_SELECTION_INTERVAL => {
                finite(&opts.lower, "options.lower")?;
                finite(&opts.upper, "options.upper")?;
                Selection::Interval {
                    lower: opts.lower,
                    upper: opts.upper,
                }
            }
            _ => Selection::All,
        };
        let vectors = match opts.vectors {
            0 => false,
            1 => true,
            other => {
                return Err(FfiError::new(
                    MECH_STATUS_INVALID_ARGUMENT,
                    format!("options.vectors must be 0 or 1, got {other}"),
                ));
            }
        };
        // SAFETY: caller's contract.
        let problem = unsafe { read_pencil(n, a, b) }?;
        let solution = solve(
            &problem,
            &SolveOptions {
                selection,
                vectors,
                refinement,
                residuals,
            },
        )?;
        let handle = Box::into_raw(Box::new(mech_modal_result_t { n, problem, solution }));
        // SAFETY: `out` was checked writable by the caller's contract.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Frees a result of mech_modal_solve. NULL is accepted and ignored.
///
/// # Safety
/// `result` must be NULL or a handle from mech_modal_solve not yet destroyed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_modal_result_destroy(result: *mut mech_modal_result_t) {
    if !result.is_null() {
        // SAFETY: the handle came from Box::into_raw in mech_modal_solve (caller's contract).
        drop(unsafe { Box::from_raw(result) });
    }
}

/// Returns to the system the working matrices that dense solves keep for the next solve (up to
/// five n×n matrices of the largest recent order; see the README's known limits). The next
/// dense solve allocates afresh. Safe to call at any time, from any thread.
#[unsafe(no_mangle)]
pub extern "C" fn mech_modal_release_scratch() {
    mechanica_modal::release_scratch();
}

/// Borrows the result behind a handle.
///
/// # Safety
/// A non-NULL `result` must be a live handle from mech_modal_solve.
unsafe fn borrow<'a>(result: *const mech_modal_result_t) -> Result<&'a mech_modal_result_t, FfiError> {
    if result.is_null() {
        return Err(FfiError::new(MECH_STATUS_NULL_POINTER, "result is NULL"));
    }
    // SAFETY: non-NULL; live by the caller's contract.
    Ok(unsafe { &*result })
}

fn check_capacity(capacity: usize, needed: usize, what: &str) -> Result<(), FfiError> {
    if capacity < needed {
        return Err(FfiError::new(
            MECH_STATUS_BUFFER_TOO_SMALL,
            format!("{what}: capacity {capacity} < {needed} needed"),
        ));
    }
    Ok(())
}

/// Stores the number of modes in `*modes` and the order n of the pencil in `*dim`.
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
        let r = unsafe { borrow(result) }?;
        let (m_out, d_out) = (Out::new(modes, "modes")?, Out::new(dim, "dim")?);
        // SAFETY: checked writable.
        unsafe {
            m_out.write(r.solution.modes.len());
            d_out.write(r.n);
        }
        Ok(())
    })
}

/// Copies λ_k (= −ω²_k) of every mode, ascending in ω², into `lambda` (capacity ≥ number of
/// modes, else MECH_STATUS_BUFFER_TOO_SMALL and nothing written).
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
        let r = unsafe { borrow(result) }?;
        let m = r.solution.modes.len();
        check_capacity(capacity, m, "lambda")?;
        let out = OutSlice::new(lambda, m, "lambda")?;
        let values: Vec<f64> = r.solution.modes.iter().map(|mode| mode.lambda).collect();
        // SAFETY: checked for m writable elements.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// The C record of a mode, with its group's multiplicity from `groups`.
fn mode_to_c(m: &Mode, groups: &[ModeGroup]) -> mech_modal_mode_t {
    let (kind, rate) = match m.kind {
        ModeKind::Oscillatory { omega } => (MECH_MODAL_KIND_OSCILLATORY, omega),
        ModeKind::Zero => (MECH_MODAL_KIND_ZERO, 0.0),
        ModeKind::Unstable { growth_rate } => (MECH_MODAL_KIND_UNSTABLE, growth_rate),
        ModeKind::Infinite => (MECH_MODAL_KIND_INFINITE, f64::INFINITY),
    };
    mech_modal_mode_t {
        lambda: m.lambda,
        omega_sq: m.omega_sq,
        rate,
        error_bound: m.error_bound,
        backward_error: m.backward_error.unwrap_or(-1.0),
        kind,
        group: m.group,
        multiplicity: groups.get(m.group).map_or(1, |g| g.multiplicity),
    }
}

/// Copies the scalar data of every mode into `modes` (capacity ≥ number of modes).
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
        let r = unsafe { borrow(result) }?;
        let s = &r.solution;
        check_capacity(capacity, s.modes.len(), "modes")?;
        let out = OutSlice::new(modes, s.modes.len(), "modes")?;
        let values: Vec<mech_modal_mode_t> = s.modes.iter().map(|m| mode_to_c(m, &s.groups)).collect();
        // SAFETY: checked for the number of modes.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// Copies the mode shapes as an n × (number of modes) column-major matrix into `x`
/// (capacity ≥ n·modes). Finite modes are A-orthonormal; infinite ones are unit null vectors
/// of A. MECH_STATUS_INVALID_ARGUMENT if the solve was values only.
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
        let r = unsafe { borrow(result) }?;
        let Some(v) = r.solution.vectors.as_ref() else {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "the solve computed values only (options.vectors = 0)",
            ));
        };
        let len = v.nrows() * v.ncols();
        check_capacity(capacity, len, "x")?;
        let out = OutSlice::new(x, len, "x")?;
        let mut values = Vec::with_capacity(len);
        for j in 0..v.ncols() {
            values.extend((0..v.nrows()).map(|i| v[(i, j)]));
        }
        // SAFETY: checked for len writable elements.
        unsafe { out.write(&values) };
        Ok(())
    })
}

/// Copies the accuracy summary of the solve into `*accuracy`.
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
        let r = unsafe { borrow(result) }?;
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

/// Stores in `*below` the number of modes with ω² < `shift`, certified by the inertia of an
/// LBLᵀ factorization of B − shift·A (Sylvester's law; A must be positive definite for the
/// count to equal the number of modes).
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

/// How well the modal coordinates of mech_modal_free_response reproduce the initial state, and
/// the response's own error bound.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_modal_response_fit_t {
    /// ‖δ(0) − Σ q_k(0) x_k‖₂ (m).
    pub displacement_residual: f64,
    /// ‖δ̇(0) − Σ q̇_k(0) x_k‖₂ (m/s).
    pub velocity_residual: f64,
    /// displacement_residual / ‖δ(0)‖₂ (0 when δ(0) = 0).
    pub relative_displacement_residual: f64,
    /// velocity_residual / ‖δ̇(0)‖₂ (0 when δ̇(0) = 0).
    pub relative_velocity_residual: f64,
    /// The largest first-order bound on ‖δ(t) − δ_exact(t)‖₂ over the requested times, from the
    /// error bounds of the frequencies (phase drift) and rounding; excludes the residuals above.
    pub max_error_bound: f64,
    /// Number of massless coordinates (infinite modes); they follow the massive ones statically,
    /// so with massless > 0 the residuals include the inconsistency of δ(0), δ̇(0).
    pub massless: usize,
}

/// The free response of A δ̈ + B δ = 0 (8.91) from δ(0) = `delta0` and δ̇(0) = `delta_dot0`
/// (n each) at `time_count` times `times` (s, any sign): δ(t_j) = Σ_k q_k(t_j) x_k with
/// q = q₀ cos ωt + (q̇₀/ω) sin ωt for oscillatory modes, q₀ + q̇₀t for zero (rigid-body) modes
/// and q₀ cosh γt + (q̇₀/γ) sinh γt for unstable ones; massless coordinates follow statically.
/// `result` must come from mech_modal_solve with MECH_MODAL_SELECTION_ALL and vectors = 1
/// (else MECH_STATUS_INVALID_ARGUMENT). Writes δ(t_j) as column j of the n × time_count
/// column-major `delta_out` (capacity ≥ n·time_count), δ̇(t_j) likewise into `velocity_out`
/// (may be NULL), and the fit summary into `fit_out` (may be NULL). An unstable mode that
/// overflows a double at some t_j gives MECH_STATUS_INVALID_ARGUMENT; nothing is written then.
///
/// # Safety
/// `result` must be a live handle; `delta0`, `delta_dot0` must point to n readable doubles,
/// `times` to `time_count`; `delta_out` to `delta_capacity` writable doubles; `velocity_out`
/// NULL or `velocity_capacity` writable doubles; `fit_out` NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mech_modal_free_response(
    result: *const mech_modal_result_t,
    delta0: *const f64,
    delta_dot0: *const f64,
    times: *const f64,
    time_count: usize,
    delta_out: *mut f64,
    delta_capacity: usize,
    velocity_out: *mut f64,
    velocity_capacity: usize,
    fit_out: *mut mech_modal_response_fit_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let r = unsafe { borrow(result) }?;
        let n = r.n;
        // SAFETY: caller's contract.
        let (d0, v0, ts) = unsafe {
            (
                read_slice(delta0, n, "delta0")?,
                read_slice(delta_dot0, n, "delta_dot0")?,
                read_slice(times, time_count, "times")?,
            )
        };
        finite(d0, "delta0")?;
        finite(v0, "delta_dot0")?;
        finite(ts, "times")?;
        let len = n.checked_mul(time_count).ok_or_else(|| {
            FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("n·time_count = {n}·{time_count} overflows"),
            )
        })?;
        check_capacity(delta_capacity, len, "delta_out")?;
        let d_out = OutSlice::new(delta_out, len, "delta_out")?;
        let v_out = if velocity_out.is_null() {
            None
        } else {
            check_capacity(velocity_capacity, len, "velocity_out")?;
            Some(OutSlice::new(velocity_out, len, "velocity_out")?)
        };
        let f_out = if fit_out.is_null() {
            None
        } else {
            Some(Out::new(fit_out, "fit_out")?)
        };
        let response = FreeResponse::new(&r.problem, &r.solution, d0, v0)?;
        let mut deltas = vec![0.0; len];
        let mut velocities = vec![0.0; if v_out.is_some() { len } else { 0 }];
        let mut max_error_bound = 0.0_f64;
        for (j, &t) in ts.iter().enumerate() {
            response.at(t, &mut deltas[j * n..(j + 1) * n])?;
            if v_out.is_some() {
                response.velocity_at(t, &mut velocities[j * n..(j + 1) * n])?;
            }
            max_error_bound = max_error_bound.max(response.error_bound(t)?);
        }
        let fit = response.fit();
        // SAFETY: checked for len writable elements / writable (caller's contract).
        unsafe {
            d_out.write(&deltas);
            if let Some(v) = v_out {
                v.write(&velocities);
            }
            if let Some(f) = f_out {
                f.write(mech_modal_response_fit_t {
                    displacement_residual: fit.displacement_residual,
                    velocity_residual: fit.velocity_residual,
                    relative_displacement_residual: fit.relative_displacement_residual,
                    relative_velocity_residual: fit.relative_velocity_residual,
                    max_error_bound,
                    massless: fit.massless,
                });
            }
        }
        Ok(())
    })
}

/// Accuracy and cost summary of mech_modal_sparse_lowest.
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

/// Reads one n×n CSC matrix (both triangles) into triplets, checking the column pointers.
///
/// # Safety
/// `col_ptr` must point to n + 1 readable size_t; `row_idx` and `values` to col_ptr[n] elements.
unsafe fn read_csc(
    n: usize,
    col_ptr: *const usize,
    row_idx: *const usize,
    values: *const f64,
    what: &str,
) -> Result<Vec<Triplet<usize, usize, f64>>, FfiError> {
    let len = n
        .checked_add(1)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, "n + 1 overflows"))?;
    // SAFETY: caller's contract.
    let ptr = unsafe { read_slice(col_ptr, len, what) }?;
    if ptr[0] != 0 || ptr.windows(2).any(|w| w[1] < w[0]) {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("{what}: column pointers must start at 0 and not decrease"),
        ));
    }
    let nnz = ptr[n];
    // SAFETY: caller's contract.
    let (rows, vals) = unsafe { (read_slice(row_idx, nnz, what)?, read_slice(values, nnz, what)?) };
    let mut out = Vec::with_capacity(nnz);
    for j in 0..n {
        for p in ptr[j]..ptr[j + 1] {
            out.push(Triplet::new(rows[p], j, vals[p]));
        }
    }
    Ok(out)
}

/// The `count` lowest modes of det(λA + B) = 0 for sparse n×n A (mass, positive semidefinite)
/// and B (stiffness) in compressed sparse columns (0-based, both triangles stored; duplicates are
/// summed): shift-invert block Lanczos on a sparse Cholesky factorization, certified by a sparse
/// inertia count. Writes ω²_k ascending into `omega_sq_out` (count), their error bounds into
/// `error_bound_out` (count, may be NULL), the A-orthonormal shapes as an n × count column-major
/// matrix into `vectors_out` (may be NULL) and the summary into `report_out` (may be NULL).
/// Exactly `count` modes are returned: when `count` cuts through a repeated eigenvalue, only
/// part of its eigenspace is (ask for more to get the whole group). Copies of a repeated
/// eigenvalue missed by the first Lanczos run are found by the inertia count and recovered by
/// deflated reruns; a result is never returned uncertified. Each pair converges until its
/// Ritz residual ‖K⁻¹Ax − θx‖_A ≤ 1e-12·θ (K = B − σA, θ = 1/(ω² − σ)), so its backward
/// error is at most about 1e-12·√κ(A)·‖K‖₂/‖B‖_F (κ(A) the condition number of A); the
/// eigenvalue errors are quadratic in that residual.
/// Errors: BAD_DIMENSION for an index ≥ n, NON_FINITE, INVALID_ARGUMENT for asymmetry, bad
/// column pointers or count ∉ [1, n]; NOT_POSITIVE_DEFINITE when no shift below the spectrum
/// was found (A indefinite); NOT_CONVERGED (also when the reruns run out).
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
        if n == 0 {
            return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "n: dimension is 0"));
        }
        let w_out = OutSlice::new(omega_sq_out, count, "omega_sq_out")?;
        let e_out = OutSlice::optional(error_bound_out, count, "error_bound_out")?;
        let x_out = OutSlice::optional(vectors_out, shapes_len(n, count)?, "vectors_out")?;
        let r_out = Out::optional(report_out, "report_out")?;
        let a = CscInput::new(a_col_ptr, a_row_idx, a_values);
        let b = CscInput::new(b_col_ptr, b_row_idx, b_values);
        let options = SparseOptions {
            count,
            ..SparseOptions::default()
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

/// n·count, the length of the mode shapes' buffer.
fn shapes_len(n: usize, count: usize) -> Result<usize, FfiError> {
    n.checked_mul(count)
        .ok_or_else(|| FfiError::new(MECH_STATUS_BAD_DIMENSION, "n·count overflows"))
}

/// Reads both CSC matrices and runs the sparse solver.
///
/// # Safety
/// As [`read_csc`] for each matrix.
unsafe fn solve_csc(
    n: usize,
    a: CscInput,
    b: CscInput,
    options: &SparseOptions,
) -> Result<SparseModalSolution, FfiError> {
    // SAFETY: caller's contract.
    let (a, b) = unsafe {
        (
            read_csc(n, a.col_ptr, a.row_idx, a.values, "a")?,
            read_csc(n, b.col_ptr, b.row_idx, b.values, "b")?,
        )
    };
    let pencil = SparsePencil::from_triplets(n, &a, &b)?;
    Ok(solve_sparse(&pencil, options)?)
}

/// The n × count mode shapes, column-major; an error if fewer than `count` came back.
fn shapes_of(sol: &SparseModalSolution, n: usize, count: usize) -> Result<Vec<f64>, FfiError> {
    let mut shapes = Vec::with_capacity(sol.vectors.nrows() * sol.vectors.ncols());
    for j in 0..sol.vectors.ncols() {
        shapes.extend((0..n).map(|i| sol.vectors[(i, j)]));
    }
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

/// Options of mech_modal_sparse_solve. Zero fields take the defaults, so a zero-initialised
/// struct with `count` set is the default solve of mech_modal_sparse_lowest.
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

/// [`SparseOptions`] from the C options: zero fields take the defaults; a non-finite or
/// out-of-range tolerance or shift, or a `shift_given` other than 0 and 1, is refused.
fn sparse_options(o: &mech_modal_sparse_options_t) -> Result<SparseOptions, FfiError> {
    let defaults = SparseOptions::default();
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
    Ok(SparseOptions {
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
/// multiplicity. `vectors_out` (n × count, column-major, may be NULL), `report_out` and
/// `details_out` (may be NULL) as named. Errors as mech_modal_sparse_lowest, plus
/// INVALID_ARGUMENT for a tolerance outside [0, 1) or shift_given ∉ {0, 1}, NON_FINITE for a
/// non-finite tolerance or given shift; nothing is written on error.
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
        if n == 0 {
            return Err(FfiError::new(MECH_STATUS_BAD_DIMENSION, "n: dimension is 0"));
        }
        // SAFETY: caller's contract.
        let c_options = unsafe { read(options, "options") }?;
        let options = sparse_options(&c_options)?;
        let count = options.count;
        let m_out = OutSlice::new(modes_out, count, "modes_out")?;
        let x_out = OutSlice::optional(vectors_out, shapes_len(n, count)?, "vectors_out")?;
        let r_out = Out::optional(report_out, "report_out")?;
        let d_out = Out::optional(details_out, "details_out")?;
        let a = CscInput::new(a_col_ptr, a_row_idx, a_values);
        let b = CscInput::new(b_col_ptr, b_row_idx, b_values);
        // SAFETY: caller's contract.
        let sol = unsafe { solve_csc(n, a, b, &options) }?;
        let shapes = shapes_of(&sol, n, count)?;
        let modes: Vec<mech_modal_mode_t> = sol.modes.iter().map(|m| mode_to_c(m, &sol.groups)).collect();
        let r = &sol.report;
        let details = mech_modal_sparse_details_t {
            lanczos_runs: r.lanczos_runs,
            restarts: r.restarts,
            shift_attempts: r.shift_attempts,
            kth_group_multiplicity: r.kth_group_multiplicity,
            factor_seconds: r.timings.factor.as_secs_f64(),
            lanczos_seconds: r.timings.lanczos.as_secs_f64(),
            refine_seconds: r.timings.refine.as_secs_f64(),
            inertia_seconds: r.timings.inertia.as_secs_f64(),
        };
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
                o.write(details);
            }
        }
        Ok(())
    })
}
