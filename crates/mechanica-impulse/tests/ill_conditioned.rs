//! Impacts of ill-conditioned bodies that start tangentially at rest: needles (moments
//! (r, 1, 1)), flat bodies ((1, r, 1 + r)) and generic ones, with ratios r down to 1e-9,
//! random orientations, contact points and normals, sticking or slipping along the ray.
//! The impulse is compared with a double-double reference computed independently from the
//! same contact mobility W (closed forms of the constant-ratio impact: the stick ratio
//! t = −W_TT⁻¹ W_Tn, the slip ray by bisection on its secular equation), and the reported
//! `integration_error` must bound the true error without being loose.

mod common;

use common::dd::{self, Dd, Dd3, cross, inverse2, mat, normalize, vec3};
use mechanica_impulse::{
    ContactImpulse, ContactLaw, ContactMode, ImpactOptions, ImpulseError, RestitutionLaw, RigidBody, resolve_contact,
    resolve_in_contact_space,
};
use mechanica_mass::MassProperties;
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

const U: f64 = f64::EPSILON / 2.0;

/// What the exact process does from tangential rest.
#[derive(Debug)]
enum Expected {
    /// The impulse (world frame), the mode, and the impulse (1 + f)|W_TT⁻¹ u_T| that would
    /// stop the tangential velocity the rounded input carries.
    Impulse(Vector3<f64>, ContactMode, f64),
    /// The normal velocity cannot grow along the slip ray (frictional jam).
    Jam,
}

/// The contact frame (t₁, t₂, n̂) in double-double, n̂ = n/|n| exactly normalised.
fn frame(n: &Vector3<f64>) -> [[Dd; 3]; 3] {
    let n_hat = normalize(&vec3(n));
    let helper = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let t1 = normalize(&cross(&n_hat, &vec3(&helper)));
    let t2 = cross(&n_hat, &t1);
    [t1, t2, n_hat]
}

/// The slip ray ŝ with (W_Tn − f W_TT ŝ) = α ŝ, α > 0, |ŝ| = 1: bisection on α of
/// |(f W_TT + α I)⁻¹ W_Tn| = 1 (decreasing in α), then Newton steps in double-double on
/// φ(α) = |ŝ(α)|² − 1, φ′ = −2 ŝᵀ M⁻¹ ŝ, so that ŝ is accurate beyond one rounding.
fn ray(w_tt: &[[Dd; 2]; 2], w_tn: &[Dd; 2], f: f64) -> [Dd; 2] {
    let inverse_at = |alpha: Dd| {
        let f = Dd::new(f);
        inverse2(&[
            [w_tt[0][0] * f + alpha, w_tt[0][1] * f],
            [w_tt[1][0] * f, w_tt[1][1] * f + alpha],
        ])
    };
    let apply = |m: &[[Dd; 2]; 2], x: &[Dd; 2]| [m[0][0] * x[0] + m[0][1] * x[1], m[1][0] * x[0] + m[1][1] * x[1]];
    let norm2 = |s: &[Dd; 2]| s[0] * s[0] + s[1] * s[1];
    let (mut lo, mut hi) = (0.0, (norm2(w_tn).sqrt()).to_f64() * 2.0);
    for _ in 0..2000 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if norm2(&apply(&inverse_at(Dd::new(mid)), w_tn)).to_f64() > 1.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let mut alpha = Dd::new(0.5 * (lo + hi));
    for _ in 0..4 {
        let m = inverse_at(alpha);
        let s = apply(&m, w_tn);
        let phi = norm2(&s) - Dd::new(1.0);
        let m_s = apply(&m, &s);
        let slope = Dd::new(-2.0) * (s[0] * m_s[0] + s[1] * m_s[1]);
        alpha = alpha - phi / slope;
    }
    let s = apply(&inverse_at(alpha), w_tn);
    let norm = norm2(&s).sqrt();
    [s[0] / norm, s[1] / norm]
}

/// The double-double reference for the contact mobility `w`, normal `n`, normal approach
/// speed `u_n` < 0 (no tangential velocity), restitution `e` and friction `f`: a single
/// constant-ratio segment d = (t, 1) or (−f ŝ, 1), at the end of which all three laws agree,
/// p_f = (1 + e)(−u_n)/b with b = (W d)_n. `None` when a decision is too close to call.
fn reference(wd: &Dd3, n: &Vector3<f64>, u_n: f64, e: f64, f: f64) -> Option<Expected> {
    let r = frame(n);
    let c = |i: usize, j: usize| {
        let mut sum = Dd::ZERO;
        for k in 0..3 {
            for l in 0..3 {
                sum = sum + r[i][k] * wd[k][l] * r[j][l];
            }
        }
        sum
    };
    let w_tt = [[c(0, 0), c(0, 1)], [c(1, 0), c(1, 1)]];
    let w_tn = [c(0, 2), c(1, 2)];
    let inv = inverse2(&w_tt);
    // The tangential part of u⁻ = u_n n (rounded) in the exact frame, and the impulse that stops it.
    let u_w = vec3(&(n * u_n));
    let u_t = [0, 1].map(|i| r[i][0] * u_w[0] + r[i][1] * u_w[1] + r[i][2] * u_w[2]);
    let stop = [0, 1].map(|i| inv[i][0] * u_t[0] + inv[i][1] * u_t[1]);
    let stop = (1.0 + f) * (stop[0] * stop[0] + stop[1] * stop[1]).sqrt().to_f64();
    let t = [
        -(inv[0][0] * w_tn[0] + inv[0][1] * w_tn[1]),
        -(inv[1][0] * w_tn[0] + inv[1][1] * w_tn[1]),
    ];
    let t_norm = (t[0] * t[0] + t[1] * t[1]).sqrt().to_f64();
    let (d, mode) = if t_norm <= f * (1.0 - 1e-9) {
        (t, ContactMode::Stick)
    } else if t_norm >= f * (1.0 + 1e-9) {
        let s = ray(&w_tt, &w_tn, f);
        ([-(s[0] * Dd::new(f)), -(s[1] * Dd::new(f))], ContactMode::Slip)
    } else {
        return None;
    };
    let b = c(2, 0) * d[0] + c(2, 1) * d[1] + c(2, 2);
    let w_nn = c(2, 2).to_f64();
    if b.to_f64() < -1e-6 * w_nn {
        return Some(Expected::Jam);
    }
    if b.to_f64() < 1e-6 * w_nn {
        return None;
    }
    let p_f = Dd::new((1.0 + e) * -u_n) / b;
    let dc = [d[0] * p_f, d[1] * p_f, p_f];
    let world = |i: usize| (r[0][i] * dc[0] + r[1][i] * dc[1] + r[2][i] * dc[2]).to_f64();
    Some(Expected::Impulse(
        Vector3::new(world(0), world(1), world(2)),
        mode,
        stop,
    ))
}

/// A body of mass `m` whose central inertia has principal moments `moments` (scaled by
/// `size²`) in the orientation `angles` (a rotation vector).
fn body(m: f64, moments: Vector3<f64>, size: f64, angles: Vector3<f64>) -> MassProperties {
    let r = Rotation3::from_scaled_axis(angles);
    let j = r.matrix() * Matrix3::from_diagonal(&(moments * (m * size * size))) * r.matrix().transpose();
    let mut props = MassProperties::point(m, Vector3::zeros()).expect("positive mass");
    props.inertia_c = (j + j.transpose()) * 0.5;
    props
}

/// Checks the impulse of the contact `w`, `n`, `u_n` against the reference: the true error
/// within the reported bound, the bound within a few hundred ulps of the impulse plus what
/// the input itself leaves open: the rounding of u⁻ = u_n n leaves a tangential velocity of a
/// few ulps, which the process neglects (it is far below the rest threshold); the impulse
/// that would stop it, (1 + f)|W_TT⁻¹ u_T|, is the scale of that effect.
fn check_against_reference(
    expected: Option<Expected>,
    out: Result<ContactImpulse, ImpulseError>,
) -> Result<(), String> {
    let Some(expected) = expected else {
        return Ok(());
    };
    match (expected, out) {
        (Expected::Jam, Err(ImpulseError::NotConverged { .. })) => Ok(()),
        (Expected::Impulse(p_ref, mode, stop), Ok(c)) => {
            let error = (c.impulse_w - p_ref).norm();
            let bound = c.integration_error;
            if c.mode != mode {
                return Err(format!("mode {:?}, expected {mode:?}", c.mode));
            }
            if error > bound {
                return Err(format!(
                    "error {error:e} above the reported {bound:e} (|P| = {:e})",
                    p_ref.norm()
                ));
            }
            if bound > 256.0 * U * p_ref.norm() + 4.0 * stop {
                return Err(format!(
                    "reported {bound:e} is loose: true error {error:e}, |P| = {:e}",
                    p_ref.norm()
                ));
            }
            Ok(())
        }
        (expected, out) => Err(format!("expected {expected:?}, got {out:?}")),
    }
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.log10()..hi.log10()).prop_map(|x| 10f64.powf(x))
}

/// Principal moments: a needle, a flat body or a generic one, with the small ratio `r`.
fn moments(kind: usize, r: f64, other: f64) -> Vector3<f64> {
    match kind {
        0 => Vector3::new(r, 1.0, 1.0),
        1 => Vector3::new(1.0, r, 1.0 + r),
        _ => Vector3::new(r, other, 1.0),
    }
}

fn unit_or_z(v: Vector3<f64>) -> Vector3<f64> {
    if v.norm() < 1e-3 { Vector3::z() } else { v.normalize() }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    /// Normals along a signed coordinate axis, so that u⁻ = u_n n has no tangential part at
    /// all; the body's orientation makes the normal random relative to the body.
    #[test]
    fn slender_and_flat_bodies_from_rest_on_axis_normals(
        kind in 0..3usize, r in log_uniform(1e-9, 1.0), other in 0.1..1.0f64,
        m in log_uniform(1e-2, 1e2), size in log_uniform(1e-2, 1e2),
        angles in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), point in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        axis in 0..6usize, speed in log_uniform(1e-2, 1e2), e in 0.0..=1.0f64,
        f in log_uniform(1e-2, 1e2), law in 0..3usize,
    ) {
        let props = body(m, moments(kind, r, other), size, Vector3::new(angles.0, angles.1, angles.2));
        let rigid = RigidBody::from_mass_properties(&props, Vector3::zeros(), Vector3::zeros()).expect("body");
        let w = rigid.point_mobility(&(Vector3::new(point.0, point.1, point.2) * size));
        let n = Vector3::ith(axis % 3, if axis < 3 { 1.0 } else { -1.0 });
        let law = ContactLaw::new(e, f, [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge][law])
            .expect("law");
        let expected = reference(&mat(&w), &n, -speed, e, f);
        let out = resolve_in_contact_space(&w, &(n * -speed), &n, &law, &ImpactOptions::default());
        prop_assert_eq!(check_against_reference(expected, out), Ok(()));
    }

    /// Random normals, through the two-body impact: the reference forms W from the body's mass
    /// and inertia tensor in double-double (J⁻¹ by the adjugate), so the error of forming W and
    /// J⁻¹ counts too. The body moves at −n, which has no tangential part along n.
    #[test]
    fn slender_and_flat_bodies_from_rest_on_random_normals(
        kind in 0..3usize, r in log_uniform(1e-9, 1.0), other in 0.1..1.0f64,
        angles in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), point in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        normal in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), e in 0.0..=1.0f64,
        f in log_uniform(1e-2, 1e2), law in 0..3usize,
    ) {
        let props = body(1.0, moments(kind, r, other), 1.0, Vector3::new(angles.0, angles.1, angles.2));
        let n = unit_or_z(Vector3::new(normal.0, normal.1, normal.2));
        let rigid = RigidBody::from_mass_properties(&props, -n, Vector3::zeros()).expect("body");
        let point = Vector3::new(point.0, point.1, point.2);
        let law = ContactLaw::new(e, f, [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge][law])
            .expect("law");
        let ground = RigidBody::fixed(Vector3::new(5.0, 5.0, 5.0)).expect("ground");
        let expected = reference(&dd::point_mobility(1.0, &props.inertia_c, &point), &n, -1.0, e, f);
        let out = resolve_contact(&ground, &rigid, &point, &n, &law, &ImpactOptions::default()).map(|o| o.contact);
        prop_assert_eq!(check_against_reference(expected, out), Ok(()));
    }
}

/// The reported case: a needle with axial moment 2e-7 of the others, struck from rest and
/// sticking. The eigen-decomposition pseudo-inverse of W_TT left a relative error of 1e-5
/// while reporting 0; the factored, refined solve is exact to a few ulps and says so.
#[test]
fn a_needle_sticking_from_rest_is_exact_to_a_few_ulps() {
    let props = {
        let r = Rotation3::from_euler_angles(0.0, 0.56, 0.08);
        let j = r.matrix() * Matrix3::from_diagonal(&Vector3::new(2e-7, 1.0, 1.0)) * r.matrix().transpose();
        let mut props = MassProperties::point(1.0, Vector3::zeros()).expect("positive mass");
        props.inertia_c = (j + j.transpose()) * 0.5;
        props
    };
    let n = Vector3::new(-2.0, -3.0, -6.0) / 7.0;
    let d = Vector3::new(-0.4, 0.6, 0.7);
    let needle = RigidBody::from_mass_properties(&props, -n, Vector3::zeros()).expect("body");
    let ground = RigidBody::fixed(Vector3::new(5.0, 5.0, 5.0)).expect("ground");
    let law = ContactLaw::new(0.5, 10.0, RestitutionLaw::Stronge).expect("law");
    let out = resolve_contact(&ground, &needle, &d, &n, &law, &ImpactOptions::default()).expect("impact");
    let w = dd::point_mobility(1.0, &props.inertia_c, &d);
    let Some(Expected::Impulse(p_ref, mode, _)) = reference(&w, &n, -1.0, 0.5, 10.0) else {
        panic!("the reference sticks");
    };
    assert_eq!((out.contact.mode, mode), (ContactMode::Stick, ContactMode::Stick));
    let error = (out.contact.impulse_w - p_ref).norm();
    assert!(
        error <= out.contact.integration_error,
        "{error:e} vs {:e}",
        out.contact.integration_error
    );
    assert!(
        error <= 8.0 * U * p_ref.norm(),
        "relative error {:e}",
        error / p_ref.norm()
    );
    assert!(out.contact.integration_error <= 64.0 * U * p_ref.norm());
}
