//! The motion C ABI: a simulation of a dynamics handle (as in `abi_dynamics`: any joint types,
//! masses over 60 decades, dampers and charges) with every integration method and hostile
//! options (zero, negative, NaN steps and tolerances, unknown methods, a wrong error-estimate
//! flag), hostile initial states and forces, NULL and misaligned pointers and wrong lengths,
//! then a few advances to times chosen by the input (forward, backward, NaN, up to 1e300 s).
//! Each run is limited to MAX_STEPS steps by mech_simulation_set_max_steps, so an advance to
//! any time ends quickly (with MECH_STATUS_NOT_CONVERGED past the limit). Besides the output
//! contract (`dynamics::check_call`):
//! - a successful advance reaches exactly its target time, with at most MAX_STEPS steps;
//! - the report and the momentum monitors are finite whenever they are returned with
//!   MECH_STATUS_OK, the drifts and scales non-negative, the error estimates −1 exactly when
//!   the companion run is off, the invariant the Jacobi integral exactly with a rotating frame;
//! - a failed advance leaves the report's time and the outputs where they were;
//! - with unilateral contacts (random bodies, points, normals, offsets and laws, some invalid):
//!   the impacts come in time order, at most one per step, each with
//!   at least one contact and finite numbers, and the queries refuse indices past the count.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::dynamics::{
    OwnedDynamics, any_or, build_dynamics, check_call, decades, graded, graded_vector, misaligned, state_vector, vec_or,
};
use mechanica_fuzz::oracle::{Sentinel, doubles_of, doubles_untouched, sentinel_doubles};
use mechanica_fuzz::{Input, trace};

/// The step limit of each run: bounds the work of every advance.
const MAX_STEPS: u64 = 100;

struct OwnedSimulation(*mut mech_simulation_t);

impl Drop for OwnedSimulation {
    fn drop(&mut self) {
        unsafe { mech_simulation_destroy(self.0) };
    }
}

/// A few dampers and charges on the dynamics (checked by `abi_dynamics`; here they only load
/// the simulation).
fn loads(d: &OwnedDynamics, input: &mut Input) {
    for _ in 0..input.below(3) {
        let status = if input.bool() {
            let (coordinate, c) = (input.below(d.dof + 1), graded(input, 10));
            unsafe { mech_dynamics_add_joint_damper(d.handle, coordinate, c, std::ptr::null_mut()) }
        } else {
            let (body, point) = (input.below(d.bodies + 1), vec_or(input, 1.0));
            let (charge, e, b) = (any_or(input, 10.0), vec_or(input, 100.0), vec_or(input, 10.0));
            unsafe { mech_dynamics_add_charged_point(d.handle, body, point, charge, e, b, std::ptr::null_mut()) }
        };
        check_call("dynamics load", status, true, &[]);
    }
}

/// Options from the defaults with hostile changes.
fn options(input: &mut Input) -> mech_motion_options_t {
    let mut o = Sentinel::<mech_motion_options_t>::new();
    assert_eq!(unsafe { mech_motion_options_default(o.ptr()) }, MECH_STATUS_OK);
    let mut o = o.value;
    o.method = input.enum_i32(4);
    let tolerance = |input: &mut Input| {
        if input.u8() < 224 {
            10f64.powi(-(input.below(15) as i32))
        } else {
            input.any_f64()
        }
    };
    o.step = if input.u8() < 224 {
        (0.1 + input.fraction()) * decades(input, 4)
    } else {
        input.any_f64()
    };
    o.rtol = tolerance(input);
    o.atol = tolerance(input);
    o.estimate_error = if input.u8() < 248 {
        i32::from(input.bool())
    } else {
        input.u64() as i32
    };
    o
}

/// A simulation of `d`, or `None` after checking a refused creation.
fn create(d: &OwnedDynamics, input: &mut Input) -> Option<(OwnedSimulation, bool)> {
    let n = d.dof;
    let len = match input.u8() {
        0..=243 => n,
        244..=249 => n + 1,
        _ => n.saturating_sub(1),
    };
    let q0 = state_vector(input, len, 3.0);
    let q_dot0 = state_vector(input, len, 3.0);
    let tau = graded_vector(input, len);
    let tau_ptr = if input.bool() { tau.as_ptr() } else { std::ptr::null() };
    let o = options(input);
    let options_ptr: *const mech_motion_options_t = if input.u8() < 240 { &o } else { std::ptr::null() };
    let estimate = if options_ptr.is_null() {
        true
    } else {
        o.estimate_error == 1
    };
    let mut storage = [0u64; 4];
    let (handle, bad) = match input.u8() {
        0..=249 => (d.handle.cast_const(), None),
        250..=252 => (std::ptr::null(), Some(MECH_STATUS_NULL_POINTER)),
        _ => (
            misaligned::<mech_dynamics_t>(&mut storage).cast_const(),
            Some(MECH_STATUS_MISALIGNED_POINTER),
        ),
    };
    let mut simulation = std::ptr::null_mut();
    let contacts = (input.u8() < 96).then(|| contacts(d, input));
    trace!(
        "simulation_create(n {len}, q0 {q0:?}, q̇0 {q_dot0:?}, τ {:?}, options {o:?}, contacts {contacts:?})",
        (!tau_ptr.is_null()).then_some(&tau)
    );
    let status = match &contacts {
        None => unsafe {
            mech_simulation_create(
                handle,
                options_ptr,
                q0.as_ptr(),
                q_dot0.as_ptr(),
                tau_ptr,
                len,
                &mut simulation,
            )
        },
        Some(list) => unsafe {
            mech_simulation_create_with_contacts(
                handle,
                options_ptr,
                list.as_ptr(),
                list.len(),
                q0.as_ptr(),
                q_dot0.as_ptr(),
                tau_ptr,
                len,
                &mut simulation,
            )
        },
    };
    check_call("mech_simulation_create", status, simulation.is_null(), &[]);
    if let Some(expected) = bad {
        assert_eq!(
            status, expected,
            "mech_simulation_create: the status for a bad dynamics handle"
        );
    }
    if len != n {
        assert_ne!(
            status, MECH_STATUS_OK,
            "mech_simulation_create: accepted n = {len} for {n} coordinates"
        );
    }
    if status != MECH_STATUS_OK {
        return None;
    }
    Some((OwnedSimulation(simulation), estimate))
}

/// Up to three contacts: mostly a body point against a plane with a unit normal, sometimes a
/// point of another body, a missing body, a normal that is not a unit vector, or a restitution,
/// friction, law or offset that is out of range.
fn contacts(d: &OwnedDynamics, input: &mut Input) -> Vec<mech_motion_contact_t> {
    (0..input.below(4))
        .map(|_| {
            let axis = vec_or(input, 1.0);
            let length = (axis.x * axis.x + axis.y * axis.y + axis.z * axis.z).sqrt();
            let normal = if input.u8() < 232 && length > 1e-3 && length.is_finite() {
                mech_vec3_t {
                    x: axis.x / length,
                    y: axis.y / length,
                    z: axis.z / length,
                }
            } else {
                axis
            };
            let other_body = match input.u8() {
                0..=199 => -1,
                200..=249 => input.below(d.bodies + 1) as i64,
                _ => -(input.below(3) as i64) - 2,
            };
            mech_motion_contact_t {
                contact: mech_mechanism_contact_t {
                    body: input.below(d.bodies + 1),
                    point: vec_or(input, 1.0),
                    other_body,
                    other_point: vec_or(input, 1.0),
                    normal,
                    restitution: if input.u8() < 240 {
                        input.fraction()
                    } else {
                        input.any_f64()
                    },
                    friction: if input.u8() < 240 {
                        graded(input, 2)
                    } else {
                        input.any_f64()
                    },
                    law: input.enum_i32(2),
                },
                offset: any_or(input, 3.0),
            }
        })
        .collect()
}

/// The impacts so far (including those of an advance that failed later on), checked against
/// the steps taken.
fn impacts(s: &OwnedSimulation, steps: u64) {
    let mut count = usize::MAX;
    let status = unsafe { mech_simulation_impact_count(s.0, &mut count) };
    assert_eq!(status, MECH_STATUS_OK, "impact count");
    assert!(count as u64 <= steps, "{count} impacts in {steps} steps");
    let mut previous = 0.0;
    for k in 0..count {
        let mut impact = Sentinel::<mech_motion_impact_t>::new();
        let status = unsafe { mech_simulation_impact(s.0, k, impact.ptr()) };
        assert_eq!(status, MECH_STATUS_OK, "impact {k}");
        let i = impact.value;
        let numbers = [
            i.t,
            i.gap,
            i.approach_speed,
            i.kinetic_energy_before,
            i.energy_before,
            i.energy_after,
            i.energy_lost,
            i.segment_drift,
            i.impulse_error,
        ];
        assert!(numbers.iter().all(|x| x.is_finite()), "impact {k}: {i:?}");
        assert!(
            i.t >= previous,
            "impact {k} at {} before the previous one at {previous}",
            i.t
        );
        assert!(i.contact_count >= 1 && i.approach_speed > 0.0, "impact {k}: {i:?}");
        previous = i.t;
    }
    let mut beyond = Sentinel::<mech_motion_impact_t>::new();
    let status = unsafe { mech_simulation_impact(s.0, count, beyond.ptr()) };
    assert_eq!(status, MECH_STATUS_INVALID_ARGUMENT, "impact past the count");
}

/// The report and the momentum monitors, checked; the report is returned when it was.
fn reports(s: &OwnedSimulation, d: &OwnedDynamics, estimate: bool) -> Option<mech_motion_report_t> {
    let mut report = Sentinel::<mech_motion_report_t>::new();
    let status = unsafe { mech_simulation_report(s.0, report.ptr()) };
    let r = report.value;
    let numbers = [
        r.t,
        r.energy,
        r.error_q,
        r.error_q_dot,
        r.energy_scale,
        r.max_energy_drift,
        r.last_energy_drift,
    ];
    check_call("mech_simulation_report", status, report.untouched(), &numbers);
    let mut momentum = Sentinel::<mech_motion_momentum_report_t>::new();
    let m_status = unsafe { mech_simulation_momentum_report(s.0, momentum.ptr()) };
    check_call(
        "mech_simulation_momentum_report",
        m_status,
        momentum.untouched(),
        doubles_of(&momentum.value),
    );
    if m_status == MECH_STATUS_OK {
        for drift in [momentum.value.linear, momentum.value.angular] {
            let max = drift.max_drift;
            assert!(
                drift.scale >= 0.0 && max.x >= 0.0 && max.y >= 0.0 && max.z >= 0.0,
                "momentum monitor with a negative scale or drift: {drift:?}"
            );
        }
    }
    if status != MECH_STATUS_OK {
        return None;
    }
    assert!(
        r.energy_scale >= 0.0 && r.max_energy_drift >= r.last_energy_drift && r.last_energy_drift >= 0.0,
        "energy monitor out of order: {r:?}"
    );
    if estimate {
        assert!(
            r.error_q >= 0.0 && r.error_q_dot >= 0.0,
            "error estimates missing: {r:?}"
        );
    } else {
        assert!(
            r.error_q == -1.0 && r.error_q_dot == -1.0,
            "error estimates without a companion: {r:?}"
        );
    }
    let expected = if d.rotating {
        MECH_MOTION_JACOBI_INTEGRAL
    } else {
        MECH_MOTION_ENERGY
    };
    assert_eq!(
        r.invariant, expected,
        "the monitored invariant (rotating frame: {})",
        d.rotating
    );
    assert!(r.steps <= MAX_STEPS, "{} steps above the limit {MAX_STEPS}", r.steps);
    Some(r)
}

/// The next target time: ahead by a span over many decades, sometimes 1e300 s, the time
/// reached, an earlier time, or any double.
fn target(input: &mut Input, reached: f64) -> f64 {
    match input.u8() {
        0..=199 => reached + (0.1 + input.fraction()) * decades(input, 6),
        200..=214 => 1e300,
        215..=224 => reached,
        225..=239 => reached - input.fraction() - f64::MIN_POSITIVE,
        _ => input.any_f64(),
    }
}

fn advance(s: &OwnedSimulation, d: &OwnedDynamics, estimate: bool, input: &mut Input, reached: f64) {
    let n = d.dof;
    let t = target(input, reached);
    let len = match input.u8() {
        0..=247 => n,
        _ => n + 1,
    };
    let null_output = input.u8() >= 250 && len > 0;
    let (mut q, mut q_dot) = (sentinel_doubles(len), sentinel_doubles(len));
    let q_ptr = if null_output {
        std::ptr::null_mut()
    } else {
        q.as_mut_ptr()
    };
    trace!("advance({t:e}, n {len}, NULL q_out {null_output})");
    let status = unsafe { mech_simulation_advance(s.0, t, len, q_ptr, q_dot.as_mut_ptr()) };
    let written: Vec<f64> = q.iter().chain(&q_dot).copied().collect();
    check_call("mech_simulation_advance", status, doubles_untouched(&written), &written);
    if len != n || null_output || !(t >= reached) {
        assert_ne!(
            status, MECH_STATUS_OK,
            "advance: accepted t {t:e} (reached {reached:e}), n {len}, NULL q {null_output}"
        );
    }
    if status == MECH_STATUS_OK {
        let r = reports(s, d, estimate).map(|r| r.t);
        if let Some(reported) = r {
            assert_eq!(reported, t, "advance succeeded but the report's time is not its target");
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let Some(d) = build_dynamics(&mut input) else { return };
    loads(&d, &mut input);
    let Some((s, estimate)) = create(&d, &mut input) else {
        return;
    };
    if input.u8() >= 248 {
        let status = unsafe { mech_simulation_set_max_steps(s.0, 0) };
        check_call("mech_simulation_set_max_steps(0)", status, true, &[]);
        assert_eq!(status, MECH_STATUS_INVALID_ARGUMENT, "set_max_steps(0)");
        let status = unsafe { mech_simulation_set_max_steps(std::ptr::null_mut(), MAX_STEPS) };
        assert_eq!(status, MECH_STATUS_NULL_POINTER, "set_max_steps(NULL)");
    }
    assert_eq!(unsafe { mech_simulation_set_max_steps(s.0, MAX_STEPS) }, MECH_STATUS_OK);
    let Some(start) = reports(&s, &d, estimate) else { return };
    assert_eq!(start.t, 0.0, "a new simulation's report is not at t = 0");
    let mut reached = 0.0;
    for _ in 0..1 + input.below(4) {
        advance(&s, &d, estimate, &mut input, reached);
        let Some(r) = reports(&s, &d, estimate) else { return };
        assert!(
            r.t >= reached,
            "the report's time went back from {reached:e} to {:e}",
            r.t
        );
        reached = r.t;
        impacts(&s, r.steps);
    }
});
