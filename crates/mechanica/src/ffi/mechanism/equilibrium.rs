//! The potential U* of a mechanism with its exact gradient and Hessian, and the search for an
//! equilibrium.

use super::{mech_mechanism_t, mechanism_mut, read_q};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::modal::column_major;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_mechanism::{EquilibriumOptions, MechanismError, Seek, find_equilibrium};

/// U*(q) (J) into `*potential_out`, its gradient ∂(U*)/∂q into `gradient_out` (n values) and,
/// unless `hessian_out` is NULL, its Hessian B = ∂²(U*)/∂q∂q (n×n, column-major), all exact
/// (8.74, 8.85), at the coordinates q (n values; n = the mechanism's dof).
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_NON_FINITE for a NaN or
/// infinite coordinate; MECH_STATUS_INVALID_ARGUMENT when a Hessian is asked at a non-zero
/// rotation vector of a spherical or free joint (its Hessian is exact only at φ = 0);
/// MECH_STATUS_SINGULAR for a spring of rest length > 0 whose ends coincide.
///
/// # Safety
/// `mechanism` must be a live handle; `q` and `gradient_out` must hold n doubles,
/// `hessian_out` n² (or be NULL).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_potential(
    mechanism: *mut mech_mechanism_t,
    q: *const f64,
    n: usize,
    potential_out: *mut f64,
    gradient_out: *mut f64,
    hessian_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        let q = unsafe { read_q(m, q, n, "q") }?;
        let potential = Out::new(potential_out, "potential_out")?;
        let gradient = OutSlice::new(gradient_out, n, "gradient_out")?;
        let hessian = if hessian_out.is_null() {
            None
        } else {
            Some(OutSlice::new(
                hessian_out,
                square_len(n, "hessian_out")?,
                "hessian_out",
            )?)
        };
        let sum = m.potential(q, hessian.is_some())?;
        // SAFETY: caller's contract.
        unsafe {
            potential.write(sum.value);
            gradient.write(&sum.gradient);
            if let (Some(out), Some(h)) = (hessian, sum.hessian) {
                out.write(&column_major(h.as_ref(), n));
            }
        }
        Ok(())
    })
}

/// What an equilibrium search heads for (int32_t; see MECH_SEEK_*).
pub type mech_seek_t = i32;
/// Any equilibrium, stable or not (Newton on grad U* = 0, line search on ‖grad U*‖).
pub const MECH_SEEK_STATIONARY: mech_seek_t = 0;
/// A local minimum of U* (a stable equilibrium).
pub const MECH_SEEK_MINIMUM: mech_seek_t = 1;

c_enum!(Seek, MECH_SEEK_STATIONARY => Seek::Stationary, MECH_SEEK_MINIMUM => Seek::Minimum);

/// The report of an equilibrium search.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_equilibrium_report_t {
    /// U* at the equilibrium (J).
    pub potential: f64,
    /// ‖grad U*‖ at the equilibrium.
    pub gradient_norm: f64,
    /// The tolerance used.
    pub tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Length of the last Newton step (an estimate of the distance to the exact equilibrium).
    pub last_step: f64,
    /// Number of coordinates resting on a joint limit.
    pub at_limit: usize,
}

/// Searches an equilibrium (grad U* = 0, or a minimum of U* per `seek`, a mech_seek_t) from
/// `q0` (n values) and writes it to `q_out` (n values) with its report (U*, ‖grad U*‖ and the
/// tolerance it met, iterations, last step) to `report_out`. `max_iterations` 0 means the
/// default (100); `tolerance` ≤ 0 means the default derived from rounding. Spherical and free
/// joints are re-centred during the search: the result is in the mechanism's new chart (bodies
/// do not move).
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_BAD_ENUM for an unknown
/// `seek`; MECH_STATUS_NON_FINITE for a NaN or infinite input or a potential or gradient that
/// overflows at the point found; MECH_STATUS_NOT_CONVERGED when
/// the search fails, in which case `q_out` still receives the best point found and
/// `report_out` its gradient norm (potential and last step NaN), so the caller can inspect it.
///
/// # Safety
/// `mechanism` must be a live handle; `q0` and `q_out` must hold n doubles; `report_out`
/// must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_mechanism_equilibrium(
    mechanism: *mut mech_mechanism_t,
    q0: *const f64,
    n: usize,
    seek: mech_seek_t,
    max_iterations: usize,
    tolerance: f64,
    q_out: *mut f64,
    report_out: *mut mech_equilibrium_report_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let m = unsafe { mechanism_mut(mechanism) }?;
        // SAFETY: caller's contract.
        let q0 = unsafe { read_q(m, q0, n, "q0") }?.to_vec();
        let seek: Seek = enum_value(seek, "seek")?;
        finite(&tolerance, "tolerance")?;
        let q_out = OutSlice::new(q_out, n, "q_out")?;
        let report_out = Out::new(report_out, "report_out")?;
        let options = EquilibriumOptions {
            max_iterations: if max_iterations == 0 { 100 } else { max_iterations },
            tolerance: (tolerance > 0.0).then_some(tolerance),
            seek,
            ..EquilibriumOptions::default()
        };
        match find_equilibrium(m, &q0, &options) {
            Ok(eq) => {
                let scalars = [eq.potential, eq.gradient_norm, eq.tolerance, eq.last_step];
                finite(&scalars[..], "equilibrium report (overflow)")?;
                finite(&eq.q[..], "equilibrium coordinates")?;
                let report = mech_equilibrium_report_t {
                    potential: eq.potential,
                    gradient_norm: eq.gradient_norm,
                    tolerance: eq.tolerance,
                    iterations: eq.iterations,
                    last_step: eq.last_step,
                    at_limit: eq.at_limit.len(),
                };
                // SAFETY: caller's contract.
                unsafe {
                    q_out.write(&eq.q);
                    report_out.write(report);
                }
                Ok(())
            }
            Err(MechanismError::NoEquilibrium {
                iterations,
                gradient_norm,
                tolerance,
                best_q,
            }) => {
                let report = mech_equilibrium_report_t {
                    potential: f64::NAN,
                    gradient_norm,
                    tolerance,
                    iterations,
                    last_step: f64::NAN,
                    at_limit: 0,
                };
                // SAFETY: caller's contract.
                unsafe {
                    q_out.write(&best_q);
                    report_out.write(report);
                }
                Err(FfiError::new(
                    MECH_STATUS_NOT_CONVERGED,
                    format!(
                        "equilibrium search did not converge: best |grad U*| = {gradient_norm:.3e} (tolerance {tolerance:.3e}); the best point was written to q_out"
                    ),
                ))
            }
            Err(other) => Err(other.into()),
        }
    })
}
