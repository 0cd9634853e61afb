//! Invariants on random impacts (proptest): momentum conservation, angular momentum about the
//! contact point, no energy gain under the default law, the exact energy identity, the
//! friction cone; plus extreme inputs, 3-D swerving slip and bad input.

mod common;

use common::Body;
use mechanica_impulse::{
    ContactLaw, ContactMode, ImpactOptions, ImpulseError, RestitutionLaw, RigidBody, resolve_contact,
    resolve_in_contact_space,
};
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

fn vec3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

/// A random rigid body: mass in [0.1, 10], principal inertias in [0.01, 1] (triangle
/// inequality not enforced: the mechanics only needs J symmetric positive definite), random
/// orientation, position and velocities.
fn body() -> impl Strategy<Value = Body> {
    (
        0.1..10.0f64,
        (0.01..1.0f64, 0.01..1.0f64, 0.01..1.0f64),
        vec3(3.0),
        vec3(1.0),
        vec3(2.0),
        vec3(2.0),
    )
        .prop_map(|(m, (a, b, c), angles, p, v, w)| {
            let r = Rotation3::from_scaled_axis(angles);
            let j = r.matrix() * Matrix3::from_diagonal(&Vector3::new(a, b, c)) * r.matrix().transpose();
            Body::new(m, p, j, v, w)
        })
}

fn law() -> impl Strategy<Value = ContactLaw> {
    (0.0..=1.0f64, 0.0..2.0f64, 0..3usize).prop_map(|(e, f, k)| {
        let law = [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge][k];
        ContactLaw::new(e, f, law).expect("valid law")
    })
}

fn unit(v: Vector3<f64>) -> Vector3<f64> {
    if v.norm() < 1e-3 { Vector3::z() } else { v.normalize() }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn free_bodies_conserve_momentum_and_the_energy_identity_holds(
        b1 in body(), b2 in body(), r in vec3(2.0), n in vec3(1.0), law in law()
    ) {
        let n = unit(n);
        let out = resolve_contact(&b1.rigid(), &b2.rigid(), &r, &n, &law, &ImpactOptions::default()).expect("impact");
        let p_before = b1.momentum(&b1.v) + b2.momentum(&b2.v);
        let p_after = b1.momentum(&out.body1.v_wc_after) + b2.momentum(&out.body2.v_wc_after);
        let scale = p_before.norm() + b1.momentum(&b1.v).norm() + b2.momentum(&b2.v).norm() + 1e-300;
        prop_assert!((p_after - p_before).norm() <= 1e-12 * scale, "momentum {p_before} → {p_after}");
        // (7.80): angular momentum about the contact point (and hence any point) is conserved.
        let d_before = b1.angular_momentum_about(&r, &b1.v, &b1.w) + b2.angular_momentum_about(&r, &b2.v, &b2.w);
        let d_after = b1.angular_momentum_about(&r, &out.body1.v_wc_after, &out.body1.w_w_after)
            + b2.angular_momentum_about(&r, &out.body2.v_wc_after, &out.body2.w_w_after);
        let d_scale = d_before.norm() + 10.0 * scale;
        prop_assert!((d_after - d_before).norm() <= 1e-11 * d_scale);
        // ΔT from the velocities, from (7.107) and from P·(u⁻ + ½ W P) with W built here.
        let t_before = b1.energy_before() + b2.energy_before();
        let direct = b1.energy_after(&out.body1) + b2.energy_after(&out.body2) - t_before;
        let w = b1.point_mobility(&r) + b2.point_mobility(&r);
        let p = out.contact.impulse_w;
        let identity = p.dot(&(out.u_before_w + w * p * 0.5));
        let tol = 1e-10 * (t_before + 1e-300);
        prop_assert!((direct - identity).abs() <= tol, "{direct} vs {identity}");
        prop_assert!((out.contact.energy_change - direct).abs() <= tol);
        // Coulomb cone |P_T| ≤ f P_n and P_n ≥ 0 (7.97).
        prop_assert!(out.contact.normal_impulse >= 0.0);
        prop_assert!(out.contact.tangential_impulse_w.norm() <= law.friction * out.contact.normal_impulse * (1.0 + 1e-9) + 1e-15);
        // Newton's law (7.94) holds at the end, whatever the friction did.
        if law.law == RestitutionLaw::Newton && out.contact.mode != ContactMode::NoImpact {
            let u_n = out.u_before_w.dot(&n);
            prop_assert!((out.contact.u_after_w.dot(&n) + law.restitution * u_n).abs() <= 1e-9 * out.u_before_w.norm());
        }
    }

    #[test]
    fn a_body_hitting_the_ground_keeps_its_angular_momentum_about_the_contact_and_stronge_never_gains(
        b in body(), r in vec3(2.0), n in vec3(1.0), e in 0.0..=1.0f64, f in 0.0..3.0f64
    ) {
        let n = unit(n);
        let law = ContactLaw::new(e, f, RestitutionLaw::default()).expect("law");
        let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
        let out = resolve_contact(&ground, &b.rigid(), &r, &n, &law, &ImpactOptions::default()).expect("impact");
        // (7.71) with M_RS = 0.
        let before = b.angular_momentum_about(&r, &b.v, &b.w);
        let after = b.angular_momentum_about(&r, &out.body2.v_wc_after, &out.body2.w_w_after);
        let scale = before.norm() + b.props.mass * b.v.norm() * (b.props.p_oc - r).norm() + 1e-300;
        prop_assert!((after - before).norm() <= 1e-11 * scale, "{before} → {after}");
        let t = b.energy_before();
        let gain = b.energy_after(&out.body2) - t;
        prop_assert!(gain <= 1e-10 * t, "Stronge gained {gain} of {t}");
    }
}

#[test]
fn mass_ratios_of_1e12_either_way() {
    for ratio in [1e12, 1e-12] {
        let light = Body::sphere(
            1.0,
            0.1,
            Vector3::zeros(),
            Vector3::new(1.0, 0.2, 0.0),
            Vector3::zeros(),
        );
        let heavy = Body::sphere(
            ratio,
            0.1,
            Vector3::new(0.2, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        let law = ContactLaw::new(1.0, 0.0, RestitutionLaw::Stronge).expect("law");
        let out = resolve_contact(
            &light.rigid(),
            &heavy.rigid(),
            &Vector3::new(0.1, 0.0, 0.0),
            &Vector3::x(),
            &law,
            &ImpactOptions::default(),
        )
        .expect("impact");
        // Collinear closed form (5.21–5.22) along x with μ = m₁m₂/(m₁+m₂).
        let (m1, m2) = (1.0, ratio);
        let v1 = (m1 - m2) / (m1 + m2) * 1.0;
        let v2 = 2.0 * m1 / (m1 + m2) * 1.0;
        assert!(
            (out.body1.v_wc_after.x - v1).abs() <= 1e-12,
            "{} vs {v1}",
            out.body1.v_wc_after.x
        );
        assert!((out.body2.v_wc_after.x - v2).abs() <= 1e-12 * v2.abs().max(1e-12));
        assert!(out.contact.energy_change.abs() <= 1e-12);
    }
}

#[test]
fn grazing_and_separating_contacts_receive_no_impulse() {
    let ball = Body::sphere(
        1.0,
        0.1,
        Vector3::new(0.0, 0.1, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::zeros(),
    );
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    let law = ContactLaw::new(0.5, 0.5, RestitutionLaw::Newton).expect("law");
    for v_y in [0.0, 0.3] {
        let mut b = Body::sphere(1.0, 0.1, ball.props.p_oc, Vector3::new(1.0, v_y, 0.0), Vector3::zeros());
        b.w = Vector3::zeros();
        let out = resolve_contact(
            &ground,
            &b.rigid(),
            &Vector3::zeros(),
            &Vector3::y(),
            &law,
            &ImpactOptions::default(),
        )
        .expect("ok");
        assert_eq!(out.contact.mode, ContactMode::NoImpact);
        assert_eq!(out.contact.impulse_w, Vector3::zeros());
        assert_eq!(out.body2.v_wc_after, b.v);
    }
}

#[test]
fn infinite_friction_is_the_limit_of_large_friction() {
    // Spinning sphere on the ground: f = ∞ gives rolling after the impact, like any f above
    // the sticking threshold; f = 1e8 must agree to ~1/f.
    let ball = Body::sphere(
        2.0,
        0.1,
        Vector3::new(0.0, 0.1, 0.0),
        Vector3::new(1.0, -3.0, 0.5),
        Vector3::new(2.0, -1.0, 25.0),
    );
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    let opts = ImpactOptions::default();
    let inf = ContactLaw::new(0.6, f64::INFINITY, RestitutionLaw::Stronge).expect("law");
    let big = ContactLaw::new(0.6, 1e8, RestitutionLaw::Stronge).expect("law");
    let a = resolve_contact(&ground, &ball.rigid(), &Vector3::zeros(), &Vector3::y(), &inf, &opts).expect("ok");
    let b = resolve_contact(&ground, &ball.rigid(), &Vector3::zeros(), &Vector3::y(), &big, &opts).expect("ok");
    assert_eq!(a.contact.mode, ContactMode::Stick);
    let tangential = a.contact.u_after_w - Vector3::y() * a.contact.u_after_w.y;
    assert!(tangential.norm() < 1e-14);
    assert!((a.contact.impulse_w - b.contact.impulse_w).norm() < 1e-6 * a.contact.impulse_w.norm());
}

#[test]
fn rod_with_zero_axial_inertia_struck_at_its_end() {
    // Rod along the direction a, struck at its end by the ground: the pseudo-inverse is exact
    // because the end lies on the axis. Struck along its own axis it behaves as a point mass.
    let a = Vector3::new(0.0, 1.0, 0.0);
    let rod = Body::rod(
        2.0,
        1.0,
        Vector3::new(0.0, 0.5, 0.0),
        a,
        Vector3::new(0.0, -1.0, 0.0),
        Vector3::zeros(),
    );
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    let law = ContactLaw::new(0.5, 0.4, RestitutionLaw::Stronge).expect("law");
    let out = resolve_contact(
        &ground,
        &rod.rigid(),
        &Vector3::zeros(),
        &Vector3::y(),
        &law,
        &ImpactOptions::default(),
    )
    .expect("ok");
    assert!((out.body2.v_wc_after - Vector3::new(0.0, 0.5, 0.0)).norm() < 1e-14);
    assert_eq!(out.body2.w_w_after, Vector3::zeros());
    // A contact point off the rod's axis is rejected.
    let off = resolve_contact(
        &ground,
        &rod.rigid(),
        &Vector3::new(0.1, 0.0, 0.0),
        &Vector3::y(),
        &law,
        &ImpactOptions::default(),
    );
    assert!(
        matches!(off, Err(ImpulseError::ZeroInertiaAxisExcited { .. })),
        "{off:?}"
    );
}

/// A 3-D impact whose slip swerves: a tilted rod sliding obliquely.
fn swerving(tolerance: f64) -> mechanica_impulse::TwoBodyImpact {
    let axis = Vector3::new(0.6, 0.5, 0.3).normalize();
    let centre = axis * 0.5;
    let rod = Body::rod(
        1.0,
        1.0,
        centre,
        axis,
        Vector3::new(0.4, -1.0, -0.7),
        Vector3::new(0.3, 0.0, 0.2),
    );
    let rod = Body {
        w: rod.w - axis * rod.w.dot(&axis),
        ..rod
    };
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    let law = ContactLaw::new(0.8, 0.25, RestitutionLaw::Stronge).expect("law");
    let opts = ImpactOptions {
        tolerance,
        ..ImpactOptions::default()
    };
    resolve_contact(&ground, &rod.rigid(), &Vector3::zeros(), &Vector3::y(), &law, &opts).expect("ok")
}

#[test]
fn swerving_slip_is_integrated_with_an_honest_error_estimate() {
    let reference = swerving(1e-13);
    for tolerance in [1e-4, 1e-6, 1e-8] {
        let out = swerving(tolerance);
        let actual = (out.contact.impulse_w - reference.contact.impulse_w).norm();
        assert!(out.contact.integration_error > 0.0);
        assert!(
            actual <= out.contact.integration_error + 1e-12 * reference.contact.normal_impulse,
            "tol {tolerance}: actual error {actual} > reported {}",
            out.contact.integration_error
        );
        assert!(out.contact.integration_error < 1e3 * tolerance * reference.contact.normal_impulse);
    }
    // Against the independent SciPy DOP853 integration (tools/impulse_swerve_reference.py,
    // rtol 1e-13; its numbers are committed in tools/impulse_swerve_reference.out).
    let text = include_str!("../../../tools/impulse_swerve_reference.out");
    let line = text.lines().find(|l| l.starts_with("impulse ")).expect("impulse line");
    let p: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().expect("number"))
        .collect();
    let p_ref = Vector3::new(p[0], p[1], p[2]);
    assert!(text.contains("mode Slip") && reference.contact.mode == ContactMode::Slip);
    assert!(
        (reference.contact.impulse_w - p_ref).norm() < 1e-10 * p_ref.norm(),
        "{} vs {p_ref}",
        reference.contact.impulse_w
    );
    // The slip direction really changed: the friction impulse is not along the initial slip.
    let u_t0 = reference.u_before_w - Vector3::y() * reference.u_before_w.y;
    let p_t = reference.contact.tangential_impulse_w;
    assert!(u_t0.normalize().dot(&p_t.normalize()) > -0.999);
}

#[test]
fn bad_input_gives_typed_errors() {
    assert!(matches!(
        ContactLaw::new(1.5, 0.1, RestitutionLaw::Newton),
        Err(ImpulseError::RestitutionOutOfRange(_))
    ));
    assert!(matches!(
        ContactLaw::new(-0.1, 0.1, RestitutionLaw::Newton),
        Err(ImpulseError::RestitutionOutOfRange(_))
    ));
    assert!(matches!(
        ContactLaw::new(0.5, -0.1, RestitutionLaw::Newton),
        Err(ImpulseError::NegativeFriction(_))
    ));
    assert!(matches!(
        ContactLaw::new(0.5, f64::NAN, RestitutionLaw::Newton),
        Err(ImpulseError::NonFinite { .. })
    ));
    assert!(matches!(
        ContactLaw::new(f64::NAN, 0.1, RestitutionLaw::Newton),
        Err(ImpulseError::NonFinite { .. })
    ));
    let law = ContactLaw::new(0.5, 0.5, RestitutionLaw::Stronge).expect("law");
    let opts = ImpactOptions::default();
    let w = Matrix3::identity();
    let u = Vector3::new(0.0, 0.0, -1.0);
    for (n, ok) in [
        (Vector3::zeros(), false),
        (Vector3::new(0.0, 0.0, 1.1), false),
        (Vector3::z(), true),
    ] {
        let r = resolve_in_contact_space(&w, &u, &n, &law, &opts);
        assert_eq!(r.is_ok(), ok, "{r:?}");
    }
    assert!(matches!(
        resolve_in_contact_space(&w, &Vector3::new(f64::NAN, 0.0, -1.0), &Vector3::z(), &law, &opts),
        Err(ImpulseError::NonFinite { .. })
    ));
    assert!(matches!(
        resolve_in_contact_space(&-w, &u, &Vector3::z(), &law, &opts),
        Err(ImpulseError::InvalidInertia { .. })
    ));
    // An impulse beyond f64 range is an error, never an infinity or NaN in the result.
    let huge = resolve_in_contact_space(&(w * 1e-300), &(u * 1e300), &Vector3::z(), &law, &opts);
    assert_eq!(huge, Err(ImpulseError::NonFiniteResult { quantity: "impulse" }));
    // Both bodies static and approaching: nothing can stop them.
    let g1 = RigidBody::fixed(Vector3::zeros()).expect("ok");
    let g2 = RigidBody::from_inverse(
        0.0,
        &Matrix3::zeros(),
        Vector3::zeros(),
        -Vector3::y(),
        Vector3::zeros(),
    )
    .expect("ok");
    assert!(matches!(
        resolve_contact(&g1, &g2, &Vector3::zeros(), &Vector3::y(), &law, &opts),
        Err(ImpulseError::Singular { .. })
    ));
    // Negative mass.
    let mut props = mechanica_mass::MassProperties::point(1.0, Vector3::zeros()).expect("ok");
    props.mass = -1.0;
    assert!(matches!(
        RigidBody::from_mass_properties(&props, Vector3::zeros(), Vector3::zeros()),
        Err(ImpulseError::NonPositiveMass { .. })
    ));
}

#[test]
fn a_static_body_struck_by_a_point_mass_in_contact_space() {
    // Point mass m against a wall: W = I/m; all laws give P_n = (1 + e) m v.
    let (m, v, e) = (3.0, 2.0, 0.4);
    let law = ContactLaw::new(e, 0.3, RestitutionLaw::Poisson).expect("law");
    let out = resolve_in_contact_space(
        &(Matrix3::identity() / m),
        &Vector3::new(0.5, 0.0, -v),
        &Vector3::z(),
        &law,
        &ImpactOptions::default(),
    )
    .expect("ok");
    assert!((out.normal_impulse - (1.0 + e) * m * v).abs() < 1e-14 * m * v);
    assert!((out.energy_change - 0.5 * m * ((out.u_after_w.norm_squared()) - (0.25 + v * v))).abs() < 1e-13);
}

/// A swerving slip whose direction settles long before it halts: the step cap near a halt
/// (half the slip speed over the largest possible rate) once took more than the step budget;
/// the slip is now finished in closed form once its remaining turn is below the tolerance.
#[test]
fn a_slip_that_stops_swerving_long_before_it_halts_finishes() {
    let b = Body::new(
        2.2566309931730295,
        Vector3::new(0.7750475024818083, -0.9909589799763204, -0.8494229061319916),
        Matrix3::new(
            0.9650233942636324,
            0.05892415121112926,
            0.11129912940775538,
            0.05892415121112926,
            0.550655255187719,
            -0.4603491831559823,
            0.11129912940775533,
            -0.4603491831559823,
            0.4294569538373744,
        ),
        Vector3::new(1.272644709179955, 0.36727615673265107, 1.3728722726026752),
        Vector3::new(0.9335659001667853, -1.3690511512708896, -0.546728541536205),
    );
    let r = Vector3::new(-0.6974885365872442, 1.5967483806237999, -1.7335967922471072);
    let n = Vector3::new(-0.34275392572614216, -0.22621733417523632, -0.9117593999506155).normalize();
    let law = ContactLaw::new(0.0, 2.442091041837602, RestitutionLaw::Stronge).expect("law");
    let ground = RigidBody::fixed(Vector3::zeros()).expect("ground");
    let out = resolve_contact(&ground, &b.rigid(), &r, &n, &law, &ImpactOptions::default()).expect("impact");
    assert!(out.contact.steps < 1000, "{} steps", out.contact.steps);
    // (7.71) about the contact point, and no energy gained.
    let before = b.angular_momentum_about(&r, &b.v, &b.w);
    let after = b.angular_momentum_about(&r, &out.body2.v_wc_after, &out.body2.w_w_after);
    assert!((after - before).norm() <= 1e-11 * (before.norm() + b.props.mass * b.v.norm() * (b.props.p_oc - r).norm()));
    assert!(b.energy_after(&out.body2) <= b.energy_before());
    // The contact stops slipping (e = 0: the normal velocity ends at zero too).
    assert!(out.contact.u_after_w.norm() <= 1e-8 * out.u_before_w.norm());
}

/// Results beyond the range of f64 are typed errors naming the quantity, never NaN or ∞.
#[test]
fn overflowing_results_are_typed_errors() {
    use mechanica_impulse::point::{collide_collinear, impulse_on_point};
    let overflow = |quantity| Some(ImpulseError::NonFiniteResult { quantity });
    // V = v + S/m with S/m = 1e310.
    assert_eq!(
        impulse_on_point(1e-300, &Vector3::zeros(), &Vector3::new(1e10, 0.0, 0.0)).err(),
        overflow("velocity after the impulse")
    );
    // An approach speed of 2e308.
    assert_eq!(
        collide_collinear(1.0, 1e308, 1.0, -1e308, 0.5).err(),
        overflow("velocities after the collision")
    );
    // A body so light that its inverse mass overflows.
    let props = mechanica_mass::MassProperties::point(1e-310, Vector3::zeros()).expect("positive mass");
    assert!(matches!(
        RigidBody::from_mass_properties(&props, Vector3::zeros(), Vector3::zeros()),
        Err(ImpulseError::NonFiniteResult { .. })
    ));
}
