//! The impulse C ABI: point collisions, impulses on free bodies, point fixation, two-body
//! contacts and mechanism impacts, with arbitrary numbers, held to the output contract
//! (`oracle`) and to mechanics computed here from the velocities the library returns:
//! momentum is conserved, the reported energy change is the change of ½ m v² + ½ ωᵀJω, and
//! no impact gains energy under Stronge's law (any friction), under Poisson's law when the
//! friction impulse keeps a constant ratio to the normal impulse (frictionless or sticking
//! contacts, where the laws agree; with slip that halts or reverses Poisson's law may gain
//! energy), nor in point collisions, fixations and the guarded simultaneous model.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::Input;
use mechanica_fuzz::input::mat_vec;
use mechanica_fuzz::oracle::{Sentinel, check_outputs, check_status, doubles_of, doubles_untouched, sentinel_doubles};
use mechanica_fuzz::tree::{body_properties, build_tree, set_state, v3};

fn arr(v: &mech_vec3_t) -> [f64; 3] {
    [v.x, v.y, v.z]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// The distance from |x| to the next larger double: the rounding of a stored velocity, which a
/// large mass turns into a momentum the impulse need not match more closely.
fn spacing(x: f64) -> f64 {
    let a = x.abs();
    f64::from_bits(a.to_bits() + 1) - a
}
/// ‖a‖ without squaring the components (squares of 1e-200 underflow to zero).
fn norm(a: [f64; 3]) -> f64 {
    a[0].hypot(a[1]).hypot(a[2])
}
/// The power of two 2^⌊log₂ x⌋ for x > 1 (1 otherwise): dividing masses and velocities by it
/// keeps the oracles' energies m v² in range for inputs up to f64::MAX.
fn range_scale(x: f64) -> f64 {
    if x > 1.0 && x.is_finite() {
        2f64.powi(x.log2().floor() as i32)
    } else {
        1.0
    }
}

fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn velocity(input: &mut Input, scale: f64) -> [f64; 3] {
    if input.u8() < 224 {
        input.vec3_moderate(scale)
    } else {
        input.vec3_any()
    }
}
fn scalar(input: &mut Input, lo: f64, hi: f64) -> f64 {
    if input.u8() < 224 {
        lo + (hi - lo) * input.fraction()
    } else {
        input.any_f64()
    }
}

/// Two points on a line: momentum kept, energy never gained, the energy change as reported.
fn collinear(input: &mut Input) {
    let (m1, v1, m2, v2) = (
        scalar(input, 0.01, 10.0),
        scalar(input, -5.0, 5.0),
        scalar(input, 0.01, 10.0),
        scalar(input, -5.0, 5.0),
    );
    let e = scalar(input, 0.0, 1.0);
    let mut out = Sentinel::<mech_collinear_impact_t>::new();
    let status = unsafe { mech_collide_collinear(m1, v1, m2, v2, e, out.ptr()) };
    check_outputs(
        "mech_collide_collinear",
        status,
        out.untouched(),
        doubles_of(&out.value),
    );
    if status != MECH_STATUS_OK {
        return;
    }
    let o = out.value;
    // Momenta and energies in units of s·w and s·w², exact powers of two that keep them in
    // range for masses and velocities up to f64::MAX.
    let (s, w) = (
        range_scale(largest(&[m1, m2])),
        range_scale(largest(&[v1, v2, o.v1_after, o.v2_after])),
    );
    let (m1, m2) = (m1 / s, m2 / s);
    let (v1, v2, a1, a2) = (v1 / w, v2 / w, o.v1_after / w, o.v2_after / w);
    let p_scale = (m1 * v1).abs() + (m2 * v2).abs();
    assert!(
        (m1 * a1 + m2 * a2 - m1 * v1 - m2 * v2).abs() <= 1e-14 * p_scale + f64::MIN_POSITIVE,
        "momentum: m {m1:e}, {m2:e}, v {v1:e}, {v2:e}, e {e} → {a1:e}, {a2:e} (units of {s:e}, {w:e})"
    );
    assert!(
        (m2 * (a2 - v2) - o.impulse_on_2 / s / w).abs() <= 1e-14 * p_scale + f64::MIN_POSITIVE,
        "impulse"
    );
    let t = 0.5 * (m1 * v1 * v1 + m2 * v2 * v2);
    let direct = 0.5 * (m1 * (a1 * a1 - v1 * v1) + m2 * (a2 * a2 - v2 * v2));
    assert!(direct <= 1e-14 * t, "a collinear collision gained {direct} of {t}");
    let reported = o.energy_change / s / w / w;
    assert!(
        (direct - reported).abs() <= 1e-13 * t + f64::MIN_POSITIVE,
        "energy change {reported} vs {direct} (units of {s:e}·{w:e}²)",
    );
}

/// Two smooth points: momentum kept, tangential velocities unchanged, no energy gained.
fn points(input: &mut Input) {
    let (m1, m2) = (scalar(input, 0.01, 10.0), scalar(input, 0.01, 10.0));
    let (v1, v2) = (velocity(input, 5.0), velocity(input, 5.0));
    let n = if input.u8() < 240 {
        input.unit_vec3()
    } else {
        input.vec3_any()
    };
    let e = scalar(input, 0.0, 1.0);
    let mut out = Sentinel::<mech_point_impact_t>::new();
    let status = unsafe { mech_collide_points(m1, &v3(v1), m2, &v3(v2), &v3(n), e, out.ptr()) };
    check_outputs("mech_collide_points", status, out.untouched(), doubles_of(&out.value));
    if status != MECH_STATUS_OK {
        return;
    }
    let (a1, a2) = (arr(&out.value.velocity_after_1), arr(&out.value.velocity_after_2));
    // Momenta and energies in units of s·w and s·w², exact powers of two that keep them in
    // range for masses and velocities up to f64::MAX.
    let (s, w) = (
        range_scale(largest(&[m1, m2])),
        range_scale(largest(&[v1, v2, a1, a2].concat())),
    );
    let (m1, m2) = (m1 / s, m2 / s);
    let [v1, v2, a1, a2] = [v1, v2, a1, a2].map(|v| v.map(|c| c / w));
    let p_scale = m1 * norm(v1) + m2 * norm(v2);
    for k in 0..3 {
        assert!(
            (m1 * (a1[k] - v1[k]) + m2 * (a2[k] - v2[k])).abs() <= 1e-13 * p_scale + f64::MIN_POSITIVE,
            "momentum"
        );
    }
    let tangential = |a: [f64; 3], b: [f64; 3]| norm(sub(sub(a, b), n.map(|c| c * dot(sub(a, b), n))));
    assert!(
        tangential(a1, v1) <= 1e-13 * (norm(v1) + norm(v2)) + 8.0 * f64::from_bits(1),
        "tangential velocity of point 1 changed by {:e}: m {m1}, {m2}, v {v1:?}, {v2:?} → {a1:?}, {a2:?}, n {n:?}, e {e}",
        tangential(a1, v1)
    );
    let t = 0.5 * (m1 * dot(v1, v1) + m2 * dot(v2, v2));
    let direct = 0.5 * (m1 * (dot(a1, a1) - dot(v1, v1)) + m2 * (dot(a2, a2) - dot(v2, v2)));
    assert!(direct <= 1e-13 * t, "a point collision gained {direct} of {t}");
}

/// A free body from mass properties, with what the oracles need to compute its energy.
struct Body {
    raw: mech_impulse_body_t,
    mass: f64,
    inertia: [f64; 9],
    /// Whether every principal moment is well above the 1e-12·max below which the C ABI's
    /// pseudo-inverse locks the axis (documented: exact only for impulses through that axis,
    /// the work on a locked rotation being the work done on its driver): only then is
    /// ½ m v² + ½ ωᵀJω the energy the library accounts for.
    energy_known: bool,
}

impl Body {
    fn energy(&self, v: [f64; 3], w: [f64; 3]) -> f64 {
        0.5 * (self.mass * dot(v, v) + dot(w, mat_vec(&self.inertia, w)))
    }
    fn energy_before(&self) -> f64 {
        self.energy(arr(&self.raw.velocity), arr(&self.raw.angular_velocity))
    }
    fn point_velocity(&self, v: [f64; 3], w: [f64; 3], point: [f64; 3]) -> [f64; 3] {
        let r = cross(w, sub(point, arr(&self.raw.center_of_mass)));
        [v[0] + r[0], v[1] + r[1], v[2] + r[2]]
    }
}

fn body(input: &mut Input) -> Option<Body> {
    let p = body_properties(input);
    let (v, w) = (velocity(input, 5.0), velocity(input, 5.0));
    let mut out = Sentinel::<mech_impulse_body_t>::new();
    let status = unsafe { mech_impulse_body_from_mass_properties(&p, &v3(v), &v3(w), out.ptr()) };
    check_status("mech_impulse_body_from_mass_properties", status);
    if status != MECH_STATUS_OK {
        assert!(out.untouched());
        return None;
    }
    let j = p.inertia_about_com.m;
    let trace = j[0] + j[4] + j[8];
    let det =
        j[0] * (j[4] * j[8] - j[7] * j[5]) - j[3] * (j[1] * j[8] - j[7] * j[2]) + j[6] * (j[1] * j[5] - j[4] * j[2]);
    // det ≥ λ_min·(trace/3)²·… : det > 1e-6·(trace/3)³ keeps λ_min above 1e-6·trace/3.
    let energy_known = trace > 0.0 && det > 1e-6 * (trace / 3.0).powi(3);
    Some(Body {
        raw: out.value,
        mass: p.mass,
        inertia: j,
        energy_known,
    })
}

/// An impulse on a free body: m ΔV = S and the energy change of (7.107).
fn apply(input: &mut Input) {
    let Some(b) = body(input) else { return };
    let s = velocity(input, 5.0);
    let point = velocity(input, 2.0);
    let moment = if input.bool() { [0.0; 3] } else { velocity(input, 1.0) };
    let mut out = Sentinel::<mech_body_response_t>::new();
    let status = unsafe { mech_impulse_apply(&b.raw, &v3(s), &v3(point), &v3(moment), out.ptr()) };
    check_outputs("mech_impulse_apply", status, out.untouched(), doubles_of(&out.value));
    if status != MECH_STATUS_OK {
        return;
    }
    let (v, w) = (arr(&out.value.velocity_after), arr(&out.value.angular_velocity_after));
    let v0 = arr(&b.raw.velocity);
    for k in 0..3 {
        assert!(
            (b.mass * (v[k] - v0[k]) - s[k]).abs()
                <= 1e-12 * (b.mass * norm(v0) + norm(s)) + b.mass * spacing(v[k]) + 1e-300,
            "m ΔV ≠ S: m {}, v {v0:?} → {v:?}, S {s:?}",
            b.mass
        );
    }
    let direct = b.energy(v, w) - b.energy_before();
    let scale = b.energy(v, w) + b.energy_before();
    if !scale.is_finite() || !b.energy_known {
        return; // the energies overflow here, not in the library
    }
    assert!(
        (direct - out.value.energy_change).abs() <= 1e-9 * scale + 1e-300,
        "ΔT {} vs {direct}: mass {}, J {:?}, S {s:?} at {point:?}, moment {moment:?}, v {v0:?}, ω {:?} → v {v:?}, ω {w:?}",
        out.value.energy_change,
        b.mass,
        b.inertia,
        arr(&b.raw.angular_velocity)
    );
}

/// Fixing a point stops it and never gains energy.
fn fix(input: &mut Input) {
    let Some(b) = body(input) else { return };
    let point = velocity(input, 2.0);
    let mut out = Sentinel::<mech_fixation_t>::new();
    let status = unsafe { mech_impulse_fix_point(&b.raw, &v3(point), out.ptr()) };
    check_outputs(
        "mech_impulse_fix_point",
        status,
        out.untouched(),
        doubles_of(&out.value),
    );
    if status != MECH_STATUS_OK {
        return;
    }
    let (v, w) = (arr(&out.value.velocity_after), arr(&out.value.angular_velocity_after));
    mechanica_fuzz::trace!(
        "fix_point(mass {}, J {:?}, {:?}, point {point:?}) → {:?}",
        b.mass,
        b.inertia,
        b.raw,
        out.value
    );
    let before = b.energy_before();
    let after = b.energy(v, w);
    if !(before + after).is_finite() || !b.energy_known {
        return;
    }
    assert!(
        after - before <= 1e-9 * before,
        "fixing a point gained {} of {before}",
        after - before
    );
    if !b.energy_known {
        return; // a locked axis (pseudo-inverse) may keep the point from stopping exactly
    }
    let reach = norm(sub(point, arr(&b.raw.center_of_mass)));
    let speed_scale = norm(arr(&b.raw.velocity)) + norm(arr(&b.raw.angular_velocity)) * reach;
    // The point's speed after is what the library reports as the residual of its solve.
    let speed = norm(b.point_velocity(v, w, point));
    let residual = out.value.residual;
    // (Equal values pass also where the scale overflows to ∞ · 0.)
    assert!(
        speed == residual || (speed - residual).abs() <= 1e-9 * speed_scale + 1e-300,
        "the fixed point moves at {speed}, the reported residual is {residual} (scale {speed_scale})"
    );
}

/// Two free bodies in contact: momentum, the energy identity and the no-gain laws.
fn contact(input: &mut Input) {
    let (Some(b1), Some(b2)) = (body(input), body(input)) else {
        return;
    };
    let law = input.enum_i32(3);
    let c = mech_impulse_contact_t {
        point: v3(velocity(input, 2.0)),
        normal: v3(if input.u8() < 240 {
            input.unit_vec3()
        } else {
            input.vec3_any()
        }),
        restitution: scalar(input, 0.0, 1.0),
        friction: if input.u8() < 32 { 0.0 } else { scalar(input, 0.0, 2.0) },
        law,
        tolerance: if input.u8() < 240 { 1e-10 } else { input.any_f64() },
    };
    let mut out = Sentinel::<mech_impact_result_t>::new();
    let status = unsafe { mech_impulse_resolve_contact(&b1.raw, &b2.raw, &c, out.ptr()) };
    check_status("mech_impulse_resolve_contact", status);
    if status != MECH_STATUS_OK {
        assert!(
            out.untouched(),
            "mech_impulse_resolve_contact failed but wrote its output"
        );
        return;
    }
    let o = out.value;
    let (v1, w1, v2, w2) = (
        arr(&o.velocity_after_1),
        arr(&o.angular_velocity_after_1),
        arr(&o.velocity_after_2),
        arr(&o.angular_velocity_after_2),
    );
    let all: Vec<f64> = [arr(&o.impulse), v1, w1, v2, w2].concat();
    assert!(
        all.iter().all(|x| x.is_finite()) && o.energy_change.is_finite(),
        "non-finite impact result"
    );
    let p = arr(&o.impulse);
    let momentum_scale = b1.mass * norm(arr(&b1.raw.velocity)) + b2.mass * norm(arr(&b2.raw.velocity)) + norm(p);
    let (u1, u2) = (arr(&b1.raw.velocity), arr(&b2.raw.velocity));
    for k in 0..3 {
        let (d1, d2) = (b1.mass * (v1[k] - u1[k]) + p[k], b2.mass * (v2[k] - u2[k]) - p[k]);
        let (r1, r2) = (b1.mass * spacing(v1[k]), b2.mass * spacing(v2[k]));
        assert!(
            d1.abs() <= 1e-10 * momentum_scale + r1 + 1e-300,
            "body 1 momentum change ≠ −P by {d1:e}: m {} v {u1:?} → {v1:?}, P {p:?}",
            b1.mass
        );
        assert!(
            d2.abs() <= 1e-10 * momentum_scale + r2 + 1e-300,
            "body 2 momentum change ≠ P by {d2:e}: m {} v {u2:?} → {v2:?}, P {p:?}",
            b2.mass
        );
    }
    let before = b1.energy_before() + b2.energy_before();
    let after = b1.energy(v1, w1) + b2.energy(v2, w2);
    if !(before + after).is_finite() || !b1.energy_known || !b2.energy_known {
        return;
    }
    let direct = after - before;
    let point = arr(&c.point);
    let u_before = sub(
        b2.point_velocity(arr(&b2.raw.velocity), arr(&b2.raw.angular_velocity), point),
        b1.point_velocity(arr(&b1.raw.velocity), arr(&b1.raw.angular_velocity), point),
    );
    let integration = if o.integration_error > 0.0 {
        10.0 * (norm(u_before) + norm(arr(&o.relative_velocity_after))) * o.integration_error
    } else {
        0.0
    };
    let slack = 1e-9 * (before + after) + integration;
    assert!(
        (direct - o.energy_change).abs() <= slack,
        "reported ΔT {:e} but the velocities give {direct:e} (T before {before:e}, after {after:e}, slack {slack:e}, integration error {:e}, mode {}, law {law}, tolerance {:e})",
        o.energy_change,
        o.integration_error,
        o.mode,
        c.tolerance
    );
    // (Sticking under an infinite friction coefficient stops an initial slip at once, before
    // any normal impulse: the ratio is not constant, and Newton's law may gain energy.)
    let constant_ratio = c.friction == 0.0
        || o.mode == MECH_CONTACT_FRICTIONLESS
        || (o.mode == MECH_CONTACT_STICK && c.friction.is_finite())
        || o.mode == MECH_CONTACT_NO_IMPACT;
    let must_not_gain = law == MECH_RESTITUTION_STRONGE || (constant_ratio && c.restitution <= 1.0);
    if must_not_gain {
        assert!(
            direct <= slack,
            "law {law}, mode {}: the impact gained {direct} of {before} (slack {slack:e}); contact {:?}; body 1 m {} J {:?} v {:?} ω {:?} c {:?}; body 2 m {} J {:?} v {:?} ω {:?} c {:?}",
            o.mode,
            (c.point, c.normal, c.restitution, c.friction, c.tolerance),
            b1.mass,
            b1.inertia,
            b1.raw.velocity,
            b1.raw.angular_velocity,
            b1.raw.center_of_mass,
            b2.mass,
            b2.inertia,
            b2.raw.velocity,
            b2.raw.angular_velocity,
            b2.raw.center_of_mass
        );
    }
}

/// Mechanism impacts on a small tree: the energy change of an impulse is that of ½ q̇ᵀ A q̇,
/// a mechanism contact never gains energy under Stronge's law or the guarded simultaneous
/// model, and the Delassus matrix is symmetric.
fn mechanism(input: &mut Input) {
    let Some(tree) = build_tree(input) else { return };
    let bodies: Vec<mech_mass_properties_t> = (0..tree.bodies).map(|_| body_properties(input)).collect();
    check_status("mech_tree_set_state", set_state(&tree, input));
    let n = tree.dof;
    let count = 1 + input.below(3);
    let mut contacts = Vec::new();
    for _ in 0..count {
        contacts.push(mech_mechanism_contact_t {
            body: input.below(tree.bodies + 1),
            point: v3(velocity(input, 1.0)),
            other_body: input.below(tree.bodies + 1) as i64 - 1,
            other_point: v3(velocity(input, 1.0)),
            normal: v3(if input.u8() < 240 {
                input.unit_vec3()
            } else {
                input.vec3_any()
            }),
            restitution: scalar(input, 0.0, 1.0),
            friction: scalar(input, 0.0, 1.0),
            law: if input.bool() {
                MECH_RESTITUTION_STRONGE
            } else {
                input.enum_i32(3)
            },
        });
    }
    let mut results = vec![Sentinel::<mech_mechanism_contact_result_t>::new().value; count];
    let mut dq = sentinel_doubles(n);
    let mut out = Sentinel::<mech_mechanism_impact_t>::new();
    let status = unsafe {
        mech_impulse_mechanism_contacts(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            contacts.as_ptr(),
            count,
            std::ptr::null(),
            results.as_mut_ptr(),
            dq.as_mut_ptr(),
            n,
            out.ptr(),
        )
    };
    check_outputs(
        "mech_impulse_mechanism_contacts",
        status,
        out.untouched() && doubles_untouched(&dq),
        &dq,
    );
    if status == MECH_STATUS_OK {
        let o = out.value;
        let guarded = count > 1 || contacts[0].law == MECH_RESTITUTION_STRONGE;
        let slack = 1e-9 * o.energy_before + 1e-6 * o.integration_error.abs() * o.energy_before.sqrt();
        if guarded {
            assert!(
                o.energy_change <= slack,
                "a mechanism impact gained {} of {}",
                o.energy_change,
                o.energy_before
            );
        }
    }
    let impulses: Vec<mech_mechanism_impulse_t> = (0..count)
        .map(|_| mech_mechanism_impulse_t {
            body: input.below(tree.bodies + 1),
            point: v3(velocity(input, 1.0)),
            impulse: v3(velocity(input, 3.0)),
        })
        .collect();
    let mut dq = sentinel_doubles(n);
    let mut response = Sentinel::<mech_mechanism_response_t>::new();
    let status = unsafe {
        mech_impulse_mechanism_apply(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            impulses.as_ptr(),
            count,
            dq.as_mut_ptr(),
            n,
            response.ptr(),
        )
    };
    check_outputs(
        "mech_impulse_mechanism_apply",
        status,
        response.untouched() && doubles_untouched(&dq),
        doubles_of(&response.value),
    );
    if status == MECH_STATUS_OK {
        check_impulse_energy(&tree, &bodies, &dq, &response.value);
    }
    let rows = 3 * count;
    let mut w = sentinel_doubles(rows * rows);
    let mut frames = vec![mech_mat3_t { m: [0.0; 9] }; count];
    let mut rank = Sentinel::<usize>::new();
    let status = unsafe {
        mech_impulse_mechanism_delassus(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            contacts.as_ptr(),
            count,
            w.as_mut_ptr(),
            rows,
            frames.as_mut_ptr(),
            rank.ptr(),
        )
    };
    check_outputs(
        "mech_impulse_mechanism_delassus",
        status,
        doubles_untouched(&w) && rank.untouched(),
        &w,
    );
    if status == MECH_STATUS_OK {
        let largest = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..rows {
            for j in 0..rows {
                assert!(
                    (w[i + rows * j] - w[j + rows * i]).abs() <= 1e-12 * largest,
                    "W not symmetric"
                );
            }
        }
        assert!(
            rank.value <= rows.min(n),
            "rank {} of a {rows}-row W with {n} coordinates",
            rank.value
        );
    }
}

/// ΔT of an impulse equals ½(q̇+Δq̇)ᵀA(q̇+Δq̇) − ½q̇ᵀAq̇ with A from mech_tree_mass_matrix.
fn check_impulse_energy(
    tree: &mechanica_fuzz::tree::OwnedTree,
    bodies: &[mech_mass_properties_t],
    dq: &[f64],
    r: &mech_mechanism_response_t,
) {
    let n = tree.dof;
    if n == 0 {
        return; // mech_tree_mass_matrix refuses n = 0 (BAD_DIMENSION)
    }
    let mut a = vec![0.0; n * n];
    let status = unsafe { mech_tree_mass_matrix(tree.handle, bodies.as_ptr(), bodies.len(), a.as_mut_ptr(), n) };
    assert_eq!(
        status,
        MECH_STATUS_OK,
        "an impulse was solved without a mass matrix: {}",
        mechanica_fuzz::oracle::last_error()
    );
    let mut energy = 0.0;
    let mut momenta = vec![0.0; n];
    let status = unsafe {
        mech_tree_kinetic_energy(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            &mut energy,
            momenta.as_mut_ptr(),
            n,
        )
    };
    assert_eq!(
        status,
        MECH_STATUS_OK,
        "an impulse was solved without a kinetic energy: {}",
        mechanica_fuzz::oracle::last_error()
    );
    assert!(
        (energy - r.energy_before).abs() <= 1e-12 * energy.abs() + 1e-300,
        "energy before {} vs {energy}",
        r.energy_before
    );
    // ΔT = (A q̇)·Δq̇ + ½ Δq̇ᵀ A Δq̇, with A q̇ the momenta.
    let quad: f64 = (0..n)
        .map(|i| (0..n).map(|j| dq[i] * a[i + n * j] * dq[j]).sum::<f64>())
        .sum();
    let linear: f64 = (0..n).map(|i| momenta[i] * dq[i]).sum();
    let want = linear + 0.5 * quad;
    if !want.is_finite() {
        return; // the oracle's own sums overflow: no reference to compare with
    }
    let scale = energy + 0.5 * quad.abs() + linear.abs();
    // The solve's backward error η bounds the residual of A Δq̇ = Q_S by η‖A‖‖Δq̇‖, which the
    // energy sees through q̇ + ½Δq̇.
    let norm1 = |v: &[f64]| v.iter().map(|x| x.abs()).sum::<f64>();
    let half: Vec<f64> = (0..n).map(|i| dq[i] * 0.5).collect();
    // (A zero factor makes the product zero, also beside an overflowing one.)
    let times = |x: f64, y: f64| if x == 0.0 || y == 0.0 { 0.0 } else { x * y };
    let residual = times(norm1(dq), norm1(&momenta)) + times(times(norm1(&a), norm1(dq)), norm1(&half));
    let tolerance = 1e-9 * scale + 10.0 * (r.backward_error + f64::EPSILON) * residual;
    // (Equal values pass also where the tolerance overflows to ∞ · 0.)
    assert!(
        r.energy_change == want || (r.energy_change - want).abs() <= tolerance,
        "ΔT {} vs {want} (scale {scale})",
        r.energy_change
    );
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let mut steps = 0;
    while !input.is_empty() && steps < 32 {
        steps += 1;
        match input.u8() % 7 {
            0 => collinear(&mut input),
            1 => points(&mut input),
            2 => apply(&mut input),
            3 => fix(&mut input),
            4 | 5 => contact(&mut input),
            _ => mechanism(&mut input),
        }
    }
});
