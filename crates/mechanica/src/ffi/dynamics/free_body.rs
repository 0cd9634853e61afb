//! The torque-free rigid body in C: the exact motion (R(t), ω(t)) in Jacobi's elliptic
//! functions, and its Lie-group integration to a tolerance with the error estimate, for
//! checking integrators against the exact solution.

use crate::ffi::boundary::boundary;
use crate::ffi::c_enum::{c_enum, enum_value};
use crate::ffi::spatial::read_rotation;
use crate::ffi::status::*;
use crate::ffi::types::*;
use crate::ffi::validate::*;
use mechanica_dynamics::free_body::{LieIntegrator, LieMethod, TorqueFreeBody};
use mechanica_kinematics::nalgebra::Vector3;

/// The state of a free rigid body: its attitude and its angular velocity.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_free_body_state_t {
    /// R, body → space (a rotation matrix, column-major).
    pub rotation: mech_mat3_t,
    /// ω in body (principal-axes) components, rad/s.
    pub omega: mech_vec3_t,
}

/// A Lie-group method of mech_free_body_integrate (docs/theory.md, "Lie-group integration of
/// the free body").
pub type mech_lie_method_t = i32;
/// The symmetric splitting into rotations about the principal axes, order 2.
pub const MECH_LIE_SPLITTING2: mech_lie_method_t = 0;
/// Runge–Kutta–Munthe-Kaas with the classical RK4 tableau, order 4.
pub const MECH_LIE_RKMK4: mech_lie_method_t = 1;
/// The splitting composed to order 4.
pub const MECH_LIE_SPLITTING4: mech_lie_method_t = 2;
/// The splitting composed to order 6.
pub const MECH_LIE_SPLITTING6: mech_lie_method_t = 3;
/// The splitting composed to order 8.
pub const MECH_LIE_SPLITTING8: mech_lie_method_t = 4;

c_enum!(LieMethod,
    MECH_LIE_SPLITTING2 => LieMethod::Splitting2,
    MECH_LIE_RKMK4 => LieMethod::Rkmk4,
    MECH_LIE_SPLITTING4 => LieMethod::Splitting4,
    MECH_LIE_SPLITTING6 => LieMethod::Splitting6,
    MECH_LIE_SPLITTING8 => LieMethod::Splitting8,
);

/// What mech_free_body_integrate reports besides the state.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_free_body_report_t {
    /// Estimated error of the attitude (rad): the angle of R_n⁻¹ R_2n where the runs converge
    /// at the method's order, larger otherwise, and π where they have lost the phase.
    pub attitude_error: f64,
    /// Estimated error of ω relative to |ω|.
    pub omega_error: f64,
    /// Steps of the reported run.
    pub steps: u64,
}

/// The exact state at time `t` of the torque-free body with principal `moments` (> 0, kg·m²)
/// that starts from `initial` at t = 0: Euler's equations (7.41) without torque solved by
/// Jacobi's elliptic functions, the attitude through the invariable plane (EB1911 §21), in every
/// regime (either side of the separatrix, on it, axisymmetric, steady rotation). Accurate to
/// a few ulps of the elliptic functions times the growth of the phase with t.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_INVALID_ARGUMENT
/// for a moment ≤ 0, an initial rotation that is not orthonormal with det +1 to 1e-12, or a t
/// so far that the motion's phase is lost (beyond 2⁵² quarter periods, where one ulp of the
/// phase is a quarter period); MECH_STATUS_OUT_OF_RANGE when the energy or the momentum
/// overflow.
///
/// # Safety
/// `moments` and `initial` must be readable, `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_free_body_exact(
    moments: *const mech_vec3_t,
    initial: *const mech_free_body_state_t,
    t: f64,
    out: *mut mech_free_body_state_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (moments, start) = unsafe { (read(moments, "moments")?, read(initial, "initial")?) };
        // SAFETY: the pointer is to a field of a local value.
        let r0 = unsafe { read_rotation(&start.rotation, "initial.rotation") }?;
        let out = Out::new(out, "out")?;
        finite(&moments, "moments")?;
        finite(&start.omega, "initial.omega")?;
        finite(&t, "t")?;
        let body = TorqueFreeBody::new(Vector3::from(moments), Vector3::from(start.omega), r0)?;
        let (rotation, omega) = body.state_at(t)?;
        let value = mech_free_body_state_t {
            rotation: (*rotation.matrix()).into(),
            omega: omega.into(),
        };
        finite_result(&value.rotation, "rotation")?;
        finite_result(&value.omega, "omega")?;
        // SAFETY: caller's contract.
        unsafe { out.write(value) };
        Ok(())
    })
}

/// Integrates the torque-free body with principal `moments` from `initial` over `duration`
/// (≥ 0, s) by a Lie-group method that keeps R on SO(3) without renormalising: runs of n₀,
/// 2n₀, 4n₀, … steps, n₀ = ⌈duration / max_step⌉, until the error estimate formed from the
/// last three runs (docs/theory.md, "Lie-group integration of the free body") is ≤
/// `tolerance` (> 0) for the attitude (rad) and for ω (relative). Writes the finest run's state
/// and the estimate.
///
/// Errors: MECH_STATUS_NON_FINITE for a NaN or infinite input; MECH_STATUS_BAD_ENUM for an
/// unknown method; MECH_STATUS_INVALID_ARGUMENT for a moment ≤ 0, a rotation that is not one,
/// a negative duration, max_step ≤ 0, tolerance ≤ 0, or when the tolerance is not met within
/// 2³⁰ steps; MECH_STATUS_NOT_CONVERGED when the estimate stops falling above the tolerance
/// (the method's rounding floor on this motion); MECH_STATUS_OUT_OF_RANGE on overflow.
///
/// # Safety
/// `moments` and `initial` must be readable, `out` and `report` writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn mech_free_body_integrate(
    moments: *const mech_vec3_t,
    initial: *const mech_free_body_state_t,
    duration: f64,
    method: mech_lie_method_t,
    max_step: f64,
    tolerance: f64,
    out: *mut mech_free_body_state_t,
    report: *mut mech_free_body_report_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let (moments, start) = unsafe { (read(moments, "moments")?, read(initial, "initial")?) };
        // SAFETY: the pointer is to a field of a local value.
        let r0 = unsafe { read_rotation(&start.rotation, "initial.rotation") }?;
        let (out, report) = (Out::new(out, "out")?, Out::new(report, "report")?);
        let method: LieMethod = enum_value(method, "method")?;
        finite(&moments, "moments")?;
        finite(&start.omega, "initial.omega")?;
        finite(&[duration, max_step, tolerance][..], "duration, max_step and tolerance")?;
        let integrator = LieIntegrator::new(Vector3::from(moments), method)?;
        let omega0 = Vector3::from(start.omega);
        let estimate = integrator.integrate_to_tolerance(&r0, &omega0, duration, max_step, tolerance)?;
        let state = mech_free_body_state_t {
            rotation: (*estimate.solution.rotation.matrix()).into(),
            omega: estimate.solution.omega.into(),
        };
        let value = mech_free_body_report_t {
            attitude_error: estimate.attitude_error,
            omega_error: estimate.omega_error,
            steps: estimate.solution.steps,
        };
        // SAFETY: caller's contract.
        unsafe {
            out.write(state);
            report.write(value);
        }
        Ok(())
    })
}
