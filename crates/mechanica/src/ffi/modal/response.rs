//! The free response of A δ̈ + B δ = 0 from a dense result: displacements and velocities at
//! caller times, with how well the modes reproduce the initial state.

use super::result::mech_modal_result_t;
use crate::ffi::boundary::boundary;
use crate::ffi::handle::Handle;
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_modal::FreeResponse;

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
/// (n each, in the coordinates of the pencil) at `time_count` times `times` (s, any sign):
/// δ(t_j) = Σ_k q_k(t_j) x_k with q = q₀ cos ωt + (q̇₀/ω) sin ωt for oscillatory modes,
/// q₀ + q̇₀t for zero (rigid-body) modes and q₀ cosh γt + (q̇₀/γ) sinh γt for unstable ones;
/// massless coordinates follow statically. Writes δ(t_j) as column j of the n × time_count
/// column-major `delta_out`, δ̇(t_j) likewise into `velocity_out` (may be NULL), and the fit
/// summary with the response's error bound into `fit_out` (may be NULL).
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT when `result` does not come from mech_modal_solve with
/// MECH_MODAL_SELECTION_ALL and vectors = 1, or when an unstable mode overflows a double at
/// some t_j; MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_BAD_DIMENSION when
/// n·time_count overflows; MECH_STATUS_BUFFER_TOO_SMALL when `delta_capacity` (or, for a
/// non-NULL `velocity_out`, `velocity_capacity`) is below n·time_count. Nothing is written on
/// error.
///
/// # Safety
/// `result` must be a live handle; `delta0`, `delta_dot0` must point to n readable doubles,
/// `times` to `time_count`; `delta_out` to `delta_capacity` writable doubles; `velocity_out`
/// NULL or `velocity_capacity` writable doubles; `fit_out` NULL or writable.
#[unsafe(no_mangle)]
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
        let r = unsafe { mech_modal_result_t::borrow(result, "result") }?;
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
        let len = product(n, time_count, "n·time_count")?;
        let d_out = OutSlice::buffer(delta_out, delta_capacity, len, "delta_out")?;
        let v_out = OutSlice::optional_buffer(velocity_out, velocity_capacity, len, "velocity_out")?;
        let f_out = Out::optional(fit_out, "fit_out")?;
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
