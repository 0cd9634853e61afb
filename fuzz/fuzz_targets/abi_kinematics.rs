//! The kinematics C ABI: a sequence of handle-free rotation and motion calls and of calls on
//! one tree handle (built, finalized, driven through states), with arbitrary numbers. Besides
//! the output contract (`oracle`), the round trips must close: Euler angles, quaternions, the
//! rotation vector and the axis-angle form all describe the rotation they came from; Euler
//! rates map back to the angular velocity; and with the base at rest the velocity of a body
//! point is its Jacobian times q̇.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::input::{mat_vec, rotation_of};
use mechanica_fuzz::oracle::{Sentinel, check_outputs, check_status, doubles_of, doubles_untouched, sentinel_doubles};
use mechanica_fuzz::tree::JointLayout;
use mechanica_fuzz::{Input, trace};

const MAX_BODIES: usize = 8;

fn v3(a: [f64; 3]) -> mech_vec3_t {
    mech_vec3_t {
        x: a[0],
        y: a[1],
        z: a[2],
    }
}

fn arr(v: &mech_vec3_t) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn m3(m: [f64; 9]) -> mech_mat3_t {
    mech_mat3_t { m }
}

/// max |a − b| over the entries.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// ‖RᵀR − I‖ (max entry) and det R of a column-major matrix.
fn orthonormality(r: &[f64; 9]) -> (f64, f64) {
    let mut worst: f64 = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k + 3 * i] * r[k + 3 * j]).sum();
            worst = worst.max((dot - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    let det =
        r[0] * (r[4] * r[8] - r[7] * r[5]) - r[3] * (r[1] * r[8] - r[7] * r[2]) + r[6] * (r[1] * r[5] - r[4] * r[2]);
    (worst, det)
}

fn assert_rotation(call: &str, r: &[f64; 9]) {
    let (error, det) = orthonormality(r);
    assert!(
        error <= 1e-12 && (det - 1.0).abs() <= 1e-12,
        "{call}: not a rotation (‖RᵀR − I‖ = {error:e}, det = {det})"
    );
}

/// Rotation from Euler angles, then back to angles and forward again: the same rotation.
fn euler_round_trip(input: &mut Input) {
    let sequence = input.enum_i32(12);
    let angles = input.vec3_any();
    let mut r = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_rotation_from_euler(sequence, angles.as_ptr(), r.ptr()) };
    check_outputs("mech_rotation_from_euler", status, r.untouched(), &r.value.m);
    if status != MECH_STATUS_OK {
        return;
    }
    assert_rotation("mech_rotation_from_euler", &r.value.m);
    let mut back = sentinel_doubles(3);
    let mut lock = Sentinel::<i32>::new();
    let mut distance_out = Sentinel::<f64>::new();
    let status =
        unsafe { mech_euler_from_rotation(&r.value, sequence, back.as_mut_ptr(), lock.ptr(), distance_out.ptr()) };
    check_outputs("mech_euler_from_rotation", status, doubles_untouched(&back), &back);
    assert_eq!(status, MECH_STATUS_OK, "a rotation from Euler angles has Euler angles");
    let mut again = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_rotation_from_euler(sequence, back.as_ptr(), again.ptr()) };
    check_status("mech_rotation_from_euler", status);
    let gap = distance(&r.value.m, &again.value.m);
    assert!(
        gap <= 1e-9,
        "Euler round trip of {angles:?} (sequence {sequence}) is off by {gap:e}"
    );
}

/// Rotation → quaternion → rotation, and rotation vector → rotation → rotation vector.
fn quaternion_and_log_round_trips(input: &mut Input) {
    let matrix = m3(input.mat3());
    let mut q = Sentinel::<mech_quat_t>::new();
    let status = unsafe { mech_quat_from_rotation_matrix(&matrix, q.ptr()) };
    check_outputs(
        "mech_quat_from_rotation_matrix",
        status,
        q.untouched(),
        doubles_of(&q.value),
    );
    if status == MECH_STATUS_OK {
        assert!(q.value.w >= 0.0, "quaternion with w < 0");
        let mut r = Sentinel::<mech_mat3_t>::new();
        let status = unsafe { mech_rotation_matrix_from_quat(&q.value, MECH_QUAT_REQUIRE_UNIT, r.ptr()) };
        assert_eq!(status, MECH_STATUS_OK, "the quaternion of a rotation is not unit");
        let gap = distance(&r.value.m, &matrix.m);
        assert!(gap <= 1e-11, "rotation → quaternion → rotation is off by {gap:e}");
    }
    let phi = input.vec3_any();
    let mut r = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_rotation_exp(&v3(phi), r.ptr()) };
    check_outputs("mech_rotation_exp", status, r.untouched(), &r.value.m);
    if status != MECH_STATUS_OK {
        return;
    }
    assert_rotation("mech_rotation_exp", &r.value.m);
    let mut log = Sentinel::<mech_vec3_t>::new();
    let status = unsafe { mech_rotation_log(&r.value, log.ptr()) };
    check_outputs("mech_rotation_log", status, log.untouched(), doubles_of(&log.value));
    assert_eq!(status, MECH_STATUS_OK, "exp(φ) has no logarithm");
    let norm = arr(&log.value).iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!(norm <= std::f64::consts::PI + 1e-12, "|log| = {norm} > π");
    let mut again = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_rotation_exp(&log.value, again.ptr()) };
    check_status("mech_rotation_exp", status);
    let gap = distance(&r.value.m, &again.value.m);
    assert!(
        gap <= 1e-11,
        "exp(log(exp(φ))) differs from exp(φ) by {gap:e} for φ = {phi:?}"
    );
}

/// Axis-angle equals exp(angle·axis); the polar factor is a rotation at the stated distance.
fn axis_angle_and_orthonormalize(input: &mut Input) {
    let axis = if input.bool() {
        input.unit_vec3()
    } else {
        input.vec3_any()
    };
    let angle = if input.bool() {
        input.moderate(10.0)
    } else {
        input.any_f64()
    };
    let mut r = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_rotation_from_axis_angle(&v3(axis), angle, r.ptr()) };
    check_outputs("mech_rotation_from_axis_angle", status, r.untouched(), &r.value.m);
    if status == MECH_STATUS_OK && angle.abs() <= 10.0 {
        let mut e = Sentinel::<mech_mat3_t>::new();
        let status = unsafe { mech_rotation_exp(&v3(axis.map(|c| c * angle)), e.ptr()) };
        assert_eq!(status, MECH_STATUS_OK);
        let gap = distance(&r.value.m, &e.value.m);
        assert!(
            gap <= 1e-12 * (1.0 + angle.abs()),
            "axis-angle and exp differ by {gap:e}"
        );
    }
    let matrix = input.mat3();
    let mut polar = Sentinel::<mech_mat3_t>::new();
    let mut correction = Sentinel::<f64>::new();
    let status = unsafe { mech_rotation_orthonormalize(&m3(matrix), polar.ptr(), correction.ptr()) };
    let untouched = polar.untouched() && correction.untouched();
    let mut written = polar.value.m.to_vec();
    written.push(correction.value);
    check_outputs("mech_rotation_orthonormalize", status, untouched, &written);
    if status == MECH_STATUS_OK {
        trace!("orthonormalize({matrix:?}) = {:?}", polar.value.m);
        assert_rotation("mech_rotation_orthonormalize", &polar.value.m);
        let frobenius = matrix
            .iter()
            .zip(&polar.value.m)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let scale = matrix.iter().map(|a| a * a).sum::<f64>().sqrt();
        assert!(
            (frobenius - correction.value).abs() <= 1e-10 * (scale + 1.0),
            "correction {} but ‖M − R‖ = {frobenius}",
            correction.value
        );
    }
}

/// Rates → ω → rates → ω: the last ω is the first (the forward map is well conditioned).
fn euler_rates(input: &mut Input) {
    let sequence = input.enum_i32(12);
    let frame = input.enum_i32(2);
    let angles = input.vec3_any();
    let rates = input.vec3_any();
    let mut omega = Sentinel::<mech_vec3_t>::new();
    let status = unsafe {
        mech_angular_velocity_from_euler_rates(sequence, angles.as_ptr(), rates.as_ptr(), frame, omega.ptr())
    };
    check_outputs(
        "mech_angular_velocity_from_euler_rates",
        status,
        omega.untouched(),
        doubles_of(&omega.value),
    );
    if status != MECH_STATUS_OK {
        return;
    }
    let mut back = sentinel_doubles(3);
    let status = unsafe {
        mech_euler_rates_from_angular_velocity(sequence, angles.as_ptr(), &omega.value, frame, back.as_mut_ptr())
    };
    check_outputs(
        "mech_euler_rates_from_angular_velocity",
        status,
        doubles_untouched(&back),
        &back,
    );
    if status != MECH_STATUS_OK {
        return;
    }
    let mut again = Sentinel::<mech_vec3_t>::new();
    let status =
        unsafe { mech_angular_velocity_from_euler_rates(sequence, angles.as_ptr(), back.as_ptr(), frame, again.ptr()) };
    check_status("mech_angular_velocity_from_euler_rates", status);
    if status == MECH_STATUS_OK {
        let scale = back.iter().map(|c| c.abs()).sum::<f64>() + arr(&omega.value).iter().map(|c| c.abs()).sum::<f64>();
        let gap = distance(doubles_of(&omega.value), doubles_of(&again.value));
        mechanica_fuzz::trace!(
            "rates(sequence {sequence}, frame {frame}, angles {angles:?}, rates {rates:?}) → ω {:?} → {back:?} → {:?}",
            omega.value,
            again.value
        );
        assert!(
            gap <= 1e-12 * scale + 1e-300,
            "ω → rates → ω is off by {gap:e} (scale {scale:e})"
        );
    }
}

/// Velocity and acceleration fields and the relative-motion decomposition; ω from Ṙ = [ω]× R.
fn fields(input: &mut Input) {
    let motion = mech_rigid_motion_t {
        rotation: m3(input.mat3()),
        c: v3(input.vec3_any()),
        c_dot: v3(input.vec3_any()),
        c_ddot: v3(input.vec3_any()),
        omega: v3(input.vec3_any()),
        omega_dot: v3(input.vec3_any()),
    };
    let x = v3(input.vec3_any());
    let mut v = Sentinel::<mech_vec3_t>::new();
    let status = unsafe { mech_velocity_field(&motion, &x, v.ptr()) };
    check_outputs("mech_velocity_field", status, v.untouched(), doubles_of(&v.value));
    let mut a = Sentinel::<mech_vec3_t>::new();
    let status = unsafe { mech_acceleration_field(&motion, &x, a.ptr()) };
    check_outputs("mech_acceleration_field", status, a.untouched(), doubles_of(&a.value));
    let (xi, xi_dot, xi_ddot) = (v3(input.vec3_any()), v3(input.vec3_any()), v3(input.vec3_any()));
    let mut d = Sentinel::<mech_relative_decomposition_t>::new();
    let status = unsafe { mech_relative_motion_decompose(&motion, &xi, &xi_dot, &xi_ddot, d.ptr()) };
    check_outputs(
        "mech_relative_motion_decompose",
        status,
        d.untouched(),
        doubles_of(&d.value),
    );

    let r = rotation_of(input.unit_quaternion());
    let w = input.vec3_moderate(100.0);
    let skew = [0.0, w[2], -w[1], -w[2], 0.0, w[0], w[1], -w[0], 0.0];
    let mut rate = [0.0; 9];
    for col in 0..3 {
        let column = mat_vec(&skew, [r[3 * col], r[3 * col + 1], r[3 * col + 2]]);
        rate[3 * col..3 * col + 3].copy_from_slice(&column);
    }
    let mut omega = Sentinel::<mech_vec3_t>::new();
    let status = unsafe { mech_angular_velocity_from_rate(&m3(r), &m3(rate), omega.ptr()) };
    check_outputs(
        "mech_angular_velocity_from_rate",
        status,
        omega.untouched(),
        doubles_of(&omega.value),
    );
    assert_eq!(status, MECH_STATUS_OK, "a rotation from a unit quaternion was refused");
    let gap = distance(&arr(&omega.value), &w);
    assert!(
        gap <= 1e-12 * (1.0 + w.iter().map(|c| c.abs()).sum::<f64>()),
        "ω from Ṙ = [ω]×R is off by {gap:e}"
    );
}

/// One tree handle driven by the input; dropped (destroyed) at the end.
struct Tree {
    handle: *mut mech_tree_t,
    bodies: usize,
    finalized: bool,
    dof: usize,
    q_dot: Option<Vec<f64>>,
    base_moving: bool,
    /// Σ |placement translation| of the bodies: the lever arms the velocities are built from.
    reach: f64,
    /// Coordinates that are joint translations (prismatic; planar x, y; free position), in the
    /// order of the bodies, and Σ |q_k| over them at the current state: lever arms too.
    translations: Vec<usize>,
    coordinates: usize,
    translated: f64,
}

impl Drop for Tree {
    fn drop(&mut self) {
        unsafe { mech_tree_destroy(self.handle) };
    }
}

impl Tree {
    fn new() -> Self {
        let mut handle = std::ptr::null_mut();
        let status = unsafe { mech_tree_create(&mut handle) };
        assert_eq!(status, MECH_STATUS_OK);
        Tree {
            handle,
            bodies: 0,
            finalized: false,
            dof: 0,
            q_dot: None,
            base_moving: false,
            reach: 0.0,
            translations: Vec::new(),
            coordinates: 0,
            translated: 0.0,
        }
    }

    fn add_body(&mut self, input: &mut Input) {
        if self.bodies >= MAX_BODIES {
            return;
        }
        let parent = input.below(self.bodies + 2) as i64 - 1;
        let joint = input.enum_i32(6);
        let axis = if input.bool() {
            input.unit_vec3()
        } else {
            input.vec3_any()
        };
        let rotation = m3(input.mat3());
        let translation = v3(if input.bool() {
            input.vec3_moderate(2.0)
        } else {
            input.vec3_any()
        });
        let mut body = Sentinel::<usize>::new();
        let status = unsafe {
            mech_tree_add_body(
                self.handle,
                parent,
                joint,
                &v3(axis),
                &rotation,
                &translation,
                body.ptr(),
            )
        };
        check_status("mech_tree_add_body", status);
        mechanica_fuzz::trace!("add_body(parent {parent}, joint {joint}) = {status}");
        if status == MECH_STATUS_OK {
            assert_eq!(body.value, self.bodies, "bodies are numbered in the order of the calls");
            self.bodies += 1;
            self.reach += translation.x.abs() + translation.y.abs() + translation.z.abs();
            let layout = JointLayout::of(joint);
            self.translations
                .extend(layout.translation.map(|k| self.coordinates + k));
            self.coordinates += layout.dof;
        } else {
            assert!(body.untouched());
        }
    }

    fn finalize(&mut self) {
        let status = unsafe { mech_tree_finalize(self.handle) };
        check_status("mech_tree_finalize", status);
        let (mut count, mut dof) = (Sentinel::<usize>::new(), Sentinel::<usize>::new());
        let size = unsafe { mech_tree_size(self.handle, count.ptr(), dof.ptr()) };
        check_status("mech_tree_size", size);
        if status == MECH_STATUS_OK || self.finalized {
            assert_eq!(size, MECH_STATUS_OK);
            assert_eq!(count.value, self.bodies);
            assert!(dof.value <= 6 * self.bodies);
            self.finalized = true;
            self.dof = dof.value;
        } else {
            assert!(count.untouched() && dof.untouched());
        }
    }

    fn set_state(&mut self, input: &mut Input) {
        let n = if input.u8() < 230 { self.dof } else { input.below(64) };
        let q: Vec<f64> = (0..n).map(|_| input.any_f64()).collect();
        let q_dot: Vec<f64> = (0..n)
            .map(|_| {
                if input.bool() {
                    input.moderate(10.0)
                } else {
                    input.any_f64()
                }
            })
            .collect();
        let status = unsafe { mech_tree_set_state(self.handle, q.as_ptr(), q_dot.as_ptr(), n) };
        check_status("mech_tree_set_state", status);
        mechanica_fuzz::trace!("set_state(q {q:?}, q̇ {q_dot:?}) = {status}");
        self.q_dot = (status == MECH_STATUS_OK).then_some(q_dot);
        if status == MECH_STATUS_OK {
            self.translated = self.translations.iter().map(|&k| q[k].abs()).sum();
        }
    }

    fn set_base(&mut self, input: &mut Input) {
        let base = mech_base_state_t {
            rotation: m3(input.mat3()),
            position: v3(input.vec3_any()),
            omega: v3(input.vec3_any()),
            velocity: v3(input.vec3_any()),
            omega_dot: v3(input.vec3_any()),
            acceleration: v3(input.vec3_any()),
        };
        let status = unsafe { mech_tree_set_base(self.handle, &base) };
        check_status("mech_tree_set_base", status);
        mechanica_fuzz::trace!("set_base({base:?}) = {status}");
        if status == MECH_STATUS_OK {
            self.base_moving = arr(&base.omega) != [0.0; 3] || arr(&base.velocity) != [0.0; 3];
            self.q_dot = None; // setting the base discards the state
        }
    }

    fn set_accelerations(&mut self, input: &mut Input) {
        let n = if input.u8() < 230 { self.dof } else { input.below(64) };
        let q_ddot: Vec<f64> = (0..n).map(|_| input.any_f64()).collect();
        let status = unsafe { mech_tree_set_accelerations(self.handle, q_ddot.as_ptr(), n) };
        check_status("mech_tree_set_accelerations", status);
    }

    fn query(&mut self, input: &mut Input) {
        let body = input.below(self.bodies + 1);
        let point = v3(if input.bool() {
            input.vec3_moderate(2.0)
        } else {
            input.vec3_any()
        });
        let (mut rotation, mut position) = (Sentinel::<mech_mat3_t>::new(), Sentinel::<mech_vec3_t>::new());
        let status = unsafe { mech_tree_body_pose(self.handle, body, rotation.ptr(), position.ptr()) };
        let mut written = rotation.value.m.to_vec();
        written.extend_from_slice(doubles_of(&position.value));
        check_outputs(
            "mech_tree_body_pose",
            status,
            rotation.untouched() && position.untouched(),
            &written,
        );
        if status == MECH_STATUS_OK {
            let (error, det) = orthonormality(&rotation.value.m);
            assert!(
                error <= 1e-9 && (det - 1.0).abs() <= 1e-9,
                "body pose is not a rotation: {error:e}, det {det}"
            );
        }
        let (mut omega, mut velocity) = (Sentinel::<mech_vec3_t>::new(), Sentinel::<mech_vec3_t>::new());
        let status = unsafe { mech_tree_body_velocity(self.handle, body, &point, omega.ptr(), velocity.ptr()) };
        let mut written = doubles_of(&omega.value).to_vec();
        written.extend_from_slice(doubles_of(&velocity.value));
        check_outputs(
            "mech_tree_body_velocity",
            status,
            omega.untouched() && velocity.untouched(),
            &written,
        );
        if status == MECH_STATUS_OK {
            self.check_jacobian(body, &point, arr(&omega.value), arr(&velocity.value));
        }
        let (mut omega_dot, mut acceleration) = (Sentinel::<mech_vec3_t>::new(), Sentinel::<mech_vec3_t>::new());
        let status =
            unsafe { mech_tree_body_acceleration(self.handle, body, &point, omega_dot.ptr(), acceleration.ptr()) };
        let mut written = doubles_of(&omega_dot.value).to_vec();
        written.extend_from_slice(doubles_of(&acceleration.value));
        check_outputs(
            "mech_tree_body_acceleration",
            status,
            omega_dot.untouched() && acceleration.untouched(),
            &written,
        );
        let kind = input.enum_i32(4);
        let capacity = if input.u8() < 230 {
            3 * self.dof
        } else {
            input.below(3 * self.dof + 2)
        };
        let mut jacobian = sentinel_doubles(capacity);
        let status = unsafe { mech_tree_jacobian(self.handle, body, kind, &point, jacobian.as_mut_ptr(), capacity) };
        check_outputs(
            "mech_tree_jacobian",
            status,
            doubles_untouched(&jacobian),
            &jacobian[..capacity.min(3 * self.dof)],
        );
    }

    /// With the base at rest, ω = J_ω q̇ and v = J_p(point) q̇.
    fn check_jacobian(&mut self, body: usize, point: &mech_vec3_t, omega: [f64; 3], velocity: [f64; 3]) {
        let Some(q_dot) = self.q_dot.clone() else { return };
        if self.base_moving {
            return;
        }
        // Rounding is relative to the terms the velocities are built from: q̇ times the lever
        // arms (placements, the point, prismatic offsets in q), not to the result.
        let lever = 1.0 + self.reach + self.translated + point.x.abs() + point.y.abs() + point.z.abs();
        let rate: f64 = q_dot.iter().map(|v| v.abs()).sum();
        // Without velocities the rounding is nil; with an infinite lever (a point or a reach
        // at ±1e308) it is unbounded, and nothing is checked.
        let noise = if rate == 0.0 {
            0.0
        } else if !lever.is_finite() {
            f64::INFINITY
        } else {
            1e-12 * rate * lever
        };
        for (kind, actual) in [(MECH_JACOBIAN_ANGULAR, omega), (MECH_JACOBIAN_POINT, velocity)] {
            let mut jacobian = vec![0.0; 3 * self.dof];
            let status =
                unsafe { mech_tree_jacobian(self.handle, body, kind, point, jacobian.as_mut_ptr(), jacobian.len()) };
            if status == MECH_STATUS_OUT_OF_RANGE {
                // A column can overflow where q̇ is zero and the velocity did not.
                return;
            }
            assert_eq!(
                status,
                MECH_STATUS_OK,
                "velocity known but no Jacobian: {}",
                mechanica_fuzz::oracle::last_error()
            );
            for row in 0..3 {
                let terms = (0..self.dof).map(|k| jacobian[row + 3 * k] * q_dot[k]);
                let (sum, scale) = terms.fold((0.0, 0.0), |(s, a), t: f64| (s + t, a + t.abs()));
                if !scale.is_finite() {
                    return;
                }
                // Angular velocities below the normal range are rounded to the subnormal
                // spacing 2⁻¹⁰⁷⁴ before they meet the lever arms, which the columns' sizes bound.
                let reach: f64 = (0..self.dof).map(|k| jacobian[row + 3 * k].abs()).sum();
                let noise = noise + 16.0 * f64::from_bits(1) * (1.0 + reach + lever);
                assert!(
                    (sum - actual[row]).abs() <= 1e-10 * (scale + actual[row].abs()) + noise,
                    "kind {kind} row {row}: J q̇ = {sum}, the tree says {}; body {body}, point {point:?}, q̇ {q_dot:?}, J {jacobian:?}",
                    actual[row]
                );
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let mut tree = Tree::new();
    let mut steps = 0;
    while !input.is_empty() && steps < 64 {
        steps += 1;
        let op = input.u8() % 11;
        mechanica_fuzz::trace!("op {op}");
        match op {
            0 => euler_round_trip(&mut input),
            1 => quaternion_and_log_round_trips(&mut input),
            2 => axis_angle_and_orthonormalize(&mut input),
            3 => euler_rates(&mut input),
            4 => fields(&mut input),
            5 | 6 => tree.add_body(&mut input),
            7 => tree.finalize(),
            8 => tree.set_state(&mut input),
            9 => {
                if input.bool() {
                    tree.set_base(&mut input)
                } else {
                    tree.set_accelerations(&mut input)
                }
            }
            _ => tree.query(&mut input),
        }
    }
});
