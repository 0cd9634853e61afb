//! Monitors and structure: bounded energy drift of Störmer–Verlet over 1e5 steps, the
//! implicit midpoint rule on a stiff spring, energy across re-centred spherical charts, the
//! Jacobi integral in a rotating frame, and the momentum of a cyclic coordinate.

mod common;

use common::{Rng, oscillator, pendulum};
use mechanica_dynamics::Dynamics;
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, RotatingFrame};
use mechanica_motion::{Invariant, Method, Options, Simulation};
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, Vector3};

fn quiet() -> Options {
    Options {
        estimate_error: false,
        ..Options::default()
    }
}

/// A double pendulum (A depends on q) with links of length 1 about x, gravity −z.
fn double_pendulum() -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let below = Isometry3::from_parts(Translation3::new(0.0, 0.0, -1.0), Default::default());
    builder.add_body(Some(0), Joint::Revolute { axis: Vector3::x() }, below);
    let tree = builder.build().expect("tree");
    let bob = MassProperties::new(1.0, Vector3::new(0.0, 0.0, -1.0), Matrix3::identity() * 0.01).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![bob, bob]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

/// 1e5 Störmer–Verlet steps on the double pendulum: the energy error stays of order h² and
/// does not grow: the second half of the run drifts no more than the first half allows.
#[test]
fn stormer_verlet_energy_drift_is_bounded() {
    let h = 0.01;
    let simulation =
        Simulation::new(double_pendulum(), Method::StormerVerlet { step: h }, quiet()).expect("simulation");
    let run = simulation.run(&[1.0, -0.5], &[0.0, 0.0], 1e5 * h, 10.0).expect("run");
    assert!(run.steps >= 100_000, "{} steps", run.steps);
    let e0 = run.monitors.initial;
    let scale = run.monitors.scale;
    let drift =
        |samples: &[mechanica_motion::Sample]| samples.iter().fold(0.0f64, |m, s| m.max((s.energy - e0).abs())) / scale;
    let half = run.samples.len() / 2;
    let (first, second) = (drift(&run.samples[..half]), drift(&run.samples[half..]));
    assert!(run.monitors.max_drift <= 0.05, "max drift {:e}", run.monitors.max_drift);
    assert!(second <= 2.0 * first, "drift grows: {first:e} then {second:e}");
    assert!(first > 0.0);
}

/// Implicit midpoint conserves the quadratic energy of a linear spring to rounding level at
/// ωh = 10, where RK4 blows up and stops with a typed error carrying the last good state.
#[test]
fn implicit_midpoint_handles_a_stiff_spring() {
    let mut rng = Rng::new(7);
    for _ in 0..5 {
        let (m, k) = (rng.decades(-1.0, 1.0), rng.decades(6.0, 9.0));
        let h = 10.0 / (k / m).sqrt();
        let run = Simulation::new(oscillator(m, k, 0.0), Method::ImplicitMidpoint { step: h }, quiet())
            .expect("simulation")
            .run(&[1e-3], &[0.0], 1000.0 * h, 100.0 * h)
            .expect("run");
        assert!(run.monitors.max_drift <= 1e-12, "drift {:e}", run.monitors.max_drift);
        let failed = Simulation::new(oscillator(m, k, 0.0), Method::Rk4 { step: h }, quiet())
            .expect("simulation")
            .run(&[1e-3], &[0.0], 1000.0 * h, 100.0 * h);
        match failed {
            Err(mechanica_motion::MotionError::StepFailed { t, q, q_dot, .. }) => {
                assert!(t > 0.0 && t < 1000.0 * h);
                assert!(q.iter().chain(&q_dot).all(|x| x.is_finite()));
            }
            other => panic!("RK4 at ωh = 10 should fail, got {other:?}"),
        }
    }
}

/// A heavy top on a spherical joint turning several times: its charts are re-centred before
/// every step, and with the rates mapped by J_r(φ) the energy is conserved to the tolerance.
/// Reported rotation vectors stay within |φ| ≤ π.
#[test]
fn spherical_charts_keep_the_energy() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Spherical, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let inertia = Matrix3::from_diagonal(&Vector3::new(0.3, 0.4, 0.2));
    let top = MassProperties::new(2.0, Vector3::new(0.0, 0.0, 0.5), inertia).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![top]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    let dynamics = Dynamics::new(mechanism).expect("dynamics");
    let method = Method::DormandPrince {
        rtol: 1e-11,
        atol: 1e-12,
    };
    let run = Simulation::new(dynamics, method, Options::default())
        .expect("simulation")
        .run(&[0.2, 0.0, 0.0], &[0.5, 1.0, 12.0], 5.0, 0.05)
        .expect("run");
    assert!(run.monitors.max_drift <= 1e-8, "drift {:e}", run.monitors.max_drift);
    for s in &run.samples {
        let phi = Vector3::new(s.q[0], s.q[1], s.q[2]).norm();
        assert!(phi <= std::f64::consts::PI + 1e-12, "|φ| = {phi}");
    }
}

/// A pendulum in a frame turning about the vertical conserves the Jacobi integral (M.2).
#[test]
fn jacobi_integral_in_a_rotating_frame() {
    let dynamics = pendulum(1.5, 0.8, 9.81);
    let mut mechanism = dynamics.mechanism().clone();
    let frame = RotatingFrame {
        axis: Unit::new_normalize(Vector3::z()),
        rate: 2.5,
    };
    mechanism.set_rotating_frame(Some(frame)).expect("frame");
    let dynamics = Dynamics::new(mechanism).expect("dynamics");
    let method = Method::DormandPrince {
        rtol: 1e-11,
        atol: 1e-13,
    };
    let run = Simulation::new(dynamics, method, quiet())
        .expect("simulation")
        .run(&[1.0], &[0.5], 10.0, 0.1)
        .expect("run");
    assert_eq!(run.monitors.invariant, Invariant::JacobiIntegral);
    assert!(run.monitors.max_drift <= 1e-8, "drift {:e}", run.monitors.max_drift);
}

/// A pendulum hung from a turntable about the vertical (gravity along the axis): the
/// turntable angle is cyclic and its momentum is conserved.
#[test]
fn cyclic_momentum_is_conserved() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    let arm = Isometry3::from_parts(Translation3::new(0.3, 0.0, 0.0), Default::default());
    builder.add_body(Some(0), Joint::Revolute { axis: Vector3::y() }, arm);
    let tree = builder.build().expect("tree");
    let table = MassProperties::new(1.0, Vector3::zeros(), Matrix3::identity() * 0.05).expect("mass");
    let bob = MassProperties::point(0.7, Vector3::new(0.0, 0.0, -0.6)).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![table, bob]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    let dynamics = Dynamics::new(mechanism).expect("dynamics");
    let options = Options {
        cyclic: vec![0],
        ..quiet()
    };
    let method = Method::DormandPrince {
        rtol: 1e-11,
        atol: 1e-13,
    };
    let run = Simulation::new(dynamics, method, options)
        .expect("simulation")
        .run(&[0.0, 0.7], &[2.0, 0.0], 5.0, 0.1)
        .expect("run");
    let p = &run.monitors.cyclic[0];
    assert!(p.initial.abs() > 0.1);
    assert!(
        p.max_drift <= 1e-8 * p.initial.abs(),
        "momentum drift {:e}",
        p.max_drift
    );
}
