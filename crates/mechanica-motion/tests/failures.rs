//! Typed failures: refused options and sample counts, a singular mass matrix and a
//! non-finite applied force stop the run with the time reached and the last good state.

mod common;

use common::{oscillator, pendulum};
use mechanica_dynamics::Dynamics;
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_motion::{Forcing, Method, MotionError, Options, Simulation, StepFailure};
use nalgebra::{Isometry3, Vector3};
use std::sync::Arc;

#[test]
fn bad_tolerances_and_steps_are_refused() {
    for (rtol, atol) in [
        (0.0, 1e-9),
        (-1e-6, 1e-9),
        (f64::NAN, 1e-9),
        (f64::INFINITY, 1e-9),
        (1e-16, 1e-9),
        (1e-6, 0.0),
        (1e-6, -1.0),
    ] {
        let result = Simulation::new(
            pendulum(1.0, 1.0, 9.81),
            Method::DormandPrince { rtol, atol },
            Options::default(),
        );
        assert!(
            matches!(result, Err(MotionError::OutOfRange { .. })),
            "rtol {rtol}, atol {atol}"
        );
    }
    for step in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        for method in [
            Method::Rk4 { step },
            Method::StormerVerlet { step },
            Method::ImplicitMidpoint { step },
        ] {
            let result = Simulation::new(pendulum(1.0, 1.0, 9.81), method, Options::default());
            assert!(matches!(result, Err(MotionError::OutOfRange { .. })), "{method:?}");
        }
    }
}

#[test]
fn sample_counts_and_times_are_checked() {
    let simulation =
        Simulation::new(pendulum(1.0, 1.0, 9.81), Method::Rk4 { step: 0.01 }, Options::default()).expect("simulation");
    assert!(matches!(
        simulation.run(&[0.1], &[0.0], 1e9, 1e-3),
        Err(MotionError::TooManySamples { .. })
    ));
    assert!(matches!(
        simulation.run(&[0.1], &[0.0], -1.0, 0.1),
        Err(MotionError::OutOfRange { .. })
    ));
    assert!(matches!(
        simulation.run(&[0.1], &[0.0], 1.0, 0.0),
        Err(MotionError::OutOfRange { .. })
    ));
    assert!(matches!(
        simulation.run(&[f64::NAN], &[0.0], 1.0, 0.1),
        Err(MotionError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        simulation.run(&[0.1, 0.2], &[0.0], 1.0, 0.1),
        Err(MotionError::WrongLength { .. })
    ));
    let mut stepper = simulation.start(&[0.1], &[0.0]).expect("stepper");
    stepper.advance(0.5).expect("advance");
    assert!(matches!(stepper.advance(0.2), Err(MotionError::OutOfRange { .. })));
}

/// A point mass on the axis of its revolute joint has no inertia about it: A = 0.
#[test]
fn singular_mass_matrix_stops_at_the_start() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(1.0, Vector3::new(0.5, 0.0, 0.0)).expect("mass");
    let dynamics = Dynamics::new(Mechanism::new(tree, vec![body]).expect("mechanism")).expect("dynamics");
    for method in [
        Method::Rk4 { step: 0.01 },
        Method::StormerVerlet { step: 0.01 },
        Method::DormandPrince { rtol: 1e-6, atol: 1e-9 },
    ] {
        let result = Simulation::new(dynamics.clone(), method, Options::default())
            .expect("simulation")
            .run(&[0.0], &[1.0], 1.0, 0.1);
        match result {
            Err(MotionError::StepFailed { t, q, q_dot, .. }) => {
                assert_eq!(t, 0.0);
                assert_eq!((q, q_dot), (vec![0.0], vec![1.0]));
            }
            other => panic!("{method:?}: expected a failed step, got {other:?}"),
        }
    }
}

/// A force callback that returns NaN after t = 0.3 stops the run near there, with a finite
/// last good state before it.
#[test]
fn non_finite_force_stops_the_run() {
    let force: Arc<mechanica_motion::ForceFunction> =
        Arc::new(|t, _q, _v, out| out[0] = if t > 0.3 { f64::NAN } else { 1.0 });
    let options = Options {
        forcing: Forcing::Function(force),
        ..Options::default()
    };
    let simulation =
        Simulation::new(oscillator(1.0, 1.0, 0.0), Method::Rk4 { step: 0.01 }, options).expect("simulation");
    match simulation.run(&[0.0], &[0.0], 1.0, 0.1) {
        Err(MotionError::StepFailed { t, q, q_dot, cause }) => {
            assert!((0.28..=0.31).contains(&t), "t = {t}");
            assert!(q[0].is_finite() && q_dot[0].is_finite() && q[0] > 0.0);
            assert!(matches!(cause, StepFailure::NonFiniteForce { .. }));
        }
        other => panic!("expected a failed step, got {other:?}"),
    }
}

/// A step limit set on a stepper bounds every advance: RK4 with step h reaches k·h in exactly
/// k steps, so a limit L admits L·h and refuses (L + j)·h with TooManySteps after L steps,
/// leaving the last sample in place; a limit raised later lets the run go on. With the
/// companion run, a target of 1e300 s fails after at most L steps of each run.
#[test]
fn a_step_limit_bounds_each_advance() {
    let mut rng = common::Rng::new(0x5eed_0057);
    for _ in 0..20 {
        let h = rng.decades(-4.0, -1.0);
        let limit = 1 + rng.below(200);
        let extra = 1 + rng.below(50);
        let options = Options {
            estimate_error: false,
            ..Options::default()
        };
        let simulation =
            Simulation::new(oscillator(1.0, 4.0, 0.1), Method::Rk4 { step: h }, options).expect("simulation");
        let mut stepper = simulation.start(&[0.3], &[0.0]).expect("stepper");
        stepper.set_max_steps(limit);
        let target = (limit + extra) as f64 * h;
        match stepper.advance(target) {
            Err(MotionError::StepFailed {
                cause: StepFailure::TooManySteps { limit: reported },
                ..
            }) => assert_eq!(reported, limit),
            other => panic!("h {h:e}, limit {limit}: expected TooManySteps, got {other:?}"),
        }
        assert_eq!(stepper.steps(), limit);
        assert_eq!(stepper.sample().t, 0.0);
        stepper.set_max_steps(limit + extra);
        let reached = stepper.advance(target).expect("advance within the raised limit").t;
        assert_eq!(reached, target);
        assert_eq!(stepper.steps(), limit + extra);
    }
    let simulation = Simulation::new(
        pendulum(1.0, 1.0, 9.81),
        Method::DormandPrince {
            rtol: 1e-10,
            atol: 1e-12,
        },
        Options::default(),
    )
    .expect("simulation");
    let mut stepper = simulation.start(&[0.5], &[0.0]).expect("stepper");
    stepper.set_max_steps(64);
    assert!(matches!(
        stepper.advance(1e300),
        Err(MotionError::StepFailed {
            cause: StepFailure::TooManySteps { limit: 64 },
            ..
        })
    ));
    assert!(stepper.steps() <= 64);
}

/// A force that is NaN after t = 0 makes Dormand–Prince's first-step estimate fail: the
/// advance reports the force, and so does a second advance from the same stepper (the estimate
/// keeps its working storage through the failure).
#[test]
fn a_failed_first_step_estimate_can_be_retried() {
    let force: Arc<mechanica_motion::ForceFunction> =
        Arc::new(|t, _q, _v, out| out[0] = if t > 0.0 { f64::NAN } else { 1.0 });
    let options = Options {
        forcing: Forcing::Function(force),
        ..Options::default()
    };
    let method = Method::DormandPrince {
        rtol: 1e-8,
        atol: 1e-10,
    };
    let simulation = Simulation::new(oscillator(1.0, 1.0, 0.0), method, options).expect("simulation");
    let mut stepper = simulation.start(&[0.1], &[0.0]).expect("stepper");
    for attempt in 0..3 {
        match stepper.advance(1.0) {
            Err(MotionError::StepFailed {
                t,
                cause: StepFailure::NonFiniteForce { .. },
                ..
            }) => assert_eq!(t, 0.0, "attempt {attempt}"),
            other => panic!("attempt {attempt}: expected a non-finite force, got {other:?}"),
        }
    }
}

/// A mechanism without coordinates (one body on a fixed joint) integrates to any time with
/// every method: there is nothing to move.
#[test]
fn a_mechanism_without_coordinates_integrates() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Fixed, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(2.0, Vector3::new(0.3, 0.0, 0.0)).expect("mass");
    let dynamics = Dynamics::new(Mechanism::new(tree, vec![body]).expect("mechanism")).expect("dynamics");
    for method in [
        Method::Rk4 { step: 0.01 },
        Method::StormerVerlet { step: 0.01 },
        Method::ImplicitMidpoint { step: 0.01 },
        Method::DormandPrince {
            rtol: 1e-8,
            atol: 1e-10,
        },
    ] {
        let simulation = Simulation::new(dynamics.clone(), method, Options::default()).expect("simulation");
        let mut stepper = simulation.start(&[], &[]).expect("stepper");
        let sample = stepper.advance(0.5).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        assert_eq!(
            (sample.t, sample.q.len(), sample.q_dot.len()),
            (0.5, 0, 0),
            "{method:?}"
        );
    }
}
