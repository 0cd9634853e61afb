//! Forward dynamics: q̈ = A(q)⁻¹ (τ + Σ Q_loads − c(q, q̇) − g(q)) (Lagrange's equations (7.60)
//! solved for the accelerations), by the articulated-body algorithm or by the mass matrix and
//! Cholesky, with an accuracy report; and the mass matrix A(q) (8.28).

use super::{dynamics_mut, mech_dynamics_t, read_coordinates, read_state};
use crate::ffi::boundary::boundary;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_dynamics::{Dynamics, DynamicsError, ForwardDynamics, ForwardMethod, State};

/// The route that produced q̈ (int32_t).
pub type mech_forward_method_t = i32;
/// The articulated-body recursion, O(n), accepted when the inverse dynamics confirms it to the
/// rounding level.
pub const MECH_FORWARD_ARTICULATED_BODY: mech_forward_method_t = 0;
/// The composite-rigid-body mass matrix and Cholesky, O(n³), backward stable at every grading
/// of the inertias; reports the condition of A.
pub const MECH_FORWARD_MASS_MATRIX: mech_forward_method_t = 1;

/// The accuracy report of a forward-dynamics solve. Quantities that the route did not compute
/// read −1 (never NaN).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_forward_report_t {
    /// The route that produced q̈ (a mech_forward_method_t).
    pub method: mech_forward_method_t,
    /// ‖r‖∞ / max(max_k scale_k, λ) with r = τ − RNEA(q, q̇, q̈) the residual of the equations
    /// of motion at the computed q̈, scale_k the magnitude of the terms summed into τ_k and
    /// λ = DBL_MIN: the relative change of the forces that makes q̈ exact, up to the rounding of
    /// the check.
    pub backward_error: f64,
    /// κ∞(A) = ‖A‖∞ ‖A⁻¹‖∞ when the mass matrix was formed (MECH_FORWARD_MASS_MATRIX), else −1.
    pub condition: f64,
    /// A first-order estimate of the ∞-norm error of q̈, ‖A⁻¹‖∞ (‖r‖∞ + ρ) / (1 − n·κ∞·u) with
    /// ρ the rounding estimate of the check, when the mass matrix was formed; else −1. +∞
    /// (HUGE_VAL) when n·κ∞·u ≥ 1/2: A is singular to working precision and q̈ may have no
    /// correct digit. An estimate, not a bound.
    pub error_estimate: f64,
    /// The dampers' dissipation function D = ½ q̇ᵀ C q̇ at the state (W; 2D is the power they
    /// take out of the mechanism).
    pub dissipation: f64,
}

impl mech_forward_report_t {
    /// The report of a solve, −1 standing for what it did not compute.
    fn of(result: &ForwardDynamics) -> Self {
        Self {
            method: match result.method {
                ForwardMethod::ArticulatedBody => MECH_FORWARD_ARTICULATED_BODY,
                ForwardMethod::MassMatrix => MECH_FORWARD_MASS_MATRIX,
            },
            backward_error: result.backward_error,
            condition: result.condition.unwrap_or(-1.0),
            error_estimate: result.error_estimate.unwrap_or(-1.0),
            dissipation: result.dissipation,
        }
    }
}

/// Writes q̈ (n values) for the applied forces `tau` at (`q`, `q_dot`) to `q_ddot_out` by the
/// articulated-body algorithm in O(n), with every load of the dynamics at time 0; when an
/// articulated inertia is singular to working precision it solves by the mass matrix instead.
/// The fast path: no accuracy report, and its backward error grows with the grading of the
/// inertias (about u times the mass ratio); mech_dynamics_forward checks it.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_SINGULAR when A(q) is
/// singular (a coordinate moves no mass) or a dashpot's points coincide;
/// MECH_STATUS_OUT_OF_RANGE when q̈ overflows.
///
/// # Safety
/// `dynamics` must be a live handle not used by another thread during the call; `q`, `q_dot`,
/// `tau` must point to n readable doubles and `q_ddot_out` to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_aba(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    tau: *const f64,
    n: usize,
    q_ddot_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, tau] = unsafe { read_state(d, [q, q_dot, tau], "tau", n) }?;
        let out = OutSlice::new(q_ddot_out, n, "q_ddot_out")?;
        let mut q_ddot = vec![0.0; n];
        d.aba_into(q, q_dot, tau, &mut q_ddot)?;
        // SAFETY: caller's contract.
        unsafe { out.write(&q_ddot) };
        Ok(())
    })
}

/// The shared body of the two reported forward solves.
///
/// # Safety
/// As mech_dynamics_forward.
unsafe fn forward_with(
    dynamics: *mut mech_dynamics_t,
    [q, q_dot, tau]: [*const f64; 3],
    t: f64,
    n: usize,
    q_ddot_out: *mut f64,
    report_out: *mut mech_forward_report_t,
    solve: fn(&mut Dynamics, &State<'_>, &[f64]) -> Result<ForwardDynamics, DynamicsError>,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let [q, q_dot, tau] = unsafe { read_state(d, [q, q_dot, tau], "tau", n) }?;
        finite(&t, "t")?;
        let out = OutSlice::new(q_ddot_out, n, "q_ddot_out")?;
        let report = Out::optional(report_out, "report_out")?;
        let result = solve(d, &State::new(q, q_dot).at_time(t), tau)?;
        let summary = mech_forward_report_t::of(&result);
        // The error estimate alone may be +∞ (A singular to working precision, documented).
        let estimate = if summary.error_estimate == f64::INFINITY {
            0.0
        } else {
            summary.error_estimate
        };
        let numbers = [summary.backward_error, summary.condition, estimate, summary.dissipation];
        finite_result(numbers.as_slice(), "forward-dynamics accuracy report")?;
        // SAFETY: caller's contract.
        unsafe { out.write(&result.q_ddot) };
        if let Some(report) = report {
            // SAFETY: caller's contract.
            unsafe { report.write(summary) };
        }
        Ok(())
    })
}

/// Writes q̈ (n values) for the applied forces `tau` at (`q`, `q_dot`) and time `t` (s) to
/// `q_ddot_out`, and its accuracy report to `*report_out` (may be NULL). The articulated-body
/// recursion's q̈ is checked by the inverse dynamics and accepted when its backward error is
/// at the rounding level of the check, 16·(d + 4)·u (d the depth of the tree), and no joint's
/// articulated pivot is below √u times the inertia of the subtree it moves (then A(q) is
/// ill-conditioned, and a small backward error says nothing of q̈'s accuracy); otherwise the
/// equations are solved by the mass matrix and Cholesky (as mech_dynamics_forward_crba), whose
/// report carries κ∞(A) and the error estimate. `report_out->method` says which.
///
/// Errors: as mech_dynamics_aba, and MECH_STATUS_NON_FINITE for a NaN or infinite `t`.
///
/// # Safety
/// As mech_dynamics_aba; `report_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_forward(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    tau: *const f64,
    t: f64,
    n: usize,
    q_ddot_out: *mut f64,
    report_out: *mut mech_forward_report_t,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe {
        forward_with(
            dynamics,
            [q, q_dot, tau],
            t,
            n,
            q_ddot_out,
            report_out,
            Dynamics::forward_dynamics,
        )
    }
}

/// As mech_dynamics_forward, always by the composite-rigid-body mass matrix A(q) and its
/// Cholesky factor, O(n³): backward stable at every grading of the inertias, and the report
/// gives κ∞(A) and the error estimate of q̈.
///
/// Errors: as mech_dynamics_forward.
///
/// # Safety
/// As mech_dynamics_forward.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_forward_crba(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    q_dot: *const f64,
    tau: *const f64,
    t: f64,
    n: usize,
    q_ddot_out: *mut f64,
    report_out: *mut mech_forward_report_t,
) -> mech_status_t {
    // SAFETY: caller's contract.
    unsafe {
        forward_with(
            dynamics,
            [q, q_dot, tau],
            t,
            n,
            q_ddot_out,
            report_out,
            Dynamics::forward_dynamics_crba,
        )
    }
}

/// Writes the mass matrix A(q) (8.28) at `q` (n values) to `a_out`, n·n doubles in column-major
/// order (symmetric), by the composite-rigid-body recursion: T = ½ q̇ᵀ A q̇ relative to the base
/// frame.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_OUT_OF_RANGE when an
/// entry overflows.
///
/// # Safety
/// `dynamics` must be a live handle not used by another thread during the call; `q` must point
/// to n readable doubles and `a_out` to n·n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_mass_matrix(
    dynamics: *mut mech_dynamics_t,
    q: *const f64,
    n: usize,
    a_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let q = unsafe { read_coordinates(d, q, n, "q") }?;
        let out = OutSlice::new(a_out, square_len(n, "a_out")?, "a_out")?;
        let a = d.mass_matrix(q)?;
        let entries: Vec<f64> = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| a[(i, j)])
            .collect();
        finite_result(entries.as_slice(), "mass matrix")?;
        // SAFETY: caller's contract.
        unsafe { out.write(&entries) };
        Ok(())
    })
}
