//! C entry points of the motion crate: a simulation handle created on a dynamics handle, with
//! the method and its step or tolerances in mech_motion_options_t; advancing to a time into
//! caller buffers (q, q̇); the report of the global error estimate (M.13) and the monitors.
//! [`constrained`]: simulations that keep the holonomic constraints of the dynamics handle;
//! [`contacts`]: simulations with unilateral contacts and their impacts.

mod constrained;
mod contacts;

pub use constrained::*;
pub use contacts::*;

use super::boundary::{FfiError, boundary};
use super::c_enum::{c_enum, enum_value};
use super::dynamics::mech_dynamics_t;
use super::handle::Handle;
use super::status::*;
use super::types::mech_vec3_t;
use super::validate::*;
use mechanica_dynamics::ConstrainedDynamics;
use mechanica_motion::{
    Forcing, Invariant, Method, MomentumDrift, MotionError, Options, Simulation, StepFailure, Stepper,
    UnilateralContact,
};

/// An integration method (int32_t).
pub type mech_motion_method_t = i32;
/// The classical explicit Runge–Kutta method of order 4, fixed step `step`.
pub const MECH_MOTION_RK4: mech_motion_method_t = 0;
/// Dormand–Prince 5(4), adaptive with tolerances `rtol` and `atol`.
pub const MECH_MOTION_DORMAND_PRINCE: mech_motion_method_t = 1;
/// Störmer–Verlet in (q, p = A q̇), symplectic, fixed step `step`.
pub const MECH_MOTION_STORMER_VERLET: mech_motion_method_t = 2;
/// The implicit midpoint rule with Newton's method, for stiff springs, fixed step `step`.
pub const MECH_MOTION_IMPLICIT_MIDPOINT: mech_motion_method_t = 3;
/// RATTLE: Störmer–Verlet with the multipliers of holonomic constraints (M.17), symplectic,
/// fixed step `step`; without constraints it is MECH_MOTION_STORMER_VERLET.
pub const MECH_MOTION_RATTLE: mech_motion_method_t = 4;

/// The quantity H that the energy monitor follows (int32_t).
pub type mech_motion_invariant_t = i32;
/// The energy T + U (fixed or prescribed base).
pub const MECH_MOTION_ENERGY: mech_motion_invariant_t = 0;
/// The Jacobi integral T₂ − T₀ + U of a steadily rotating frame.
pub const MECH_MOTION_JACOBI_INTEGRAL: mech_motion_invariant_t = 1;

#[derive(Debug, Clone, Copy)]
enum MethodKind {
    Rk4,
    DormandPrince,
    StormerVerlet,
    ImplicitMidpoint,
    Rattle,
}

c_enum!(MethodKind,
    MECH_MOTION_RK4 => MethodKind::Rk4,
    MECH_MOTION_DORMAND_PRINCE => MethodKind::DormandPrince,
    MECH_MOTION_STORMER_VERLET => MethodKind::StormerVerlet,
    MECH_MOTION_IMPLICIT_MIDPOINT => MethodKind::ImplicitMidpoint,
    MECH_MOTION_RATTLE => MethodKind::Rattle,
);

/// Options of a simulation. Start from mech_motion_options_default.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct mech_motion_options_t {
    /// The method (a mech_motion_method_t).
    pub method: mech_motion_method_t,
    /// The largest step of the fixed-step methods, s (> 0).
    pub step: f64,
    /// Relative tolerance of MECH_MOTION_DORMAND_PRINCE (≥ 1e-14).
    pub rtol: f64,
    /// Absolute tolerance of MECH_MOTION_DORMAND_PRINCE (> 0).
    pub atol: f64,
    /// 1 to run the companion integration that gives the global error estimate, 0 not to.
    pub estimate_error: i32,
}

/// The state of a simulation after its last successful advance. Estimates not computed read −1.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct mech_motion_report_t {
    /// The time reached, s.
    pub t: f64,
    /// H = T₂ + U* − τ·q at t, J (the energy, or the Jacobi integral in a rotating frame).
    pub energy: f64,
    /// The estimated global error of q (∞-norm), or −1 without the companion run.
    pub error_q: f64,
    /// The estimated global error of q̇ (∞-norm), or −1 without the companion run.
    pub error_q_dot: f64,
    /// What H is (a mech_motion_invariant_t).
    pub invariant: mech_motion_invariant_t,
    /// The energy scale, J: the largest kinetic energy T₂ over the states reported so far.
    pub energy_scale: f64,
    /// max |H − H(0)| / energy_scale over the states reported so far.
    pub max_energy_drift: f64,
    /// |H − H(0)| / energy_scale at t.
    pub last_energy_drift: f64,
    /// Steps taken by the main integration.
    pub steps: u64,
}

/// A simulation (opaque): a copy of a dynamics with a method, integrating from an initial
/// state. Created by mech_simulation_create, freed by mech_simulation_destroy.
pub struct mech_simulation_t {
    stepper: Stepper,
}

impl Handle for mech_simulation_t {}

impl From<MotionError> for FfiError {
    fn from(error: MotionError) -> Self {
        let status = match &error {
            MotionError::Dynamics(e) => return FfiError::from(e.clone()),
            MotionError::WrongLength { .. } => MECH_STATUS_BAD_DIMENSION,
            MotionError::NonFiniteInput { .. } => MECH_STATUS_NON_FINITE,
            MotionError::NonFiniteResult { .. } => MECH_STATUS_OUT_OF_RANGE,
            MotionError::StepFailed { cause, .. } => match cause {
                StepFailure::Dynamics(e) => FfiError::from(e.clone()).status,
                StepFailure::Impact(e) => FfiError::from((**e).clone()).status,
                StepFailure::SingularMassMatrix | StepFailure::SingularConstraints => MECH_STATUS_SINGULAR,
                StepFailure::NonFinite { .. } | StepFailure::NonFiniteForce { .. } => MECH_STATUS_OUT_OF_RANGE,
                _ => MECH_STATUS_NOT_CONVERGED,
            },
            _ => MECH_STATUS_INVALID_ARGUMENT,
        };
        FfiError::new(status, error.to_string())
    }
}

/// Writes the default options to `*options_out`: Dormand–Prince with rtol = 1e-8,
/// atol = 1e-10, a step of 1e-3 s for the fixed-step methods, and the error estimate on.
///
/// # Safety
/// `options_out` must point to a writable mech_motion_options_t.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_motion_options_default(options_out: *mut mech_motion_options_t) -> mech_status_t {
    boundary(|| {
        let out = Out::new(options_out, "options_out")?;
        // SAFETY: caller's contract.
        unsafe { out.write(mech_motion_options_t::default_values()) };
        Ok(())
    })
}

/// The Rust method and options of C options.
fn rust_options(o: &mech_motion_options_t, tau: Option<&[f64]>) -> Result<(Method, Options), FfiError> {
    let method = match enum_value::<MethodKind>(o.method, "method")? {
        MethodKind::Rk4 => Method::Rk4 { step: o.step },
        MethodKind::StormerVerlet => Method::StormerVerlet { step: o.step },
        MethodKind::ImplicitMidpoint => Method::ImplicitMidpoint { step: o.step },
        MethodKind::Rattle => Method::Rattle { step: o.step },
        MethodKind::DormandPrince => Method::DormandPrince {
            rtol: o.rtol,
            atol: o.atol,
        },
    };
    if o.estimate_error != 0 && o.estimate_error != 1 {
        return Err(FfiError::new(
            MECH_STATUS_INVALID_ARGUMENT,
            format!("estimate_error must be 0 or 1, got {}", o.estimate_error),
        ));
    }
    let options = Options {
        forcing: tau.map_or(Forcing::None, |t| Forcing::Constant(t.to_vec())),
        estimate_error: o.estimate_error == 1,
        ..Options::default()
    };
    Ok((method, options))
}

/// Creates a simulation of a copy of `dynamics` (with its dampers and loads) from (`q0`,
/// `q_dot0`) (n values each) at t = 0, with the constant applied forces `tau` (n values, or
/// NULL for none) and the options `*options` (NULL for the defaults), and writes its handle
/// to `*simulation_out`. The caller frees it with mech_simulation_destroy.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_NON_FINITE for a NaN
/// or infinite entry; MECH_STATUS_BAD_ENUM for an unknown method; MECH_STATUS_INVALID_ARGUMENT
/// for a step or tolerance that is zero, negative or not finite, or rtol < 1e-14;
/// MECH_STATUS_SINGULAR when the mass matrix is singular at q0.
///
/// # Safety
/// `dynamics` must be a live handle; `q0` and `q_dot0` must point to n readable doubles,
/// `tau` be NULL or point to n readable doubles, `options` be NULL or readable, and
/// `simulation_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_create(
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
        let d = unsafe { mech_dynamics_t::borrow(dynamics, "dynamics") }?.dynamics();
        let model = ConstrainedDynamics::new(d.clone());
        // SAFETY: caller's contract.
        unsafe { start(model, Vec::new(), options, (q0, q_dot0, tau, n), simulation_out) }
    })
}

/// The C inputs of a simulation's initial value problem: q₀, q̇₀, τ (may be NULL) and n.
type InitialValues = (*const f64, *const f64, *const f64, usize);

/// Starts a simulation of `model` with `contacts`, the C options and initial values, and
/// writes its handle.
///
/// # Safety
/// As mech_simulation_create.
unsafe fn start(
    model: ConstrainedDynamics,
    contacts: Vec<UnilateralContact>,
    options: *const mech_motion_options_t,
    (q0, q_dot0, tau, n): InitialValues,
    simulation_out: *mut *mut mech_simulation_t,
) -> Result<(), FfiError> {
    let out = Out::new(simulation_out, "simulation_out")?;
    let mut defaults = mech_motion_options_t::default_values();
    if !options.is_null() {
        // SAFETY: caller's contract.
        defaults = unsafe { read(options, "options") }?;
    }
    // SAFETY: caller's contract.
    let (q0, q_dot0) = unsafe { (read_slice(q0, n, "q0")?, read_slice(q_dot0, n, "q_dot0")?) };
    let tau = if tau.is_null() {
        None
    } else {
        // SAFETY: caller's contract.
        Some(unsafe { read_slice(tau, n, "tau") }?)
    };
    let (method, options) = rust_options(&defaults, tau)?;
    let simulation = Simulation::constrained(model, method, options)?.with_contacts(contacts)?;
    let stepper = simulation.start(q0, q_dot0)?;
    // SAFETY: caller's contract.
    unsafe { out.write(mech_simulation_t { stepper }.into_raw()) };
    Ok(())
}

impl mech_motion_options_t {
    fn default_values() -> Self {
        Self {
            method: MECH_MOTION_DORMAND_PRINCE,
            step: 1e-3,
            rtol: 1e-8,
            atol: 1e-10,
            estimate_error: 1,
        }
    }
}

/// Frees a simulation handle. NULL is accepted and ignored.
///
/// # Safety
/// `simulation` must be NULL or a live handle from mech_simulation_create, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_destroy(simulation: *mut mech_simulation_t) {
    // SAFETY: caller's contract.
    unsafe { mech_simulation_t::destroy(simulation) }
}

/// Integrates to the time `t` (s, ≥ the time reached) and writes q and q̇ there (n values
/// each) to `q_out` and `q_dot_out`. Rotation vectors of spherical and free joints are given
/// in the charts of the mechanism as created (|φ| ≤ π). Adaptive steps end exactly at t.
///
/// Errors: MECH_STATUS_BAD_DIMENSION when n is not the dof; MECH_STATUS_INVALID_ARGUMENT for
/// a t before the time reached; MECH_STATUS_NON_FINITE for a NaN t. A step that fails stops
/// the integration at the last good state (mech_last_error names the time): MECH_STATUS_SINGULAR
/// for a singular mass matrix, MECH_STATUS_OUT_OF_RANGE for a non-finite state or
/// acceleration, MECH_STATUS_NOT_CONVERGED when Newton's method or the step control fails.
///
/// # Safety
/// `simulation` must be a live handle not used by another thread during the call; `q_out` and
/// `q_dot_out` must point to n writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_advance(
    simulation: *mut mech_simulation_t,
    t: f64,
    n: usize,
    q_out: *mut f64,
    q_dot_out: *mut f64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow_mut(simulation, "simulation") }?;
        finite(&t, "t")?;
        let dof = s.stepper.sample().q.len();
        if n != dof {
            return Err(FfiError::new(
                MECH_STATUS_BAD_DIMENSION,
                format!("the mechanism has {dof} coordinates, got n = {n}"),
            ));
        }
        let q = OutSlice::new(q_out, n, "q_out")?;
        let q_dot = OutSlice::new(q_dot_out, n, "q_dot_out")?;
        let sample = s.stepper.advance(t)?;
        // SAFETY: caller's contract.
        unsafe {
            q.write(&sample.q);
            q_dot.write(&sample.q_dot);
        }
        Ok(())
    })
}

/// Sets the most steps each run of the simulation may take, counted from t = 0 with the steps
/// already taken: the main integration and, with `estimate_error`, its companion (the default
/// is 100 000 000 each). An advance that needs more stops at the last good state with
/// MECH_STATUS_NOT_CONVERGED (mech_last_error says "more than N steps"), so the limit bounds
/// the work of every later mech_simulation_advance whatever its target time; raising it lets
/// the integration go on from there.
///
/// Errors: MECH_STATUS_INVALID_ARGUMENT for `max_steps` = 0.
///
/// # Safety
/// `simulation` must be a live handle not used by another thread during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_set_max_steps(
    simulation: *mut mech_simulation_t,
    max_steps: u64,
) -> mech_status_t {
    boundary(|| {
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow_mut(simulation, "simulation") }?;
        if max_steps == 0 {
            return Err(FfiError::new(
                MECH_STATUS_INVALID_ARGUMENT,
                "max_steps must be ≥ 1, got 0",
            ));
        }
        s.stepper
            .set_max_steps(usize::try_from(max_steps).unwrap_or(usize::MAX));
        Ok(())
    })
}

/// Writes the report of the last successful advance (or of the initial state) to
/// `*report_out`: time, H, the global error estimates and the energy monitor.
///
/// Errors: MECH_STATUS_OUT_OF_RANGE when one of its numbers overflowed (nothing is written).
///
/// # Safety
/// `simulation` must be a live handle and `report_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_report(
    simulation: *const mech_simulation_t,
    report_out: *mut mech_motion_report_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(report_out, "report_out")?;
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let sample = s.stepper.sample();
        let monitors = s.stepper.monitors();
        let report = mech_motion_report_t {
            t: sample.t,
            energy: sample.energy,
            error_q: sample.error.map_or(-1.0, |e| e.q),
            error_q_dot: sample.error.map_or(-1.0, |e| e.q_dot),
            invariant: match monitors.invariant {
                Invariant::JacobiIntegral => MECH_MOTION_JACOBI_INTEGRAL,
                _ => MECH_MOTION_ENERGY,
            },
            energy_scale: monitors.scale,
            max_energy_drift: monitors.max_drift,
            last_energy_drift: monitors.last_drift,
            steps: s.stepper.steps() as u64,
        };
        let numbers = [
            report.energy,
            report.error_q,
            report.error_q_dot,
            report.energy_scale,
            report.max_energy_drift,
            report.last_energy_drift,
        ];
        finite_result(numbers.as_slice(), "simulation report")?;
        // SAFETY: caller's contract.
        unsafe { out.write(report) };
        Ok(())
    })
}

/// One momentum vector of the whole mechanism over the states reported so far (world
/// components of the mechanism's frame, its base at rest). Which components are conserved
/// depends on the mechanism: see docs/theory.md (M.15)–(M.16).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct mech_motion_momentum_drift_t {
    /// The value at t = 0.
    pub initial: mech_vec3_t,
    /// The value at the time reached.
    pub last: mech_vec3_t,
    /// Componentwise max |x − x(0)| over every step and reported state.
    pub max_drift: mech_vec3_t,
    /// The largest |x| over every step and reported state: the scale of the drift.
    pub scale: f64,
}

/// The momentum monitors of a simulation: the linear momentum P = Σ mᵢ vᵢ (M.15), kg·m/s, and
/// the angular momentum L about the origin of the mechanism's frame (M.16), kg·m²/s.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct mech_motion_momentum_report_t {
    /// The linear momentum P.
    pub linear: mech_motion_momentum_drift_t,
    /// The angular momentum L about the origin.
    pub angular: mech_motion_momentum_drift_t,
}

impl From<&MomentumDrift> for mech_motion_momentum_drift_t {
    fn from(d: &MomentumDrift) -> Self {
        Self {
            initial: d.initial.into(),
            last: d.last.into(),
            max_drift: d.max_drift.into(),
            scale: d.scale,
        }
    }
}

/// Writes the momentum monitors of the simulation (over every step since t = 0 up to the last
/// successful advance) to `*report_out`.
///
/// Errors: MECH_STATUS_OUT_OF_RANGE when a momentum or its drift overflowed (masses or
/// velocities near the limits of double precision; nothing is written).
///
/// # Safety
/// `simulation` must be a live handle and `report_out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mech_simulation_momentum_report(
    simulation: *const mech_simulation_t,
    report_out: *mut mech_motion_momentum_report_t,
) -> mech_status_t {
    boundary(|| {
        let out = Out::new(report_out, "report_out")?;
        // SAFETY: caller's contract.
        let s = unsafe { mech_simulation_t::borrow(simulation, "simulation") }?;
        let monitors = s.stepper.monitors();
        let report = mech_motion_momentum_report_t {
            linear: (&monitors.linear_momentum).into(),
            angular: (&monitors.angular_momentum).into(),
        };
        let numbers = [report.linear, report.angular].map(momentum_numbers);
        finite_result(numbers.as_flattened(), "momentum monitor")?;
        // SAFETY: caller's contract.
        unsafe { out.write(report) };
        Ok(())
    })
}

/// The ten numbers of one momentum monitor.
fn momentum_numbers(d: mech_motion_momentum_drift_t) -> [f64; 10] {
    let [a, b, c] = [d.initial, d.last, d.max_drift];
    [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.scale]
}
