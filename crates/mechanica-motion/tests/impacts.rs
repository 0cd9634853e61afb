//! Runs with unilateral contacts against closed forms: a mass bouncing on the ground under
//! gravity (impact times t_{k+1} = t_k + 2 e^k v₁/g, losses ½ m v_k² (1 − e²)), a graze at the
//! apex of a throw that no step end sees, sustained contact refused, and a double pendulum
//! striking the ground (energy bookkeeping across impacts, elastic impacts conserve H); and
//! against impact sequences of a double pendulum striking a wall computed independently with
//! SciPy's event location (tools/impact_sequence_reference.py).

mod common;
use common::Rng;
use mechanica_dynamics::Dynamics;
use mechanica_impulse::{BodyPoint, ContactLaw, MechanismContact, RestitutionLaw};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_motion::{Method, MotionError, Options, Simulation, StepFailure, UnilateralContact};
use nalgebra::{Isometry3, Vector3};

/// A point mass m on a prismatic joint along z (q = height), gravity g along −z.
fn falling_mass(m: f64, g: f64) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Prismatic { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(m, Vector3::zeros()).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

/// A frictionless contact of body `body`'s point `p` with the plane n·x = offset.
fn plane_contact(
    body: usize,
    p: Vector3<f64>,
    normal: Vector3<f64>,
    offset: f64,
    e: f64,
    law: RestitutionLaw,
) -> UnilateralContact {
    UnilateralContact {
        contact: MechanismContact {
            point: BodyPoint { body, p_bq: p },
            other: None,
            normal_w: normal,
            law: ContactLaw::new(e, 0.0, law).expect("law"),
        },
        offset,
    }
}

/// Dormand–Prince with tolerances for lengths of `scale`, and the fixed-step methods with
/// `step`.
fn methods(scale: f64, step: f64) -> [Method; 3] {
    [
        Method::DormandPrince {
            rtol: 1e-11,
            atol: 1e-13 * scale,
        },
        Method::Rk4 { step },
        Method::StormerVerlet { step },
    ]
}

const LAWS: [RestitutionLaw; 3] = [RestitutionLaw::Newton, RestitutionLaw::Poisson, RestitutionLaw::Stronge];

/// Dropped from h₀ at rest: impact k at t_k with speed v_k = e^{k−1} v₁; five impacts and half
/// the next flight, for random masses, gravities, heights and restitutions, every law and
/// three methods. Gravity is constant, so every method integrates the flights exactly and only
/// the located event times carry error.
#[test]
fn bouncing_mass_matches_the_closed_form() {
    let mut rng = Rng::new(41);
    for case in 0..30 {
        let (m, g, h0) = (rng.decades(-3.0, 3.0), rng.uniform(1.0, 20.0), rng.decades(-2.0, 1.0));
        let e = rng.uniform(0.3, 0.95);
        let law = LAWS[rng.below(3)];
        let v1 = (2.0 * g * h0).sqrt();
        let mut times = vec![v1 / g];
        for k in 1..5 {
            times.push(times[k - 1] + 2.0 * e.powi(k as i32) * v1 / g);
        }
        let t_end = times[4] + e.powi(5) * v1 / g;
        for method in methods(h0, times[0] / 40.0) {
            let contact = plane_contact(0, Vector3::zeros(), Vector3::z(), 0.0, e, law);
            let simulation = Simulation::new(falling_mass(m, g), method, Options::default())
                .and_then(|s| s.with_contacts(vec![contact]))
                .expect("simulation");
            let run = simulation.run(&[h0], &[0.0], t_end, t_end / 4.0);
            let run = run.unwrap_or_else(|e| panic!("case {case} {method:?}: {e}"));
            assert_eq!(run.impacts.len(), 5, "case {case} {method:?}");
            for (k, impact) in run.impacts.iter().enumerate() {
                let v = e.powi(k as i32) * v1;
                let lost = 0.5 * m * v * v * (1.0 - e * e);
                let at = format!("case {case} {method:?} impact {k}");
                assert!(
                    (impact.t - times[k]).abs() <= 1e-9 * times[k],
                    "{at}: t {} vs {}",
                    impact.t,
                    times[k]
                );
                assert!(
                    (impact.approach_speed - v).abs() <= 1e-8 * v,
                    "{at}: speed {} vs {v}",
                    impact.approach_speed
                );
                assert!(
                    (impact.energy_lost() - lost).abs() <= 1e-7 * lost,
                    "{at}: lost {} vs {lost}",
                    impact.energy_lost()
                );
                assert!(
                    (impact.q_dot_after[0] - e * v).abs() <= 1e-8 * v,
                    "{at}: rebound {}",
                    impact.q_dot_after[0]
                );
                assert!(
                    impact.gap <= 0.0 && impact.gap >= -1e-8 * h0,
                    "{at}: gap {}",
                    impact.gap
                );
                assert!(
                    impact.segment_drift.abs() <= 1e-9 * m * g * h0,
                    "{at}: drift {}",
                    impact.segment_drift
                );
            }
            let last = run.samples.last().expect("samples");
            let apex = (e.powi(5) * v1).powi(2) / (2.0 * g);
            assert!(
                (last.q[0] - apex).abs() <= 1e-7 * h0,
                "case {case} {method:?}: {} vs apex {apex}",
                last.q[0]
            );
            assert!(
                last.q_dot[0].abs() <= 1e-7 * v1,
                "case {case} {method:?}: {}",
                last.q_dot[0]
            );
            assert!(
                run.monitors.max_drift <= 1e-8,
                "case {case} {method:?}: drift {}",
                run.monitors.max_drift
            );
        }
    }
}

/// A throw whose apex pokes δ above a ceiling between two step ends (RK4 is exact for the
/// parabola): the dip of the cubic Hermite gap finds it, the event is located at the first
/// crossing t_apex − √(2δ/g), and the elastic impact sends the mass down at the same speed.
#[test]
fn a_graze_between_step_ends_is_found() {
    let mut rng = Rng::new(7);
    for case in 0..40 {
        let g = rng.uniform(1.0, 20.0);
        let h = rng.decades(-3.0, -1.0);
        let steps_to_apex = 2 + rng.below(20);
        let t_apex = (steps_to_apex as f64 + rng.uniform(0.3, 0.7)) * h;
        let v0 = g * t_apex;
        let apex = v0 * v0 / (2.0 * g);
        // Above the ceiling for 2√(2δ/g) < h/10: no step end sees it.
        let window = h * rng.uniform(0.01, 0.1);
        let delta = g * window * window / 8.0;
        let ceiling = apex - delta;
        let contact = plane_contact(
            0,
            Vector3::zeros(),
            -Vector3::z(),
            -ceiling,
            1.0,
            RestitutionLaw::Newton,
        );
        let simulation = Simulation::new(falling_mass(1.0, g), Method::Rk4 { step: h }, Options::default())
            .and_then(|s| s.with_contacts(vec![contact]))
            .expect("simulation");
        let t_end = t_apex + 3.0 * h;
        let run = simulation.run(&[0.0], &[v0], t_end, t_end).expect("run");
        assert_eq!(run.impacts.len(), 1, "case {case}: the graze was missed");
        let impact = &run.impacts[0];
        let t_hit = t_apex - (2.0 * delta / g).sqrt();
        let speed = (2.0 * g * delta).sqrt();
        assert!(
            (impact.t - t_hit).abs() <= 1e-6 * window,
            "case {case}: t {} vs {t_hit}",
            impact.t
        );
        assert!(
            (impact.approach_speed - speed).abs() <= 1e-5 * speed,
            "case {case}: speed {} vs {speed}",
            impact.approach_speed
        );
        assert!(
            (impact.q_dot_after[0] + speed).abs() <= 1e-5 * speed,
            "case {case}: rebound {}",
            impact.q_dot_after[0]
        );
    }
}

/// A plastic impact (e = 0) leaves the mass on the ground, closing again under gravity: the
/// run stops with the sustained-contact failure right after the impact, which is recorded.
/// A bouncing mass run past the accumulation time t∞ = t₁ (1 + 2e/(1 − e)) stops the same way
/// (or on the impact limit), never silently sinking through the ground.
#[test]
fn sustained_contact_stops_the_run() {
    let mut rng = Rng::new(3);
    for case in 0..12 {
        let (g, h0) = (rng.uniform(1.0, 20.0), rng.decades(-2.0, 1.0));
        let e = if case % 2 == 0 { 0.0 } else { rng.uniform(0.2, 0.8) };
        let t1 = (2.0 * h0 / g).sqrt();
        let t_accumulate = t1 * (1.0 + 2.0 * e / (1.0 - e));
        let contact = plane_contact(0, Vector3::zeros(), Vector3::z(), 0.0, e, RestitutionLaw::Newton);
        let options = Options {
            max_impacts: 500,
            ..Options::default()
        };
        let simulation = Simulation::new(
            falling_mass(2.0, g),
            Method::DormandPrince {
                rtol: 1e-9,
                atol: 1e-12,
            },
            options,
        )
        .and_then(|s| s.with_contacts(vec![contact]))
        .expect("simulation");
        let mut stepper = simulation.start(&[h0], &[0.0]).expect("start");
        let failure = stepper
            .advance(3.0 * t_accumulate + 1.0)
            .expect_err("the run must stop");
        let MotionError::StepFailed { t, q, cause, .. } = failure else {
            panic!("case {case}: {failure}");
        };
        assert!(
            matches!(
                cause,
                StepFailure::SustainedContact { contact: 0, .. } | StepFailure::TooManyImpacts { .. }
            ),
            "case {case}: {cause}"
        );
        assert!(
            t <= t_accumulate * (1.0 + 1e-3) + 1e-9,
            "case {case}: stopped at {t}, t∞ = {t_accumulate}"
        );
        assert!(q[0] > -1e-6 * h0, "case {case}: sank to {}", q[0]);
        assert!(!stepper.impacts().is_empty(), "case {case}");
    }
}

/// A planar double pendulum released from random angles above the ground z = −d: its tip
/// strikes the ground repeatedly. Elastic frictionless impacts keep H (each loss within the
/// run's drift); frictional and inelastic ones never gain energy under Stronge's law; the
/// energy monitor excludes the impacts' changes; H at the end equals H(0) plus the segments'
/// drifts minus the losses.
#[test]
fn double_pendulum_striking_the_ground_keeps_the_books() {
    let mut rng = Rng::new(11);
    for case in 0..16 {
        let (l1, l2) = (rng.uniform(0.3, 1.0), rng.uniform(0.3, 1.0));
        let mut builder = TreeBuilder::new();
        builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
        builder.add_body(
            Some(0),
            Joint::Revolute { axis: Vector3::x() },
            Isometry3::translation(0.0, 0.0, -l1),
        );
        let tree = builder.build().expect("tree");
        let bodies = vec![
            MassProperties::point(rng.decades(-1.0, 1.0), Vector3::new(0.0, 0.0, -l1)).expect("mass"),
            MassProperties::point(rng.decades(-1.0, 1.0), Vector3::new(0.0, 0.0, -l2)).expect("mass"),
        ];
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
        let dynamics = Dynamics::new(mechanism).expect("dynamics");
        let elastic = case % 2 == 0;
        let (e, friction) = if elastic {
            (1.0, 0.0)
        } else {
            (rng.uniform(0.3, 0.9), rng.uniform(0.1, 1.0))
        };
        let law = ContactLaw::new(e, friction, RestitutionLaw::Stronge).expect("law");
        let contact = UnilateralContact {
            contact: MechanismContact {
                point: BodyPoint {
                    body: 1,
                    p_bq: Vector3::new(0.0, 0.0, -l2),
                },
                other: None,
                normal_w: Vector3::z(),
                law,
            },
            offset: -(l1 + l2) * rng.uniform(0.5, 0.9),
        };
        let method = Method::DormandPrince {
            rtol: 1e-10,
            atol: 1e-12,
        };
        let simulation = Simulation::new(dynamics, method, Options::default())
            .and_then(|s| s.with_contacts(vec![contact]))
            .expect("simulation");
        let q0 = [rng.uniform(1.2, 2.0), rng.uniform(-0.5, 0.5)];
        let run = simulation.run(&q0, &[0.0, 0.0], 3.0, 0.5);
        let run = match run {
            Ok(run) => run,
            Err(MotionError::StepFailed {
                cause: StepFailure::SustainedContact { .. },
                ..
            }) if !elastic => continue,
            Err(e) => panic!("case {case}: {e}"),
        };
        assert!(!run.impacts.is_empty(), "case {case}: no impact");
        let h0 = run.samples[0].energy;
        let scale = run.monitors.scale;
        let mut booked = h0;
        for (k, impact) in run.impacts.iter().enumerate() {
            let at = format!("case {case} impact {k}");
            assert!(
                impact.segment_drift.abs() <= 1e-7 * scale,
                "{at}: drift {:e}",
                impact.segment_drift
            );
            if elastic {
                assert!(
                    impact.energy_lost().abs() <= 1e-9 * scale,
                    "{at}: lost {:e}",
                    impact.energy_lost()
                );
            } else {
                assert!(
                    impact.energy_lost() >= -1e-12 * scale,
                    "{at}: gained {:e}",
                    -impact.energy_lost()
                );
            }
            booked += impact.segment_drift - impact.energy_lost();
        }
        let last = run.samples.last().expect("samples");
        assert!(
            (last.energy - booked).abs() <= 1e-7 * scale,
            "case {case}: H {} vs booked {booked}",
            last.energy
        );
        assert!(
            run.monitors.max_drift <= 1e-7,
            "case {case}: monitor drift {}",
            run.monitors.max_drift
        );
    }
}

/// Invalid contacts are refused with their index: a missing body, a normal that is not a unit
/// vector, a non-finite offset, and contacts on a mechanism with holonomic constraints.
#[test]
fn invalid_contacts_are_refused() {
    let simulation = || {
        Simulation::new(falling_mass(1.0, 9.81), Method::Rk4 { step: 1e-3 }, Options::default()).expect("simulation")
    };
    let good = plane_contact(0, Vector3::zeros(), Vector3::z(), 0.0, 0.5, RestitutionLaw::Newton);
    let mut missing = good;
    missing.contact.point.body = 3;
    let mut long = good;
    long.contact.normal_w = Vector3::new(0.0, 0.0, 1.001);
    let mut far = good;
    far.offset = f64::INFINITY;
    for (i, bad) in [missing, long, far].into_iter().enumerate() {
        let result = simulation().with_contacts(vec![good, bad]);
        assert!(
            matches!(result, Err(MotionError::InvalidContact { index: 1, .. })),
            "bad contact {i}: {result:?}"
        );
    }
}

/// Ten double pendulums of point masses (random masses, lengths, restitutions and walls) striking
/// a wall two to fourteen times in 4 s, against the sequences of tools/impact_sequence_reference.py
/// (SciPy DOP853 with event location at rtol 1e-13, its own Newton impact map; `err_t`, `err_q`
/// its accuracy from a run at 1e-11): the same number of impacts at the same times with the
/// same losses, and the final state within this run's own global error estimate plus the
/// reference's.
#[test]
fn double_pendulum_against_scipy_event_location() {
    let text = include_str!("../../../tools/impact_sequence_reference.json");
    let reference: serde_json::Value = serde_json::from_str(text).expect("reference JSON");
    let g = reference["g"].as_f64().expect("g");
    let cases = reference["cases"].as_array().expect("cases");
    assert!(cases.len() >= 8, "{} cases", cases.len());
    for (case, c) in cases.iter().enumerate() {
        let get = |key: &str| c[key].as_f64().unwrap_or_else(|| panic!("case {case}: {key}"));
        let list = |key: &str| -> Vec<f64> {
            c[key]
                .as_array()
                .expect("array")
                .iter()
                .map(|v| v.as_f64().expect("number"))
                .collect()
        };
        let (l1, l2) = (get("l1"), get("l2"));
        let mut builder = TreeBuilder::new();
        builder.add_body(None, Joint::Revolute { axis: Vector3::y() }, Isometry3::identity());
        builder.add_body(
            Some(0),
            Joint::Revolute { axis: Vector3::y() },
            Isometry3::translation(0.0, 0.0, -l1),
        );
        let tree = builder.build().expect("tree");
        let bodies = vec![
            MassProperties::point(get("m1"), Vector3::new(0.0, 0.0, -l1)).expect("mass"),
            MassProperties::point(get("m2"), Vector3::new(0.0, 0.0, -l2)).expect("mass"),
        ];
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
        let dynamics = Dynamics::new(mechanism).expect("dynamics");
        let wall = plane_contact(
            1,
            Vector3::new(0.0, 0.0, -l2),
            -Vector3::x(),
            -get("wall"),
            get("e"),
            RestitutionLaw::Newton,
        );
        let method = Method::DormandPrince {
            rtol: 1e-12,
            atol: 1e-14,
        };
        let simulation = Simulation::new(dynamics, method, Options::default())
            .and_then(|s| s.with_contacts(vec![wall]))
            .expect("simulation");
        let t_end = get("t_end");
        let run = simulation.run(&list("q0"), &[0.0, 0.0], t_end, t_end).expect("run");
        let expected = c["impacts"].as_array().expect("impacts");
        assert_eq!(run.impacts.len(), expected.len(), "case {case}");
        let (err_t, err_q) = (get("err_t"), get("err_q"));
        for (k, (ours, theirs)) in run.impacts.iter().zip(expected).enumerate() {
            let at = format!("case {case} impact {k}");
            let t = theirs["t"].as_f64().expect("t");
            let lost = theirs["energy_lost"].as_f64().expect("lost");
            let speed = theirs["approach_speed"].as_f64().expect("speed");
            assert!((ours.t - t).abs() <= 1e-8 + 10.0 * err_t, "{at}: t {} vs {t}", ours.t);
            assert!(
                (ours.approach_speed - speed).abs() <= 1e-6 * speed + 10.0 * err_q,
                "{at}: speed {} vs {speed}",
                ours.approach_speed
            );
            assert!(
                (ours.energy_lost() - lost).abs() <= 1e-6 * lost.abs().max(1e-3) + 10.0 * err_q,
                "{at}: lost {} vs {lost}",
                ours.energy_lost()
            );
        }
        let last = run.samples.last().expect("samples");
        let estimate = last.error.expect("estimate");
        let (q_ref, v_ref) = (list("q_end"), list("q_dot_end"));
        let q_gap = common::distance(&last.q, &q_ref);
        let v_gap = common::distance(&last.q_dot, &v_ref);
        assert!(
            q_gap <= estimate.q + err_q,
            "case {case}: q off by {q_gap:e}, estimate {:e}, reference {err_q:e}",
            estimate.q
        );
        assert!(
            v_gap <= estimate.q_dot + err_q,
            "case {case}: q̇ off by {v_gap:e}, estimate {:e}, reference {err_q:e}",
            estimate.q_dot
        );
    }
}
