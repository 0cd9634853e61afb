//! The dynamics C ABI: a dynamics handle on a tree of any joint types with bodies whose masses
//! span 60 decades (some massless, point-like, invalid or non-finite), then a sequence of calls
//! chosen by the input: dampers, charged points, constraints (loop closures), inverse and
//! forward dynamics, the mass matrix, joint reactions, the constrained forward dynamics, damped
//! modes, the torque-free body — with wrong lengths, short capacities, NULL and misaligned
//! pointers mixed in. Besides the output contract (`dynamics::check_call`: a documented status,
//! only finite numbers written on success, nothing written and a message on failure):
//! - forward then inverse dynamics: RNEA(q, q̇, q̈) gives τ back within the backward error the
//!   forward solve reports (‖τ' − τ‖∞ ≤ η·S + 2·max ρ_k, S the library's force scale bounded
//!   from above, ρ the inverse dynamics' rounding estimate); the articulated-body route is
//!   reported only with η at its stated rounding level 16·(d + 4)·u;
//! - mech_dynamics_rnea and mech_dynamics_inverse agree within the rounding estimate;
//! - the mass matrix is symmetric; each added constraint adds its equations to the count;
//! - damped modes follow the count protocol, number between n and 2n, and a repeated call
//!   gives the same records bit for bit;
//! - the free body's exact motion keeps R orthonormal, its kinetic energy and |L|.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::dynamics::{
    OwnedDynamics, any_or, build_dynamics, check_call, graded, graded_vector, misaligned, state_vector, vec_or,
};
use mechanica_fuzz::oracle::{Sentinel, doubles_of, doubles_untouched, sentinel_doubles};
use mechanica_fuzz::tree::v3;
use mechanica_fuzz::{Input, trace};

const U: f64 = f64::EPSILON / 2.0;
/// The rounding factor 16·(d + 4)·ε of the dynamics (`estimate_factor`, ε = f64::EPSILON)
/// for the deepest tree `build_tree` makes (depth ≤ 4) and for the shallowest (depth ≥ 0).
const FACTOR_MAX: f64 = 16.0 * 8.0 * f64::EPSILON;
const FACTOR_MIN: f64 = 16.0 * 4.0 * f64::EPSILON;

/// What the sequence of calls has added to the handle.
struct Loads {
    dampers: usize,
    charges: usize,
    equations: usize,
}

/// The handle argument of one call: usually the live one, sometimes NULL or misaligned (both
/// rejected before any dereference), with the status the call must then return.
fn handle_for(d: &OwnedDynamics, input: &mut Input, storage: &mut [u64; 4]) -> (*mut mech_dynamics_t, Option<i32>) {
    match input.u8() {
        0..=249 => (d.handle, None),
        250..=252 => (std::ptr::null_mut(), Some(MECH_STATUS_NULL_POINTER)),
        _ => (misaligned(storage), Some(MECH_STATUS_MISALIGNED_POINTER)),
    }
}

fn expect_handle_status(call: &str, status: i32, expected: Option<i32>) {
    if let Some(expected) = expected {
        assert_eq!(status, expected, "{call}: the status for a NULL or misaligned handle");
    }
}

/// The length passed for an n-vector: n, or sometimes a wrong one (the buffers always hold
/// the length passed, so a call that reads before checking stays in bounds).
fn length(input: &mut Input, n: usize) -> usize {
    match input.u8() {
        0..=243 => n,
        244..=249 => n + 1,
        _ => n.saturating_sub(1),
    }
}

/// An optional index output: a local, or NULL.
fn index_out(input: &mut Input, slot: &mut usize) -> *mut usize {
    if input.u8() < 200 { slot } else { std::ptr::null_mut() }
}

fn add_damper(d: &OwnedDynamics, loads: &mut Loads, input: &mut Input) {
    let mut storage = [0u64; 4];
    let (h, bad) = handle_for(d, input, &mut storage);
    let mut index = usize::MAX;
    let out = index_out(input, &mut index);
    let (call, status) = if input.bool() {
        let coordinate = input.below(d.dof + 2);
        let c = graded(input, 20);
        trace!("add_joint_damper({coordinate}, {c:e})");
        ("mech_dynamics_add_joint_damper", unsafe {
            mech_dynamics_add_joint_damper(h, coordinate, c, out)
        })
    } else {
        let (a, b) = (
            input.below(d.bodies + 3) as i64 - 2,
            input.below(d.bodies + 3) as i64 - 2,
        );
        let (pa, pb) = (vec_or(input, 1.0), vec_or(input, 1.0));
        let c = graded(input, 20);
        let axial = input.enum_i32(2);
        trace!("add_point_damper({a}, {pa:?}, {b}, {pb:?}, {c:e}, axial {axial})");
        ("mech_dynamics_add_point_damper", unsafe {
            mech_dynamics_add_point_damper(h, a, pa, b, pb, c, axial, out)
        })
    };
    check_call(call, status, index == usize::MAX, &[]);
    expect_handle_status(call, status, bad);
    if status == MECH_STATUS_OK {
        if !out.is_null() {
            assert_eq!(index, loads.dampers, "{call}: the damper's index");
        }
        loads.dampers += 1;
    }
}

fn add_charge(d: &OwnedDynamics, loads: &mut Loads, input: &mut Input) {
    let body = input.below(d.bodies + 1);
    let point = vec_or(input, 1.0);
    let charge = any_or(input, 10.0);
    let (e, b) = (vec_or(input, 100.0), vec_or(input, 10.0));
    let mut index = usize::MAX;
    let out = index_out(input, &mut index);
    trace!("add_charged_point({body}, {point:?}, {charge:e}, {e:?}, {b:?})");
    let status = unsafe { mech_dynamics_add_charged_point(d.handle, body, point, charge, e, b, out) };
    check_call("mech_dynamics_add_charged_point", status, index == usize::MAX, &[]);
    if status == MECH_STATUS_OK {
        if !out.is_null() {
            assert_eq!(index, loads.charges, "mech_dynamics_add_charged_point: the index");
        }
        loads.charges += 1;
    }
}

/// One of the four constraints; the equation count must grow by the constraint's equations.
fn add_constraint(d: &OwnedDynamics, loads: &mut Loads, input: &mut Input) {
    let body = |input: &mut Input| input.below(d.bodies + 3) as i64 - 2;
    let mut index = usize::MAX;
    let out = index_out(input, &mut index);
    let (call, status, equations) = match input.u8() % 4 {
        0 => {
            let (a, b) = (body(input), body(input));
            let (pa, pb) = (vec_or(input, 1.0), vec_or(input, 1.0));
            let count = input.below(5);
            let directions: Vec<mech_vec3_t> = (0..count.max(1)).map(|_| vec_or(input, 1.0)).collect();
            let pointer = if input.u8() < 250 {
                directions.as_ptr()
            } else {
                std::ptr::null()
            };
            trace!("add_point_constraint({a}, {pa:?}, {b}, {pb:?}, {directions:?}, {count})");
            let status = unsafe {
                mech_dynamics_add_point_constraint(d.handle, a, pa, b, pb, pointer, count.min(directions.len()), out)
            };
            (
                "mech_dynamics_add_point_constraint",
                status,
                count.min(directions.len()),
            )
        }
        1 => {
            let b = body(input);
            let (p, normal, offset) = (vec_or(input, 1.0), vec_or(input, 1.0), any_or(input, 1.0));
            trace!("add_plane_constraint({b}, {p:?}, {normal:?}, {offset:e})");
            let status = unsafe { mech_dynamics_add_plane_constraint(d.handle, b, p, normal, offset, out) };
            ("mech_dynamics_add_plane_constraint", status, 1)
        }
        2 => {
            let (a, b) = (body(input), body(input));
            let (pa, pb) = (vec_or(input, 1.0), vec_or(input, 1.0));
            let length = any_or(input, 2.0);
            trace!("add_distance_constraint({a}, {pa:?}, {b}, {pb:?}, {length:e})");
            let status = unsafe { mech_dynamics_add_distance_constraint(d.handle, a, pa, b, pb, length, out) };
            ("mech_dynamics_add_distance_constraint", status, 1)
        }
        _ => {
            let coordinate = input.below(d.dof + 2);
            let value = any_or(input, 2.0);
            trace!("add_coordinate_constraint({coordinate}, {value:e})");
            let status = unsafe { mech_dynamics_add_coordinate_constraint(d.handle, coordinate, value, out) };
            ("mech_dynamics_add_coordinate_constraint", status, 1)
        }
    };
    check_call(call, status, index == usize::MAX, &[]);
    let mut count = Sentinel::<usize>::new();
    assert_eq!(
        unsafe { mech_dynamics_constraint_equations(d.handle, count.ptr()) },
        MECH_STATUS_OK
    );
    if status == MECH_STATUS_OK {
        loads.equations += equations;
    }
    assert_eq!(
        count.value, loads.equations,
        "{call} (status {status}): the equation count"
    );
}

/// τ' = RNEA(q, q̇, q̈) with its rounding estimate ρ, by mech_dynamics_inverse at time t;
/// checked against mech_dynamics_rnea (loads at time 0) when t = 0.
fn inverse(d: &OwnedDynamics, q: &[f64], q_dot: &[f64], q_ddot: &[f64], t: f64) -> Option<(Vec<f64>, Vec<f64>)> {
    let n = d.dof;
    let mut tau = sentinel_doubles(n);
    let mut parts = [sentinel_doubles(n), sentinel_doubles(n), sentinel_doubles(n)];
    let [c, g, rho] = &mut parts;
    let status = unsafe {
        mech_dynamics_inverse(
            d.handle,
            q.as_ptr(),
            q_dot.as_ptr(),
            q_ddot.as_ptr(),
            t,
            n,
            tau.as_mut_ptr(),
            c.as_mut_ptr(),
            g.as_mut_ptr(),
            rho.as_mut_ptr(),
        )
    };
    let written: Vec<f64> = tau.iter().chain(parts.iter().flatten()).copied().collect();
    let untouched = doubles_untouched(&written);
    check_call("mech_dynamics_inverse", status, untouched, &written);
    if status != MECH_STATUS_OK {
        return None;
    }
    assert!(
        parts[2].iter().all(|r| *r >= 0.0),
        "mech_dynamics_inverse: a negative rounding estimate {:?}",
        parts[2]
    );
    let [_, _, rho] = parts;
    if t == 0.0 {
        let mut fast = sentinel_doubles(n);
        let status = unsafe {
            mech_dynamics_rnea(
                d.handle,
                q.as_ptr(),
                q_dot.as_ptr(),
                q_ddot.as_ptr(),
                n,
                fast.as_mut_ptr(),
            )
        };
        check_call("mech_dynamics_rnea", status, doubles_untouched(&fast), &fast);
        if status == MECH_STATUS_OK {
            for k in 0..n {
                assert!(
                    (fast[k] - tau[k]).abs() <= 2.0 * rho[k],
                    "rnea τ[{k}] = {:e} but inverse τ[{k}] = {:e} (rounding estimate {:e})",
                    fast[k],
                    tau[k],
                    rho[k]
                );
            }
        }
    }
    Some((tau, rho))
}

/// Forward dynamics (checked or by the mass matrix) at a state, then the round trip through
/// the inverse dynamics.
fn forward(d: &OwnedDynamics, input: &mut Input) {
    let n = d.dof;
    let len = length(input, n);
    let q = state_vector(input, len, 3.0);
    let q_dot = state_vector(input, len, 3.0);
    let tau = graded_vector(input, len);
    let t = if input.u8() < 240 { 0.0 } else { input.any_f64() };
    let crba = input.bool();
    let with_report = input.u8() < 230;
    let mut storage = [0u64; 4];
    let (h, bad) = handle_for(d, input, &mut storage);
    let mut q_ddot = sentinel_doubles(len);
    let mut report = Sentinel::<mech_forward_report_t>::new();
    let report_ptr = if with_report {
        report.ptr()
    } else {
        std::ptr::null_mut()
    };
    trace!("forward(crba {crba}, q {q:?}, q̇ {q_dot:?}, τ {tau:?}, t {t:e}, n {len})");
    let call = if crba {
        "mech_dynamics_forward_crba"
    } else {
        "mech_dynamics_forward"
    };
    let status = unsafe {
        let f = if crba {
            mech_dynamics_forward_crba
        } else {
            mech_dynamics_forward
        };
        f(
            h,
            q.as_ptr(),
            q_dot.as_ptr(),
            tau.as_ptr(),
            t,
            len,
            q_ddot.as_mut_ptr(),
            report_ptr,
        )
    };
    let r = report.value;
    let mut written = q_ddot.clone();
    if with_report {
        // The error estimate is +∞ where A is singular to working precision (documented).
        let estimate = if r.error_estimate == f64::INFINITY { 0.0 } else { r.error_estimate };
        written.extend([r.backward_error, r.condition, estimate, r.dissipation]);
    }
    check_call(call, status, doubles_untouched(&q_ddot) && report.untouched(), &written);
    expect_handle_status(call, status, bad);
    if len != n {
        assert_ne!(status, MECH_STATUS_OK, "{call}: accepted n = {len} for {n} coordinates");
    }
    if status != MECH_STATUS_OK || !with_report {
        return;
    }
    assert!(r.backward_error >= 0.0, "{call}: negative backward error {r:?}");
    assert!(r.dissipation >= 0.0, "{call}: negative dissipation {r:?}");
    match r.method {
        MECH_FORWARD_ARTICULATED_BODY => {
            assert!(!crba, "mech_dynamics_forward_crba reported the articulated-body route");
            assert!(
                r.condition == -1.0 && r.error_estimate == -1.0,
                "{call}: articulated-body report with a condition {r:?}"
            );
            assert!(
                r.backward_error <= FACTOR_MAX,
                "{call}: articulated-body q̈ accepted with backward error {:e} above 16·(d + 4)·u",
                r.backward_error
            );
        }
        // κ of the empty matrix (no coordinates) is 0; ‖A‖‖A⁻¹‖ ≥ 1 up to its own rounding.
        MECH_FORWARD_MASS_MATRIX => assert!(
            (r.condition >= 1.0 - 8.0 * U || d.dof == 0) && r.error_estimate >= 0.0,
            "{call}: mass-matrix report without κ ≥ 1 and an error estimate: {r:?}"
        ),
        other => panic!("{call}: unknown method {other}"),
    }
    round_trip(d, [&q, &q_dot, &tau], t, &q_ddot, r.backward_error);
}

/// ‖RNEA(q, q̇, q̈) − τ‖∞ ≤ η·S + 2·max ρ_k: the forward solve's backward error η is
/// ‖r‖∞ / max(max_k(ρ_k / (16·(d + 4)·u) + |τ_k|), λ), with r the residual of the library's
/// own RNEA check at the same q̈ and λ the smallest normal double; the scale S uses the
/// smallest factor (d ≥ 1), so it bounds the library's from above, and 2·max ρ covers the
/// rounding of this second evaluation.
fn round_trip(d: &OwnedDynamics, [q, q_dot, tau]: [&[f64]; 3], t: f64, q_ddot: &[f64], eta: f64) {
    let Some((again, rho)) = inverse(d, q, q_dot, q_ddot, t) else {
        return;
    };
    let scale = rho
        .iter()
        .zip(tau)
        .map(|(r, t)| r / FACTOR_MIN + t.abs())
        .fold(f64::MIN_POSITIVE, f64::max);
    let rounding = rho.iter().fold(0.0, |m: f64, r| m.max(*r));
    let allowed = eta * scale * (1.0 + 1e-9) + 2.0 * rounding;
    let worst = again.iter().zip(tau).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(
        worst <= allowed,
        "forward→inverse: ‖τ' − τ‖∞ = {worst:e} above η·S + 2ρ = {allowed:e} (η {eta:e}, S {scale:e}, ρ {rounding:e}); τ {tau:?}, τ' {again:?}"
    );
}

/// Inverse dynamics (with the rnea comparison), the fast aba and the joint reactions.
fn inverse_and_reactions(d: &OwnedDynamics, input: &mut Input) {
    let n = d.dof;
    let q = state_vector(input, n, 3.0);
    let q_dot = state_vector(input, n, 3.0);
    let q_ddot = graded_vector(input, n);
    trace!("inverse(q {q:?}, q̇ {q_dot:?}, q̈ {q_ddot:?})");
    inverse(d, &q, &q_dot, &q_ddot, 0.0);
    let mut a = sentinel_doubles(n);
    let status = unsafe { mech_dynamics_aba(d.handle, q.as_ptr(), q_dot.as_ptr(), q_ddot.as_ptr(), n, a.as_mut_ptr()) };
    check_call("mech_dynamics_aba", status, doubles_untouched(&a), &a);
    let frame = input.enum_i32(3);
    let bodies = if input.u8() < 240 {
        d.bodies
    } else {
        input.below(d.bodies + 2)
    };
    let mut wrenches = sentinel_doubles(6 * bodies);
    let status = unsafe {
        mech_dynamics_reactions(
            d.handle,
            q.as_ptr(),
            q_dot.as_ptr(),
            q_ddot.as_ptr(),
            n,
            frame,
            bodies,
            wrenches.as_mut_ptr(),
        )
    };
    check_call(
        "mech_dynamics_reactions",
        status,
        doubles_untouched(&wrenches),
        &wrenches,
    );
    if bodies != d.bodies || !(0..3).contains(&frame) {
        assert_ne!(
            status, MECH_STATUS_OK,
            "mech_dynamics_reactions: accepted {bodies} bodies, frame {frame}"
        );
    }
}

/// The mass matrix: written only on success, finite and symmetric.
fn mass_matrix(d: &OwnedDynamics, input: &mut Input) {
    let n = d.dof;
    let len = length(input, n);
    let q = state_vector(input, len, 3.0);
    let mut a = sentinel_doubles(len * len);
    let status = unsafe { mech_dynamics_mass_matrix(d.handle, q.as_ptr(), len, a.as_mut_ptr()) };
    check_call("mech_dynamics_mass_matrix", status, doubles_untouched(&a), &a);
    if status != MECH_STATUS_OK {
        return;
    }
    let largest = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for i in 0..n {
        for j in 0..i {
            let (x, y) = (a[i + n * j], a[j + n * i]);
            assert!(
                (x - y).abs() <= 4.0 * U * largest,
                "mass matrix not symmetric: A[{i},{j}] = {x:e}, A[{j},{i}] = {y:e}"
            );
        }
    }
}

fn forward_constrained(d: &OwnedDynamics, loads: &Loads, input: &mut Input) {
    let n = d.dof;
    let q = state_vector(input, n, 3.0);
    let q_dot = state_vector(input, n, 3.0);
    let tau = graded_vector(input, n);
    let m = if input.u8() < 240 {
        loads.equations
    } else {
        input.below(loads.equations + 2)
    };
    let mut q_ddot = sentinel_doubles(n);
    let mut multipliers = sentinel_doubles(m);
    let mut report = Sentinel::<mech_constrained_report_t>::new();
    trace!("forward_constrained(q {q:?}, q̇ {q_dot:?}, τ {tau:?}, m {m})");
    let status = unsafe {
        mech_dynamics_forward_constrained(
            d.handle,
            q.as_ptr(),
            q_dot.as_ptr(),
            tau.as_ptr(),
            0.0,
            n,
            m,
            q_ddot.as_mut_ptr(),
            multipliers.as_mut_ptr(),
            report.ptr(),
        )
    };
    let mut written = q_ddot.clone();
    written.extend_from_slice(&multipliers);
    written.extend_from_slice(doubles_of(&report.value));
    let untouched = doubles_untouched(&q_ddot) && doubles_untouched(&multipliers) && report.untouched();
    check_call("mech_dynamics_forward_constrained", status, untouched, &written);
    if m != loads.equations {
        assert_ne!(status, MECH_STATUS_OK, "forward_constrained: accepted m = {m}");
    }
    if status == MECH_STATUS_OK {
        let r = report.value;
        assert!(
            r.position_drift >= 0.0 && r.velocity_drift >= 0.0 && r.backward_error >= 0.0,
            "forward_constrained: a negative report entry {r:?}"
        );
    }
}

/// Damped modes: the count query (capacity 0), then a buffer of the size it gave (or a
/// short one).
fn damped_modes(d: &OwnedDynamics, input: &mut Input) {
    let n = d.dof;
    let q0 = state_vector(input, n, 2.0);
    let mut count = Sentinel::<usize>::new();
    let status = unsafe {
        mech_dynamics_damped_modes(
            d.handle,
            q0.as_ptr(),
            n,
            0,
            std::ptr::null_mut(),
            count.ptr(),
            std::ptr::null_mut(),
        )
    };
    trace!("damped_modes(q0 {q0:?}): query status {status}");
    let untouched = count.untouched() || status == MECH_STATUS_BUFFER_TOO_SMALL;
    check_call("mech_dynamics_damped_modes (query)", status, untouched, &[]);
    if status == MECH_STATUS_OK {
        assert_eq!(count.value, 0, "damped modes: a capacity of 0 succeeded with modes");
        assert_eq!(n, 0, "damped modes: no modes for n = {n}");
        return;
    }
    if status != MECH_STATUS_BUFFER_TOO_SMALL {
        return;
    }
    let needed = count.value;
    assert!(
        (n..=2 * n).contains(&needed),
        "damped modes: {needed} modes for n = {n} (documented n … 2n)"
    );
    let capacity = if input.u8() < 230 { needed } else { input.below(needed) };
    let mut modes = vec![Sentinel::<mech_damped_mode_t>::new().value; capacity];
    let mut written = Sentinel::<usize>::new();
    let mut gradient = Sentinel::<f64>::new();
    let status = unsafe {
        mech_dynamics_damped_modes(
            d.handle,
            q0.as_ptr(),
            n,
            capacity,
            modes.as_mut_ptr(),
            written.ptr(),
            gradient.ptr(),
        )
    };
    // The same call again: the count must be the one the query gave, whatever the capacity.
    if status == MECH_STATUS_BUFFER_TOO_SMALL || (status == MECH_STATUS_OK && capacity < needed) {
        assert_eq!(
            written.value, needed,
            "damped modes: the count changed between calls (capacity {capacity}, status {status})"
        );
        assert!(
            capacity < needed,
            "damped modes: BUFFER_TOO_SMALL for capacity {capacity} ≥ {needed}"
        );
        return;
    }
    let mut numbers = vec![gradient.value];
    for m in &modes {
        numbers.extend([m.natural_frequency, m.damped_frequency, m.damping_ratio]);
        numbers.extend(
            m.s_re
                .iter()
                .chain(&m.s_im)
                .chain(&m.error_bound)
                .chain(&m.backward_error),
        );
    }
    check_call(
        "mech_dynamics_damped_modes",
        status,
        written.untouched() && gradient.untouched(),
        &numbers,
    );
    if status != MECH_STATUS_OK {
        return;
    }
    assert_eq!(written.value, needed, "damped modes: the count changed between calls");
    for (i, m) in modes.iter().enumerate() {
        assert!(
            (0..=8).contains(&m.kind) && (1..=2).contains(&m.eigenvalue_count),
            "damped mode {i}: kind {} with {} eigenvalues",
            m.kind,
            m.eigenvalue_count
        );
        assert!(
            m.error_bound.iter().chain(&m.backward_error).all(|e| *e >= 0.0)
                && (m.natural_frequency >= 0.0 || m.natural_frequency == -1.0)
                && m.damped_frequency >= 0.0,
            "damped mode {i}: negative bound or frequency {m:?}"
        );
    }
    // A third identical call: the handle carries nothing from one call to the next.
    let mut again = vec![Sentinel::<mech_damped_mode_t>::new().value; capacity];
    let (mut count_again, mut gradient_again) = (Sentinel::<usize>::new(), Sentinel::<f64>::new());
    let status = unsafe {
        mech_dynamics_damped_modes(
            d.handle,
            q0.as_ptr(),
            n,
            capacity,
            again.as_mut_ptr(),
            count_again.ptr(),
            gradient_again.ptr(),
        )
    };
    assert_eq!(status, MECH_STATUS_OK, "damped modes: a repeated call failed");
    assert_eq!(
        count_again.value, needed,
        "damped modes: the count changed between calls"
    );
    assert_eq!(
        gradient_again.value.to_bits(),
        gradient.value.to_bits(),
        "damped modes: the gradient norm changed between calls"
    );
    for (i, (m, r)) in modes.iter().zip(&again).enumerate() {
        assert_eq!(record_bits(m), record_bits(r), "damped mode {i} changed between calls");
    }
}

/// Every field of a damped-mode record as bits (the record has padding, which is not compared).
fn record_bits(m: &mech_damped_mode_t) -> Vec<u64> {
    let mut bits = vec![m.kind as u64, m.eigenvalue_count as u64];
    bits.extend(
        [m.natural_frequency, m.damped_frequency, m.damping_ratio]
            .iter()
            .chain(&m.s_re)
            .chain(&m.s_im)
            .chain(&m.error_bound)
            .chain(&m.backward_error)
            .map(|v| v.to_bits()),
    );
    bits
}

/// The torque-free body: the exact motion (R orthonormal, T and |L| kept) and the Lie-group
/// integration with bounded work (≤ 64 steps of the first run, a tolerance of at least 1e-7).
fn free_body(input: &mut Input) {
    let moments = if input.u8() < 230 {
        let base = graded(input, 10);
        [
            base * (0.2 + input.fraction()),
            base * (0.2 + input.fraction()),
            base * (0.2 + input.fraction()),
        ]
    } else {
        input.vec3_any()
    };
    let rotation = mech_mat3_t { m: input.mat3() };
    let omega = if input.u8() < 230 {
        input.vec3_moderate(3.0)
    } else {
        input.vec3_any()
    };
    let start = mech_free_body_state_t {
        rotation,
        omega: v3(omega),
    };
    let inertia = v3(moments);
    if input.bool() {
        let t = any_or(input, 10.0);
        let mut out = Sentinel::<mech_free_body_state_t>::new();
        trace!("free_body_exact({moments:?}, {start:?}, {t:e})");
        let status = unsafe { mech_free_body_exact(&inertia, &start, t, out.ptr()) };
        check_call("mech_free_body_exact", status, out.untouched(), doubles_of(&out.value));
        if status == MECH_STATUS_OK {
            free_body_invariants(moments, &start, &out.value);
        }
        return;
    }
    let method = input.enum_i32(5);
    let duration = any_or(input, 2.0);
    let max_step = if input.u8() < 224 {
        duration.abs() / (1.0 + input.below(64) as f64)
    } else {
        input.any_f64()
    };
    let tolerance = if input.u8() < 224 {
        10f64.powi(-(input.below(8) as i32))
    } else {
        input.any_f64()
    };
    let spin =
        moments.iter().fold(0.0f64, |m, i| m.max(i.abs())) / moments.iter().fold(f64::INFINITY, |m, i| m.min(i.abs()));
    let turns = omega.iter().map(|w| w.abs()).sum::<f64>() * duration.abs() * spin;
    let bounded = (duration.abs() / max_step.abs()) <= 64.0 && tolerance >= 1e-7 && turns <= 20.0;
    if tolerance.is_finite()
        && tolerance > 0.0
        && max_step.is_finite()
        && max_step > 0.0
        && duration.is_finite()
        && duration > 0.0
        && !bounded
    {
        return; // a valid request whose work the harness does not bound
    }
    let mut out = Sentinel::<mech_free_body_state_t>::new();
    let mut report = Sentinel::<mech_free_body_report_t>::new();
    trace!("free_body_integrate({moments:?}, {start:?}, {duration:e}, {method}, {max_step:e}, {tolerance:e})");
    let status = unsafe {
        mech_free_body_integrate(
            &inertia,
            &start,
            duration,
            method,
            max_step,
            tolerance,
            out.ptr(),
            report.ptr(),
        )
    };
    let mut written = doubles_of(&out.value).to_vec();
    written.extend([report.value.attitude_error, report.value.omega_error]);
    check_call(
        "mech_free_body_integrate",
        status,
        out.untouched() && report.untouched(),
        &written,
    );
}

fn free_body_invariants(moments: [f64; 3], start: &mech_free_body_state_t, end: &mech_free_body_state_t) {
    let r = end.rotation.m;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k + 3 * i] * r[k + 3 * j]).sum();
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!((dot - expected).abs() <= 1e-9, "free body: RᵀR[{i},{j}] = {dot}");
        }
    }
    let w0 = [start.omega.x, start.omega.y, start.omega.z];
    let w1 = [end.omega.x, end.omega.y, end.omega.z];
    let energy = |w: &[f64; 3]| (0..3).map(|k| moments[k] * w[k] * w[k]).sum::<f64>();
    let momentum = |w: &[f64; 3]| (0..3).map(|k| (moments[k] * w[k]).powi(2)).sum::<f64>().sqrt();
    let (t0, t1) = (energy(&w0), energy(&w1));
    let (l0, l1) = (momentum(&w0), momentum(&w1));
    if !(t0.is_finite() && l0.is_finite() && t0 > 0.0) {
        return;
    }
    assert!((t1 - t0).abs() <= 1e-8 * t0, "free body: 2T went from {t0:e} to {t1:e}");
    assert!(
        (l1 - l0).abs() <= 1e-8 * l0,
        "free body: |L| went from {l0:e} to {l1:e}"
    );
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    if input.u8() < 16 {
        free_body(&mut input);
        return;
    }
    let Some(d) = build_dynamics(&mut input) else { return };
    let mut loads = Loads {
        dampers: 0,
        charges: 0,
        equations: 0,
    };
    for _ in 0..1 + input.below(8) {
        if input.is_empty() {
            break;
        }
        match input.u8() % 10 {
            0 => add_damper(&d, &mut loads, &mut input),
            1 => add_charge(&d, &mut loads, &mut input),
            2 => add_constraint(&d, &mut loads, &mut input),
            3 | 4 => forward(&d, &mut input),
            5 => inverse_and_reactions(&d, &mut input),
            6 => mass_matrix(&d, &mut input),
            7 => forward_constrained(&d, &loads, &mut input),
            8 => damped_modes(&d, &mut input),
            _ => free_body(&mut input),
        }
    }
});
