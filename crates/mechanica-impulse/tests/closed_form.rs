//! Closed-form impacts: billiard balls, a spinning sphere on a wall, a rod striking the ground
//! at an angle (smooth, sticking, sliding, halting, reversing), rigid-body fixation, and
//! Kane's paradox for Newton's law.

mod common;

use common::Body;
use mechanica_impulse::{
    ContactLaw, ContactMode, ImpactOptions, RestitutionLaw, RigidBody, TwoBodyImpact, resolve_contact,
};
use nalgebra::Vector3;

fn ground() -> RigidBody {
    RigidBody::fixed(Vector3::zeros()).expect("ground")
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale
}

fn hit(
    b1: &RigidBody,
    b2: &RigidBody,
    r: Vector3<f64>,
    n: Vector3<f64>,
    e: f64,
    f: f64,
    law: RestitutionLaw,
) -> TwoBodyImpact {
    let law = ContactLaw::new(e, f, law).expect("law");
    resolve_contact(b1, b2, &r, &n, &law, &ImpactOptions::default()).expect("impact")
}

#[test]
fn billiard_balls_with_friction_stick_or_slide_by_the_7_over_m_rule() {
    // Two equal balls (mass m, radius R), ball 2 at rest at 2R x̂. Contact mobility
    // W = (2/m) n nᵀ + (7/m)(I − n nᵀ): normal impulse p = (1 + e) m v_n / 2; the contact
    // sticks iff (m/7)|v_t| ≤ f p.
    let (m, radius, e) = (0.17, 0.028575, 0.9);
    let (v_n, v_t) = (2.0, 0.6);
    for (f, sticks) in [(0.5, true), (0.03, false)] {
        let b1 = Body::sphere(
            m,
            radius,
            Vector3::zeros(),
            Vector3::new(v_n, v_t, 0.0),
            Vector3::zeros(),
        );
        let b2 = Body::sphere(
            m,
            radius,
            Vector3::new(2.0 * radius, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        let out = hit(
            &b1.rigid(),
            &b2.rigid(),
            Vector3::new(radius, 0.0, 0.0),
            Vector3::x(),
            e,
            f,
            RestitutionLaw::Stronge,
        );
        let p = (1.0 + e) * m * v_n / 2.0;
        let p_t = if sticks { m * v_t / 7.0 } else { f * p };
        let mode = if sticks {
            ContactMode::SlipThenStick
        } else {
            ContactMode::Slip
        };
        assert_eq!(out.contact.mode, mode);
        assert!(
            close(out.contact.normal_impulse, p, p),
            "{} vs {p}",
            out.contact.normal_impulse
        );
        assert!(
            close(out.contact.impulse_w.y, p_t, p),
            "{} vs {p_t}",
            out.contact.impulse_w.y
        );
        assert!(close(out.body2.v_wc_after.x, p / m, v_n) && close(out.body2.v_wc_after.y, p_t / m, v_n));
        // Spin of ball 2: J Ω = d × P with d = −R x̂: Ω_z = −R P_y / (0.4 m R²).
        assert!(close(out.body2.w_w_after.z, -p_t / (0.4 * m * radius), v_n / radius));
        let t_before = b1.energy_before();
        let dt = b1.energy_after(&out.body1) + b2.energy_after(&out.body2) - t_before;
        assert!(close(out.contact.energy_change, dt, t_before) && dt < 0.0);
    }
}

#[test]
fn spinning_sphere_hitting_a_wall_rolls_or_slides() {
    // Sphere (m, R) at height R above the ground y = 0, v = (v_x, −v_y), spin ω_z. The contact
    // slip is u_t = v_x + R ω_z; W = n nᵀ/m + 7/(2m) (I − n nᵀ); p = (1 + e) m v_y.
    let (m, radius, e) = (2.0, 0.1, 0.6);
    let (v_x, v_y, w_z) = (1.0, 3.0, 25.0);
    let u_t = v_x + radius * w_z;
    let p = (1.0 + e) * m * v_y;
    for (f, sticks) in [(0.6, true), (0.1, false)] {
        let ball = Body::sphere(
            m,
            radius,
            Vector3::new(0.0, radius, 0.0),
            Vector3::new(v_x, -v_y, 0.0),
            Vector3::new(0.0, 0.0, w_z),
        );
        for law in [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge] {
            let out = hit(&ground(), &ball.rigid(), Vector3::zeros(), Vector3::y(), e, f, law);
            let p_x = if sticks {
                -2.0 * m * u_t / 7.0
            } else {
                -f * p * u_t.signum()
            };
            assert!(close(out.contact.normal_impulse, p, p));
            assert!(
                close(out.contact.impulse_w.x, p_x, p),
                "{law:?}: {} vs {p_x}",
                out.contact.impulse_w.x
            );
            let v_after = v_x + p_x / m;
            let w_after = w_z + 5.0 * p_x / (2.0 * m * radius);
            assert!(close(out.body2.v_wc_after.x, v_after, v_y) && close(out.body2.v_wc_after.y, -v_y + p / m, v_y));
            assert!(close(out.body2.w_w_after.z, w_after, w_z));
            if sticks {
                // Rolling after the impact: V_x + R Ω_z = 0.
                assert!((out.body2.v_wc_after.x + radius * out.body2.w_w_after.z).abs() < 1e-12 * v_y);
                assert_eq!(out.contact.mode, ContactMode::SlipThenStick);
            } else {
                assert_eq!(out.contact.mode, ContactMode::Slip);
            }
            // Closed-form segments report only their rounding: a few ulps of the impulse.
            let bound = out.contact.integration_error;
            assert!(bound > 0.0 && bound <= 64.0 * f64::EPSILON * p, "{law:?}: {bound:e}");
        }
    }
}

/// Rod of mass m, length L, lower end at the origin, tilted by θ from the ground, falling at
/// speed v and sliding at v_x; its mobility at the end (n = ŷ, t = x̂):
/// W_nn = (1 + 3cos²θ)/m, W_tt = (1 + 3sin²θ)/m, W_tn = −3 sinθ cosθ/m.
struct FallingRod {
    m: f64,
    length: f64,
    theta: f64,
}

impl FallingRod {
    fn body(&self, v: f64, v_x: f64) -> Body {
        let (s, c) = self.theta.sin_cos();
        let centre = Vector3::new(c, s, 0.0) * (self.length / 2.0);
        Body::rod(
            self.m,
            self.length,
            centre,
            Vector3::new(c, s, 0.0),
            Vector3::new(v_x, -v, 0.0),
            Vector3::zeros(),
        )
    }
    fn w(&self) -> (f64, f64, f64) {
        let (s, c) = self.theta.sin_cos();
        (
            (1.0 + 3.0 * c * c) / self.m,
            (1.0 + 3.0 * s * s) / self.m,
            -3.0 * s * c / self.m,
        )
    }
}

#[test]
fn rod_striking_the_ground_smooth_sticking_and_sliding() {
    let rod = FallingRod {
        m: 1.5,
        length: 0.8,
        theta: 0.6,
    };
    let (w_nn, w_tt, w_tn) = rod.w();
    let (v, e) = (2.0, 0.5);
    let stick_ratio = -w_tn / w_tt;
    let cases = [
        // (f, tangential impulse per unit normal impulse, normal rate du_n/dp, mode)
        (0.0, 0.0, w_nn, ContactMode::Frictionless),
        (
            stick_ratio * 1.5,
            stick_ratio,
            w_nn + w_tn * stick_ratio,
            ContactMode::Stick,
        ),
        // Sliding from rest: slip starts along ŝ = sign(W_tn) = −x̂, so P_x = +f p.
        (
            stick_ratio * 0.5,
            stick_ratio * 0.5,
            w_nn + w_tn * stick_ratio * 0.5,
            ContactMode::Slip,
        ),
    ];
    for (f, ratio, rate, mode) in cases {
        let body = rod.body(v, 0.0);
        for law in [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge] {
            let out = hit(&ground(), &body.rigid(), Vector3::zeros(), Vector3::y(), e, f, law);
            let p = (1.0 + e) * v / rate;
            assert_eq!(out.contact.mode, mode, "f = {f}, {law:?}");
            assert!(
                close(out.contact.normal_impulse, p, p),
                "{law:?} f={f}: {} vs {p}",
                out.contact.normal_impulse
            );
            assert!(close(out.contact.impulse_w.x, ratio * p, p));
            // Post-impact normal velocity −e·(−v) for every law (constant ratio).
            assert!(close(out.contact.u_after_w.y, e * v, v));
            let dt = body.energy_after(&out.body2) - body.energy_before();
            assert!(close(out.contact.energy_change, dt, body.energy_before()) && dt < 0.0);
        }
    }
}

/// Piecewise-linear reference for a rod that slides at v_x > 0: the slip (ŝ = +x̂, P_x' = −f)
/// halts at p₁ = v_x / (f W_tt − W_tn); then it sticks (P_x' = t*) or reverses (P_x' = +f).
/// Returns the final normal impulse by the law, from the closed-form normal velocity and work.
fn rod_reference(rod: &FallingRod, v: f64, v_x: f64, e: f64, f: f64, law: RestitutionLaw) -> (f64, f64) {
    let (w_nn, w_tt, w_tn) = rod.w();
    let p1 = v_x / (f * w_tt - w_tn);
    let stick = -w_tn / w_tt;
    let ratio2 = if stick <= f { stick } else { f };
    let (r1, r2) = (w_nn - w_tn * f, w_nn + w_tn * ratio2);
    // u_n(p) piecewise linear, with u_n(0) = −v; work W(p) = ∫ u_n.
    let u_n = |p: f64| {
        if p <= p1 {
            -v + r1 * p
        } else {
            -v + r1 * p1 + r2 * (p - p1)
        }
    };
    let work = |p: f64| {
        if p <= p1 {
            -v * p + 0.5 * r1 * p * p
        } else {
            -v * p1 + 0.5 * r1 * p1 * p1 + u_n(p1) * (p - p1) + 0.5 * r2 * (p - p1).powi(2)
        }
    };
    // Bisection on monotone functions (independent of the crate's closed-form root formulas).
    let solve = |g: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64| {
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) < 0.0 { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    };
    let big = 100.0 * v / w_nn.min(r2);
    let p_c = solve(&|p| u_n(p), 0.0, big);
    let p_f = match law {
        RestitutionLaw::Newton => solve(&|p| u_n(p) - e * v, p_c, big),
        RestitutionLaw::Poisson => (1.0 + e) * p_c,
        RestitutionLaw::Stronge => {
            let w_c = work(p_c);
            solve(&|p| work(p) - (1.0 - e * e) * w_c, p_c, big)
        }
    };
    let p_x = if p_f <= p1 {
        -f * p_f
    } else {
        -f * p1 + ratio2 * (p_f - p1)
    };
    (p_f, p_x)
}

#[test]
fn rod_sliding_along_the_ground_halts_then_sticks_or_reverses() {
    let rod = FallingRod {
        m: 1.5,
        length: 0.8,
        theta: 0.6,
    };
    let (_, w_tt, w_tn) = rod.w();
    let stick = -w_tn / w_tt;
    let (v, v_x, e) = (2.0, 0.3, 0.7);
    for (f, mode) in [
        (stick * 1.2, ContactMode::SlipThenStick),
        (stick * 0.6, ContactMode::Reversed),
    ] {
        let body = rod.body(v, v_x);
        for law in [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge] {
            let out = hit(&ground(), &body.rigid(), Vector3::zeros(), Vector3::y(), e, f, law);
            let (p_f, p_x) = rod_reference(&rod, v, v_x, e, f, law);
            assert_eq!(out.contact.mode, mode, "{law:?}");
            // Bisection converges to ~1 ulp; the halting point is a closed-form root.
            assert!(
                (out.contact.normal_impulse - p_f).abs() < 1e-11 * p_f,
                "{law:?}: {} vs {p_f}",
                out.contact.normal_impulse
            );
            assert!(
                (out.contact.impulse_w.x - p_x).abs() < 1e-11 * p_f,
                "{law:?}: {} vs {p_x}",
                out.contact.impulse_w.x
            );
        }
    }
}

#[test]
fn kanes_paradox_newton_gains_energy_where_stronge_does_not() {
    // A rod falling at 0.85 rad with a forward slide and friction just below the sticking
    // ratio: the slip halts near the end of compression and reverses during restitution, where
    // the normal velocity grows more slowly per unit impulse than it fell during compression. With Newton's law and e = 1 the kinetic energy after
    // the impact exceeds the energy before (Kane & Levinson's paradox); Poisson's and
    // Stronge's laws do not.
    let rod = FallingRod {
        m: 1.0,
        length: 1.0,
        theta: 0.85,
    };
    let (_, w_tt, w_tn) = rod.w();
    let f = 0.9 * (-w_tn / w_tt);
    let body = rod.body(1.0, 0.5);
    let mut gains = Vec::new();
    for law in [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge] {
        let out = hit(&ground(), &body.rigid(), Vector3::zeros(), Vector3::y(), 1.0, f, law);
        assert_eq!(out.contact.mode, ContactMode::Reversed, "{law:?}");
        let gain = body.energy_after(&out.body2) - body.energy_before();
        assert!((gain - out.contact.energy_change).abs() < 1e-12 * body.energy_before());
        gains.push(gain);
    }
    assert!(gains[0] > 1e-3 * body.energy_before(), "Newton: ΔT = {}", gains[0]);
    assert!(gains[2] <= 1e-14 * body.energy_before(), "Stronge: ΔT = {}", gains[2]);
}

#[test]
fn hinged_pendulum_striking_a_wall_has_effective_mass_m_over_3() {
    // Rod (m, L) hanging from a revolute hinge at (0, L, 0) about z, swinging at ω: its tip at
    // the origin moves at ωL along x and hits a wall whose normal points along −x. The tip can
    // move only along x, so W = (3/m) n nᵀ (singular tangential block): the friction impulse
    // is zero, p = (1 + e)(m/3) ωL and Ω = −e ω (7.87*–7.91*).
    let (m, l, w, e) = (1.2, 0.9, 2.0, 0.7);
    let rod = Body::rod(
        m,
        l,
        Vector3::new(0.0, l / 2.0, 0.0),
        Vector3::y(),
        Vector3::new(w * l / 2.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, w),
    );
    let hinged = rod
        .rigid()
        .hinged_on_axis(&Vector3::new(0.0, l, 0.0), &Vector3::z())
        .expect("consistent hinge");
    let wall = RigidBody::fixed(Vector3::new(1.0, 0.0, 0.0)).expect("wall");
    for law in [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge] {
        let out = hit(&wall, &hinged, Vector3::zeros(), -Vector3::x(), e, 0.5, law);
        let p = (1.0 + e) * m / 3.0 * w * l;
        assert!(
            close(out.contact.normal_impulse, p, p),
            "{law:?}: {} vs {p}",
            out.contact.normal_impulse
        );
        assert!(out.contact.tangential_impulse_w.norm() < 1e-12 * p);
        assert!(close(out.body2.w_w_after.z, -e * w, w));
        assert_eq!(out.contact.mode, ContactMode::Stick);
        // Energy from the pendulum formula ½ (mL²/3) Ω².
        let j_h = m * l * l / 3.0;
        let dt = 0.5 * j_h * (out.body2.w_w_after.z.powi(2) - w * w);
        assert!(close(out.contact.energy_change, dt, j_h * w * w));
    }
}

/// Tolerances that would end a slip still in progress (above 1e-2), zero, negative or NaN
/// tolerances and a zero step budget are refused; the largest allowed tolerance still gives a
/// sliding sphere's impulse to its closed form p_t = −f p_n.
#[test]
fn meaningless_impact_options_are_refused() {
    let (m, radius, e, f) = (2.0, 0.1, 0.6, 0.1);
    let ball = Body::sphere(
        m,
        radius,
        Vector3::new(0.0, radius, 0.0),
        Vector3::new(1.0, -3.0, 0.0),
        Vector3::new(0.0, 0.0, 25.0),
    );
    let law = ContactLaw::new(e, f, RestitutionLaw::Poisson).expect("law");
    let resolve = |options: ImpactOptions| {
        resolve_contact(
            &ground(),
            &ball.rigid(),
            &Vector3::zeros(),
            &Vector3::y(),
            &law,
            &options,
        )
    };
    for tolerance in [0.5, 1.0, 1e300, 0.0, -1e-10, f64::NAN, f64::INFINITY] {
        let options = ImpactOptions {
            tolerance,
            ..ImpactOptions::default()
        };
        assert!(
            matches!(
                resolve(options),
                Err(mechanica_impulse::ImpulseError::InvalidOption { .. }
                    | mechanica_impulse::ImpulseError::NonFinite { .. })
            ),
            "tolerance {tolerance} accepted"
        );
    }
    let no_steps = ImpactOptions {
        max_steps: 0,
        ..ImpactOptions::default()
    };
    assert!(resolve(no_steps).is_err());
    let coarse = ImpactOptions {
        tolerance: mechanica_impulse::MAX_IMPACT_TOLERANCE,
        ..ImpactOptions::default()
    };
    let out = resolve(coarse).expect("coarse tolerance");
    let p_n = (1.0 + e) * m * 3.0;
    let impulse = out.contact.impulse_w;
    assert!((impulse.y - p_n).abs() <= 1e-12 * p_n, "{impulse}");
    assert!((impulse.x + f * p_n).abs() <= 1e-12 * p_n, "{impulse}");
}
