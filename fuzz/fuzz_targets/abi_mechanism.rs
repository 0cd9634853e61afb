//! The mechanism C ABI: a mechanism built from a small tree, loaded by a sequence of calls
//! (gravity, rotating frame, springs, forces, limits) with arbitrary numbers, then its
//! potential, modes and an equilibrium search. Besides the output contract (`oracle`):
//! - the Hessian of U* is symmetric;
//! - without a rotating frame and with every rotation vector zero at q (so that the charts
//!   re-centred at q are the caller's) the modes are those of the dense solver on
//!   (A(q), ∇²U*(q)), with A from mech_tree_mass_matrix, within both error bounds;
//! - an equilibrium reports the potential and gradient norm found again at its q, meets the
//!   tolerance it reports, and a minimum search never ends above its start.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::oracle::{Sentinel, check_outputs, check_status, doubles_untouched, sentinel_doubles};
use mechanica_fuzz::tree::{OwnedTree, body_properties, build_tree, v3};
use mechanica_fuzz::{Input, trace};

struct Mechanism {
    handle: *mut mech_mechanism_t,
    n: usize,
    rotating: bool,
    limited: bool,
    /// Size of the terms the potential sums (stiffness × length², force × length, …): the
    /// rounding of U* and its derivatives is relative to it, not to the result.
    load_scale: f64,
    /// Total mass of the bodies (kg).
    mass: f64,
}

impl Drop for Mechanism {
    fn drop(&mut self) {
        unsafe { mech_mechanism_destroy(self.handle) };
    }
}

fn any_or(input: &mut Input, scale: f64) -> f64 {
    if input.u8() < 224 {
        input.moderate(scale)
    } else {
        input.any_f64()
    }
}

fn vec_or(input: &mut Input, scale: f64) -> mech_vec3_t {
    v3([any_or(input, scale), any_or(input, scale), any_or(input, scale)])
}

/// One load call chosen by the input.
fn load(m: &mut Mechanism, bodies: usize, input: &mut Input) {
    let h = m.handle;
    // Every length in these trees is below REACH (placements ≤ 1, coordinates ≤ 2 per body).
    const REACH: f64 = 16.0;
    let mut magnitude = 0.0;
    let mass = m.mass;
    let mut weigh =
        |x: &mech_vec3_t, power: i32| magnitude += (x.x.abs() + x.y.abs() + x.z.abs()) * (REACH + 1.0).powi(power);
    let (name, status) = match input.u8() % 6 {
        0 => {
            let g = vec_or(input, 10.0);
            weigh(&v3([(g.x.abs() + g.y.abs() + g.z.abs()) * mass, 0.0, 0.0]), 1);
            trace!("set_gravity({g:?})");
            ("mech_mechanism_set_gravity", unsafe {
                mech_mechanism_set_gravity(h, g)
            })
        }
        1 => {
            let axis = if input.u8() < 224 {
                v3(input.unit_vec3())
            } else {
                vec_or(input, 1.0)
            };
            let rate = any_or(input, 3.0);
            weigh(&v3([rate * rate * mass, 0.0, 0.0]), 2);
            trace!("set_rotating_frame({axis:?}, {rate:e})");
            let status = unsafe { mech_mechanism_set_rotating_frame(h, axis, rate) };
            m.rotating |= status == MECH_STATUS_OK;
            ("mech_mechanism_set_rotating_frame", status)
        }
        2 => {
            let coordinate = input.below(m.n + 1);
            let (k, rest) = (any_or(input, 50.0), any_or(input, 1.0));
            weigh(&v3([k * (1.0 + rest.abs()).powi(2), 0.0, 0.0]), 2);
            trace!("add_joint_spring({coordinate}, {k:e}, {rest:e})");
            ("mech_mechanism_add_joint_spring", unsafe {
                mech_mechanism_add_joint_spring(h, coordinate, k, rest)
            })
        }
        3 => {
            let (a, b) = (input.below(bodies + 2) as i64 - 1, input.below(bodies + 2) as i64 - 1);
            let (pa, pb) = (vec_or(input, 1.0), vec_or(input, 1.0));
            let (k, rest) = (any_or(input, 50.0), any_or(input, 1.0));
            let reach = 1.0 + rest.abs() + pa.x.abs() + pa.y.abs() + pa.z.abs() + pb.x.abs() + pb.y.abs() + pb.z.abs();
            weigh(&v3([k * reach * reach, 0.0, 0.0]), 2);
            trace!("add_point_spring({a}, {pa:?}, {b}, {pb:?}, {k:e}, {rest:e})");
            let status = unsafe { mech_mechanism_add_point_spring(h, a, pa, b, pb, k, rest) };
            ("mech_mechanism_add_point_spring", status)
        }
        4 => {
            let body = input.below(bodies + 1);
            let (point, force) = (vec_or(input, 1.0), vec_or(input, 10.0));
            weigh(&force, 1);
            weigh(
                &v3([
                    (force.x.abs() + force.y.abs() + force.z.abs()) * (point.x.abs() + point.y.abs() + point.z.abs()),
                    0.0,
                    0.0,
                ]),
                0,
            );
            trace!("add_force({body}, {point:?}, {force:?})");
            ("mech_mechanism_add_force", unsafe {
                mech_mechanism_add_force(h, body, point, force)
            })
        }
        _ => {
            let coordinate = input.below(m.n + 1);
            let (lo, hi) = (any_or(input, 3.0), any_or(input, 3.0));
            trace!("set_limits({coordinate}, {lo:e}, {hi:e})");
            let status = unsafe { mech_mechanism_set_limits(h, coordinate, lo, hi) };
            m.limited |= status == MECH_STATUS_OK;
            ("mech_mechanism_set_limits", status)
        }
    };
    check_status(name, status);
    if status == MECH_STATUS_OK {
        m.load_scale += magnitude;
    }
}

/// U*, its gradient and Hessian at q; the Hessian must be symmetric.
fn potential(m: &Mechanism, q: &[f64]) -> Option<(f64, Vec<f64>, Vec<f64>)> {
    let n = m.n;
    let mut value = Sentinel::<f64>::new();
    let (mut gradient, mut hessian) = (sentinel_doubles(n), sentinel_doubles(n * n));
    let status = unsafe {
        mech_mechanism_potential(
            m.handle,
            q.as_ptr(),
            n,
            value.ptr(),
            gradient.as_mut_ptr(),
            hessian.as_mut_ptr(),
        )
    };
    let mut written = vec![value.value];
    written.extend_from_slice(&gradient);
    written.extend_from_slice(&hessian);
    check_outputs(
        "mech_mechanism_potential",
        status,
        value.untouched() && doubles_untouched(&gradient) && doubles_untouched(&hessian),
        &written,
    );
    if status != MECH_STATUS_OK {
        return None;
    }
    let largest = hessian.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let tolerance = 1e-9 * largest + 1e-12 * m.load_scale;
    for i in 0..n {
        for j in 0..i {
            let (x, y) = (hessian[i + n * j], hessian[j + n * i]);
            assert!(
                (x - y).abs() <= tolerance,
                "Hessian not symmetric: H[{i},{j}] = {x}, H[{j},{i}] = {y}"
            );
        }
    }
    Some((value.value, gradient, hessian))
}

/// The mechanism's modes at q against the dense solver on (A(q), ∇²U*(q)).
fn modes(m: &Mechanism, tree: &OwnedTree, bodies: &[mech_mass_properties_t], q: &[f64], input: &mut Input) {
    let n = m.n;
    let count = if input.u8() < 240 {
        input.below(n + 1)
    } else {
        input.below(2 * n + 2)
    };
    let slots = if count == 0 { n } else { count };
    let (mut omega_sq, mut bounds) = (sentinel_doubles(slots), sentinel_doubles(slots));
    let mut kinds = vec![-7i32; slots];
    let mut shapes = sentinel_doubles(n * slots);
    let mut found = Sentinel::<usize>::new();
    let mut stability = Sentinel::<mech_stability_t>::new();
    let status = unsafe {
        mech_mechanism_modes(
            m.handle,
            q.as_ptr(),
            n,
            count,
            omega_sq.as_mut_ptr(),
            bounds.as_mut_ptr(),
            kinds.as_mut_ptr(),
            shapes.as_mut_ptr(),
            found.ptr(),
            stability.ptr(),
        )
    };
    check_status("mech_mechanism_modes", status);
    trace!("modes(q {q:?}, count {count}) = {status}");
    if status != MECH_STATUS_OK {
        assert!(
            doubles_untouched(&omega_sq) && found.untouched() && stability.untouched(),
            "failed modes wrote"
        );
        return;
    }
    let k = found.value;
    assert!(k <= slots, "{k} modes in {slots} slots");
    assert!(
        omega_sq[..k]
            .iter()
            .chain(&bounds[..k])
            .all(|v| v.is_finite() || *v == f64::INFINITY),
        "non-finite modes: ω² {:?}, bounds {:?}, kinds {:?}",
        &omega_sq[..k],
        &bounds[..k],
        &kinds[..k]
    );
    if m.rotating || k == 0 || kinds[..k].contains(&MECH_MODAL_KIND_INFINITE) {
        return;
    }
    // The modes are taken in charts re-centred at q. Away from an equilibrium the Hessian
    // depends on the chart (its second derivative meets the nonzero gradient), so the caller's
    // charts give the same pencil only where every rotation vector is zero.
    if tree.rotation_coordinates.iter().any(|&k| q[k] != 0.0) {
        return;
    }
    let Some((_, _, hessian)) = potential(m, q) else { return };
    let zeros = vec![0.0; n];
    if unsafe { mech_tree_set_state(tree.handle, q.as_ptr(), zeros.as_ptr(), n) } != MECH_STATUS_OK {
        return;
    }
    let mut a = vec![0.0; n * n];
    if unsafe { mech_tree_mass_matrix(tree.handle, bodies.as_ptr(), bodies.len(), a.as_mut_ptr(), n) } != MECH_STATUS_OK
    {
        return;
    }
    let mut options = Sentinel::<mech_modal_options_t>::new();
    unsafe { mech_modal_options_default(options.ptr()) };
    let mut result = std::ptr::null_mut();
    let status = unsafe { mech_modal_solve(n, a.as_ptr(), hessian.as_ptr(), &options.value, &mut result) };
    if status != MECH_STATUS_OK {
        return;
    }
    let mut dense = vec![Sentinel::<mech_modal_mode_t>::new().value; n];
    let (mut total, mut dim) = (0usize, 0usize);
    unsafe { mech_modal_result_size(result, &mut total, &mut dim) };
    let copied = unsafe { mech_modal_result_modes(result, dense.as_mut_ptr(), n) };
    unsafe { mech_modal_result_destroy(result) };
    if copied != MECH_STATUS_OK || total < k {
        return;
    }
    for i in 0..k {
        let (w, e) = (dense[i].omega_sq, dense[i].error_bound);
        let allowed = 2.0 * (e + bounds[i]) + 1e-12 * (w.abs() + omega_sq[i].abs());
        assert!(
            (w - omega_sq[i]).abs() <= allowed,
            "mode {i}: ω² {} vs dense {w} (bounds {:e}, {e:e})",
            omega_sq[i],
            bounds[i]
        );
    }
}

/// An equilibrium search from q0, checked by evaluating U* again at its result.
fn equilibrium(m: &Mechanism, q0: &[f64], input: &mut Input) {
    let n = m.n;
    let seek = input.enum_i32(2);
    let max_iterations = input.below(60);
    let tolerance = if input.u8() < 224 { 0.0 } else { input.any_f64() };
    let start = if seek == MECH_SEEK_MINIMUM {
        potential(m, q0).map(|p| p.0)
    } else {
        None
    };
    let mut q = sentinel_doubles(n);
    let mut report = Sentinel::<mech_equilibrium_report_t>::new();
    let status = unsafe {
        mech_mechanism_equilibrium(
            m.handle,
            q0.as_ptr(),
            n,
            seek,
            max_iterations,
            tolerance,
            q.as_mut_ptr(),
            report.ptr(),
        )
    };
    check_status("mech_mechanism_equilibrium", status);
    if status == MECH_STATUS_NOT_CONVERGED {
        return; // q and the report are written on purpose (best point found)
    }
    if status != MECH_STATUS_OK {
        assert!(
            doubles_untouched(&q) && report.untouched(),
            "failed equilibrium search wrote"
        );
        return;
    }
    let r = report.value;
    assert!(
        q.iter().all(|v| v.is_finite()) && r.potential.is_finite() && r.gradient_norm.is_finite(),
        "non-finite equilibrium from q0 = {q0:?}: q = {q:?}, U* = {}, ‖∇U*‖ = {}, tolerance {}",
        r.potential,
        r.gradient_norm,
        r.tolerance
    );
    assert!(
        r.gradient_norm <= r.tolerance,
        "converged with ‖∇U*‖ = {} above its tolerance {}",
        r.gradient_norm,
        r.tolerance
    );
    let Some((value, gradient, _)) = potential(m, &q) else {
        return;
    };
    let scale = value.abs() + 1e-300;
    assert!(
        (value - r.potential).abs() <= 1e-9 * scale,
        "reported U* {} but U*(q) = {value}",
        r.potential
    );
    if !m.limited {
        let norm = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        assert!(
            norm <= 2.0 * r.tolerance + 1e-9 * r.gradient_norm,
            "‖∇U*(q)‖ = {norm} but the search met {}",
            r.tolerance
        );
        if let Some(start) = start {
            assert!(
                value <= start + 1e-9 * (start.abs() + value.abs()),
                "a minimum search rose from {start} to {value}"
            );
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let Some(tree) = build_tree(&mut input) else { return };
    let bodies: Vec<mech_mass_properties_t> = (0..tree.bodies).map(|_| body_properties(&mut input)).collect();
    trace!(
        "tree: {} bodies, {} coordinates; bodies {bodies:?}",
        tree.bodies, tree.dof
    );
    let claimed = if input.u8() < 240 { bodies.len() } else { input.below(6) };
    let mut handle = std::ptr::null_mut();
    let status = unsafe { mech_mechanism_create(tree.handle, bodies.as_ptr(), claimed.min(bodies.len()), &mut handle) };
    check_status("mech_mechanism_create", status);
    if status != MECH_STATUS_OK {
        assert!(handle.is_null());
        return;
    }
    let mut dof = Sentinel::<usize>::new();
    assert_eq!(unsafe { mech_mechanism_dof(handle, dof.ptr()) }, MECH_STATUS_OK);
    assert_eq!(dof.value, tree.dof, "the mechanism's dof differs from its tree's");
    let mass: f64 = bodies.iter().map(|b| b.mass.abs()).sum();
    let mut m = Mechanism {
        handle,
        n: tree.dof,
        rotating: false,
        limited: false,
        load_scale: 0.0,
        mass,
    };
    for _ in 0..input.below(6) {
        load(&mut m, tree.bodies, &mut input);
    }
    let mut q: Vec<f64> = (0..m.n).map(|_| any_or(&mut input, 2.0)).collect();
    if input.bool() {
        // Half the time at the chart centres, where the modes are checked against the dense solver.
        for &k in &tree.rotation_coordinates {
            q[k] = 0.0;
        }
    }
    potential(&m, &q);
    modes(&m, &tree, &bodies, &q, &mut input);
    equilibrium(&m, &q, &mut input);
});
