//! Damped and gyroscopic small oscillations about a configuration q₀:
//! det(s²A + s(C + G) + B) = 0 (FM 4.62–4.66, §8e, §8g) by the certified quadratic eigensolver,
//! one plain record per mode.

use super::{dynamics_mut, mech_dynamics_t, read_coordinates};
use crate::ffi::boundary::{FfiError, boundary};
use crate::ffi::status::*;
use crate::ffi::validate::*;
use mechanica_modal::{QuadraticEigenvalue, QuadraticMode, QuadraticModeKind, QuadraticModes, QuadraticOptions};

/// What a damped mode is physically (int32_t; see MECH_DAMPED_KIND_*).
pub type mech_damped_kind_t = i32;
/// A conjugate pair s = σ ± iω, σ < 0 and ω ≠ 0 beyond their bounds: a decaying oscillation.
pub const MECH_DAMPED_KIND_UNDERDAMPED: mech_damped_kind_t = 0;
/// Two real negative roots separated by their bounds: decay without oscillation.
pub const MECH_DAMPED_KIND_OVERDAMPED: mech_damped_kind_t = 1;
/// Decaying, but the bounds cannot tell a double real root from a complex pair or two close
/// real roots (critical damping within the accuracy).
pub const MECH_DAMPED_KIND_CRITICAL: mech_damped_kind_t = 2;
/// s = 0 within its bound: a rigid-body or neutrally stable direction.
pub const MECH_DAMPED_KIND_RIGID: mech_damped_kind_t = 3;
/// Re s greater than its bound: the motion grows.
pub const MECH_DAMPED_KIND_UNSTABLE: mech_damped_kind_t = 4;
/// Re s = 0 within its bound and ω ≠ 0: an undamped (conservative or gyroscopic) oscillation.
pub const MECH_DAMPED_KIND_NEUTRAL: mech_damped_kind_t = 5;
/// A single real negative root: first-order decay (a damper on a massless coordinate).
pub const MECH_DAMPED_KIND_RELAXATION: mech_damped_kind_t = 6;
/// An infinite eigenvalue: a massless direction (A x = 0).
pub const MECH_DAMPED_KIND_INFINITE: mech_damped_kind_t = 7;
/// The bound contains points of more than one kind: the accuracy does not decide.
pub const MECH_DAMPED_KIND_UNDECIDED: mech_damped_kind_t = 8;

/// One damped mode: one or two eigenvalues s of det(s²A + s(C + G) + B) = 0 with their
/// accuracy. Every field is finite.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_damped_mode_t {
    /// A MECH_DAMPED_KIND_* value.
    pub kind: mech_damped_kind_t,
    /// Undamped natural frequency ω_n = √|s₁s₂| (|s| for a conjugate pair or a single root,
    /// rad/s); −1 for an infinite mode.
    pub natural_frequency: f64,
    /// Damped frequency |Im s| (rad/s); 0 for real roots and infinite modes.
    pub damped_frequency: f64,
    /// Damping ratio ζ = −(s₁ + s₂)/(2ω_n) (−σ/|s| for a conjugate pair or a single root); −1
    /// when it is not defined (ω_n = 0 or an infinite mode). A growing mode may have a genuine
    /// negative ζ: read `kind` before reading −1 as "undefined".
    pub damping_ratio: f64,
    /// Re s of the mode's eigenvalues (1/s): the conjugate pair with Im s > 0 first, or the two
    /// real roots; a single eigenvalue is repeated in both entries. 0 for an infinite
    /// eigenvalue.
    pub s_re: [f64; 2],
    /// Im s of the mode's eigenvalues (rad/s), as `s_re`.
    pub s_im: [f64; 2],
    /// Bound on |s_computed − s_exact| of each eigenvalue for the matrices A, C + G, B formed
    /// at q₀ (first-order η κ |s|, or a cluster bound for close roots); for an infinite
    /// eigenvalue a bound on |1/s| of the exact one.
    pub error_bound: [f64; 2],
    /// Backward error η of each eigenvalue (Tisseur's, relative to the coefficients).
    pub backward_error: [f64; 2],
    /// Number of distinct eigenvalues of the mode (1 or 2).
    pub eigenvalue_count: i32,
}

/// The C kind of a damped mode.
fn kind_to_c(kind: QuadraticModeKind) -> mech_damped_kind_t {
    match kind {
        QuadraticModeKind::Underdamped => MECH_DAMPED_KIND_UNDERDAMPED,
        QuadraticModeKind::Overdamped => MECH_DAMPED_KIND_OVERDAMPED,
        QuadraticModeKind::Critical => MECH_DAMPED_KIND_CRITICAL,
        QuadraticModeKind::Rigid => MECH_DAMPED_KIND_RIGID,
        QuadraticModeKind::Unstable => MECH_DAMPED_KIND_UNSTABLE,
        QuadraticModeKind::Neutral => MECH_DAMPED_KIND_NEUTRAL,
        QuadraticModeKind::Relaxation => MECH_DAMPED_KIND_RELAXATION,
        QuadraticModeKind::Infinite => MECH_DAMPED_KIND_INFINITE,
        // A kind added after this layer was written: the accuracy "does not decide" here.
        _ => MECH_DAMPED_KIND_UNDECIDED,
    }
}

/// The C record of a mode, its eigenvalues looked up in `eigenvalues`.
fn mode_to_c(mode: &QuadraticMode, eigenvalues: &[QuadraticEigenvalue]) -> Result<mech_damped_mode_t, FfiError> {
    let members: Vec<&QuadraticEigenvalue> = mode.eigenvalues.iter().filter_map(|&k| eigenvalues.get(k)).collect();
    let (Some(first), Some(last)) = (members.first(), members.last()) else {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            "a damped mode without eigenvalues",
        ));
    };
    let pair = [*first, *last];
    let s = pair.map(|e| e.s.map_or((0.0, 0.0), |s| (s.re, s.im)));
    let record = mech_damped_mode_t {
        kind: kind_to_c(mode.kind),
        natural_frequency: mode.natural_frequency.unwrap_or(-1.0),
        damped_frequency: mode.damped_frequency,
        damping_ratio: mode.damping_ratio.unwrap_or(-1.0),
        s_re: s.map(|(re, _)| re),
        s_im: s.map(|(_, im)| im),
        error_bound: pair.map(|e| e.error_bound),
        backward_error: pair.map(|e| e.backward_error),
        eigenvalue_count: if members.len() >= 2 { 2 } else { 1 },
    };
    let values = [
        record.natural_frequency,
        record.damped_frequency,
        record.damping_ratio,
        record.s_re[0],
        record.s_re[1],
        record.s_im[0],
        record.s_im[1],
        record.error_bound[0],
        record.error_bound[1],
        record.backward_error[0],
        record.backward_error[1],
    ];
    finite_result(values.as_slice(), "damped mode")?;
    Ok(record)
}

/// The C records of every mode of a solution, in its order.
fn modes_to_c(solution: &QuadraticModes) -> Result<Vec<mech_damped_mode_t>, FfiError> {
    solution
        .modes
        .iter()
        .map(|m| mode_to_c(m, &solution.eigenvalues))
        .collect()
}

/// Computes the damped and gyroscopic modes of the mechanism about `q0` (n coordinates):
/// det(s²A + s(C + G) + B) = 0 with A = A(q₀) the mass matrix, C the dampers' matrix, G the
/// gyroscopic matrix of a rotating frame and B = ∂²U* / ∂q² the stiffness matrix (FM 4.62–4.66,
/// §8e, §8g), solved by the certified quadratic eigensolver (docs/theory.md, "Quadratic
/// eigenproblems (damped and gyroscopic modes)"). Writes one mech_damped_mode_t per mode to
/// `modes_out`, by natural frequency ascending with infinite modes last, their number to
/// `*count_out`, and ‖grad U*(q₀)‖ to `*gradient_norm_out` (may be NULL): the linearization is
/// that of an equilibrium only when this is 0. The rotation vectors of spherical and free joints
/// are measured from the pose at q₀ for the linearization (their Hessian is exact only there);
/// this re-centring is done on a copy, so the handle is not changed and identical calls give
/// identical results, bit for bit.
///
/// The number of modes is between n (all pairs) and 2n (all single roots). Call with
/// `capacity` = 2n to be sure it fits, or with `capacity` = 0 (`modes_out` may then be NULL) to
/// learn the count, which a second call with the same arguments reproduces.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_NON_FINITE for a NaN or
/// infinite q0; MECH_STATUS_BUFFER_TOO_SMALL when `capacity` is below the number of modes, in
/// which case (only) the needed number is written to `*count_out`; MECH_STATUS_INVALID_ARGUMENT
/// for velocity-dependent potentials or a prescribed base motion (not modelled);
/// MECH_STATUS_SINGULAR when det(s²A + s(C + G) + B) vanishes for every s or a dashpot's points
/// coincide; MECH_STATUS_OUT_OF_RANGE when a result overflows. Apart from `*count_out` on
/// BUFFER_TOO_SMALL, nothing is written on failure.
///
/// # Safety
/// `dynamics` must be a live handle not used by another thread during the call; `q0` must
/// point to n readable doubles; `modes_out` to `capacity` writable records; `count_out`
/// writable; `gradient_norm_out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_dynamics_damped_modes(
    dynamics: *mut mech_dynamics_t,
    q0: *const f64,
    n: usize,
    capacity: usize,
    modes_out: *mut mech_damped_mode_t,
    count_out: *mut usize,
    gradient_norm_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let d = unsafe { dynamics_mut(dynamics) }?;
        // SAFETY: caller's contract.
        let q0 = unsafe { read_coordinates(d, q0, n, "q0") }?;
        let count_out = Out::new(count_out, "count_out")?;
        let gradient_out = Out::optional(gradient_norm_out, "gradient_norm_out")?;
        let result = d.damped_modes(q0, &QuadraticOptions::default())?;
        let records = modes_to_c(&result.solution)?;
        finite_result(&result.gradient_norm, "gradient norm")?;
        if let Err(error) = check_capacity(capacity, records.len(), "modes_out") {
            // SAFETY: caller's contract.
            unsafe { count_out.write(records.len()) };
            return Err(error);
        }
        let out = OutSlice::new(modes_out, records.len(), "modes_out")?;
        // SAFETY: checked for the number of modes.
        unsafe { out.write(&records) };
        // SAFETY: caller's contract.
        unsafe { count_out.write(records.len()) };
        if let Some(g) = gradient_out {
            // SAFETY: caller's contract.
            unsafe { g.write(result.gradient_norm) };
        }
        Ok(())
    })
}
