//! Simulations of mechanisms with holonomic constraints f(q) = 0: the constraints added to a
//! dynamics handle (mech_dynamics_add_*_constraint) are kept during the motion, by RATTLE
//! (M.17) with MECH_MOTION_RATTLE, or by the index-1 equations (M.18) with projection onto
//! f = 0 and J q̇ = 0 after each step (M.19) with the other methods; the constraint drift
//! (M.20) is reported.

use super::{InitialValues, mech_motion_options_t, mech_simulation_t, start};
use crate::ffi::boundary::boundary;
use crate::ffi::dynamics::mech_dynamics_t;
use crate::ffi::handle::Handle;
use crate::ffi::status::*;
use crate::ffi::validate::*;

/// The drift of a simulation's holonomic constraints over the states reached so far (M.20):
/// ‖f(q)‖₂ (m, or mixed units when equations mix lengths and angles) and ‖J(q) q̇‖₂. All zero
/// for a mechanism without constraints.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_motion_constraint_report_t {
    /// max ‖f(q)‖₂ over every step and reported state.
    pub max_position_drift: f64,
    /// max ‖J(q) q̇‖₂ over every step and reported state.
    pub max_velocity_drift: f64,
    /// ‖f(q)‖₂ at the time reached.
    pub last_position_drift: f64,
    /// ‖J(q) q̇‖₂ at the time reached.
    pub last_velocity_drift: f64,
}

/// Creates a simulation of a copy of `dynamics` that keeps its holonomic constraints (see the
/// module docs; the arguments are those of mech_simulation_create). (`q0`, `q_dot0`) should
/// satisfy the constraints; the first step moves the state onto them.
///
/// Errors: those of mech_simulation_create; MECH_STATUS_INVALID_ARGUMENT for a coordinate
/// constraint on a rotation vector of a spherical or free joint. A step whose constraints
/// cannot be met (RATTLE's Newton iteration, or the projection, does not reach the rounding
/// level of f) stops the integration with MECH_STATUS_NOT_CONVERGED at the last good state;
/// dependent constraints give MECH_STATUS_SINGULAR.
///
/// # Safety
/// As mech_simulation_create.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_create_constrained(
    dynamics: *const mech_dynamics_t,
    options: *const mech_motion_options_t,
    q0: *const f64,
    q_dot0: *const f64,
    tau: *const f64,
    n: usize,
    simulation_out: *mut *mut mech_simulation_t,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let model = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?
            .constrained()
            .clone();
        let initial: InitialValues = (q0, q_dot0, tau, n);
        // SAFETY: caller's contract.
        unsafe { start(model, Vec::new(), options, initial, simulation_out) }
    })
}

/// Writes the constraint drift of the simulation (over every step since t = 0 up to the last
/// successful advance) to `*report_out`.
///
/// # Safety
/// `simulation` must be a live handle and `report_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_constraint_report(
    simulation: *const mech_simulation_t,
    report_out: *mut mech_motion_constraint_report_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(report_out, "report_out")?;
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let drift = s.stepper.monitors().constraints;
        let report = mech_motion_constraint_report_t {
            max_position_drift: drift.max_position,
            max_velocity_drift: drift.max_velocity,
            last_position_drift: drift.last_position,
            last_velocity_drift: drift.last_velocity,
        };
        // SAFETY: caller's contract.
        unsafe { out.write(report) };
        Ok(())
    })
}
