//! The momentum monitors (M.15)–(M.16): P and L of a planar double pendulum against the sums
//! written out by hand; a free-floating chain without gravity conserving P and L to the
//! integrator's accuracy (random chains and states); the same chain under gravity, where the
//! monitor reports the momentum gained along gravity (m g t) while L along gravity stays
//! conserved; the cyclic momentum of a turntable equal to L along its axis.

mod common;

use common::Rng;
use mechanica_dynamics::Dynamics;
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_motion::{Method, Options, Simulation, system_momentum};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

fn quiet() -> Options {
    Options {
        estimate_error: false,
        ..Options::default()
    }
}

/// Two point masses m₁, m₂ on links l₁, l₂ about the x axis, hanging along −z at q = 0.
fn planar_double_pendulum(m: [f64; 2], l: [f64; 2]) -> Mechanism {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let below = Isometry3::from_parts(Translation3::new(0.0, 0.0, -l[0]), Default::default());
    builder.add_body(Some(0), Joint::Revolute { axis: Vector3::x() }, below);
    let tree = builder.build().expect("tree");
    let bobs = [0, 1].map(|i| MassProperties::point(m[i], Vector3::new(0.0, 0.0, -l[i])).expect("mass"));
    Mechanism::new(tree, bobs.to_vec()).expect("mechanism")
}

/// P and L of the planar double pendulum from the bob positions written out: bob 1 at
/// l₁(0, sin θ₁, −cos θ₁), bob 2 at that plus l₂(0, sin θ₁₂, −cos θ₁₂) with θ₁₂ = θ₁ + θ₂
/// (rotation about x turns −z towards +y).
#[test]
fn momenta_of_a_planar_double_pendulum_match_the_sums() {
    let mut rng = Rng::new(41);
    for _ in 0..50 {
        let m = [rng.uniform(0.1, 5.0), rng.uniform(0.1, 5.0)];
        let l = [rng.uniform(0.2, 2.0), rng.uniform(0.2, 2.0)];
        let q = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)];
        let v = [rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0)];
        let mechanism = planar_double_pendulum(m, l);
        let got = system_momentum(&mechanism, &q, &v).expect("momentum");
        let (a, b) = (q[0], q[0] + q[1]);
        let x1 = Vector3::new(0.0, l[0] * a.sin(), -l[0] * a.cos());
        let v1 = Vector3::new(0.0, l[0] * a.cos(), l[0] * a.sin()) * v[0];
        let x2 = x1 + Vector3::new(0.0, l[1] * b.sin(), -l[1] * b.cos());
        let v2 = v1 + Vector3::new(0.0, l[1] * b.cos(), l[1] * b.sin()) * (v[0] + v[1]);
        let linear = v1 * m[0] + v2 * m[1];
        let angular = x1.cross(&v1) * m[0] + x2.cross(&v2) * m[1];
        let scale = linear.norm().max(angular.norm()).max(1.0);
        assert!(
            (got.linear - linear).norm() <= 1e-13 * scale,
            "P {} vs {}",
            got.linear,
            linear
        );
        assert!(
            (got.angular - angular).norm() <= 1e-13 * scale,
            "L {} vs {}",
            got.angular,
            angular
        );
    }
}

/// A free-floating chain: a free root body and `links` revolute links with random axes,
/// placements and masses; gravity as given.
fn floating_chain(rng: &mut Rng, links: usize, gravity: Vector3<f64>) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let mut bodies = vec![
        MassProperties::new(
            2.0,
            Vector3::zeros(),
            Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
        )
        .expect("base"),
    ];
    for i in 0..links {
        let turn = UnitQuaternion::from_scaled_axis(rng.unit() * rng.uniform(0.0, 1.0));
        let placement = Isometry3::from_parts(Translation3::from(rng.unit() * rng.uniform(0.2, 0.6)), turn);
        builder.add_body(Some(i), Joint::Revolute { axis: rng.unit() }, placement);
        let mass = rng.uniform(0.2, 3.0);
        let moment = mass * 0.02;
        let inertia = Matrix3::from_diagonal(&Vector3::new(moment, moment * rng.uniform(0.5, 1.0), moment * 0.5));
        bodies.push(MassProperties::new(mass, rng.unit() * 0.2, inertia).expect("body"));
    }
    let tree = builder.build().expect("tree");
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(gravity).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

fn random_state(rng: &mut Rng, dof: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..dof).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let v = (0..dof).map(|_| rng.uniform(-2.0, 2.0)).collect();
    (q, v)
}

/// Without gravity a free-floating chain has no external force: every component of P and L
/// is conserved, to the integrator's tolerance (Dormand–Prince at rtol = 1e-11).
#[test]
fn free_floating_chain_conserves_linear_and_angular_momentum() {
    let method = Method::DormandPrince {
        rtol: 1e-11,
        atol: 1e-12,
    };
    for seed in 0..4 {
        let mut rng = Rng::new(100 + seed);
        let links = 2 + rng.below(3);
        let dynamics = floating_chain(&mut rng, links, Vector3::zeros());
        let (q, v) = random_state(&mut rng, dynamics.dof());
        let run = Simulation::new(dynamics, method, quiet())
            .expect("simulation")
            .run(&q, &v, 3.0, 0.1)
            .expect("run");
        let m = &run.monitors;
        assert!(m.linear_momentum.scale > 0.1 && m.angular_momentum.scale > 0.1);
        for (what, drift) in [("P", &m.linear_momentum), ("L", &m.angular_momentum)] {
            let worst = drift.max_drift.max();
            assert!(
                worst <= 1e-8 * drift.scale,
                "seed {seed}: {what} drift {worst:e}, scale {}",
                drift.scale
            );
        }
    }
}

/// Under gravity g along −z the same chain gains momentum −m g t along z: the monitor must
/// report it (P_z(t_end) − P_z(0) = −m g t_end), while P_x, P_y and L_z, about which gravity
/// has no resultant or moment, stay conserved. This is the monitor failing when it should.
#[test]
fn momentum_along_gravity_is_reported_as_drift() {
    let g = 9.81;
    let t_end = 2.0;
    let method = Method::DormandPrince {
        rtol: 1e-11,
        atol: 1e-12,
    };
    for seed in 0..3 {
        let mut rng = Rng::new(200 + seed);
        let dynamics = floating_chain(&mut rng, 3, Vector3::new(0.0, 0.0, -g));
        let mass: f64 = dynamics.mechanism().bodies().iter().map(|b| b.mass).sum();
        let (q, v) = random_state(&mut rng, dynamics.dof());
        let run = Simulation::new(dynamics, method, quiet())
            .expect("simulation")
            .run(&q, &v, t_end, 0.1)
            .expect("run");
        let p = &run.monitors.linear_momentum;
        let gained = p.last.z - p.initial.z;
        let expected = -mass * g * t_end;
        assert!(
            (gained - expected).abs() <= 1e-8 * expected.abs(),
            "seed {seed}: ΔP_z {gained} vs {expected}"
        );
        assert!(p.max_drift.z >= 0.99 * expected.abs());
        let tolerance = 1e-8 * p.scale;
        assert!(
            p.max_drift.x <= tolerance && p.max_drift.y <= tolerance,
            "P_x, P_y drift {}",
            p.max_drift
        );
        let l = &run.monitors.angular_momentum;
        let along = l.drift_along(&Vector3::z());
        assert!(along <= 1e-8 * l.scale, "L_z drift {along:e}");
        assert!(
            l.max_drift.x.max(l.max_drift.y) > 1e-3 * l.scale,
            "gravity's moment about x, y"
        );
    }
}

/// A pendulum on a turntable about z with gravity along z: the turntable angle is cyclic,
/// its momentum ∂T/∂q̇₀ (9.3) is the angular momentum L_z of the whole mechanism, and both are
/// conserved.
#[test]
fn cyclic_momentum_is_the_angular_momentum_about_the_axis() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    let arm = Isometry3::from_parts(Translation3::new(0.3, 0.0, 0.0), Default::default());
    builder.add_body(Some(0), Joint::Revolute { axis: Vector3::y() }, arm);
    let tree = builder.build().expect("tree");
    let table = MassProperties::new(1.0, Vector3::zeros(), Matrix3::identity() * 0.05).expect("mass");
    let bob = MassProperties::new(0.7, Vector3::new(0.0, 0.1, -0.6), Matrix3::identity() * 0.01).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![table, bob]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    let dynamics = Dynamics::new(mechanism).expect("dynamics");
    let options = Options {
        cyclic: vec![0],
        ..quiet()
    };
    let method = Method::Rk4 { step: 1e-3 };
    let run = Simulation::new(dynamics, method, options)
        .expect("simulation")
        .run(&[0.0, 0.7], &[2.0, -1.0], 3.0, 0.1)
        .expect("run");
    let cyclic = &run.monitors.cyclic[0];
    let l = &run.monitors.angular_momentum;
    assert!((cyclic.initial - l.initial.z).abs() <= 1e-13 * l.scale);
    assert!((cyclic.last - l.last.z).abs() <= 1e-13 * l.scale);
    assert!(
        cyclic.max_drift <= 1e-7 * cyclic.initial.abs(),
        "p₀ drift {:e}",
        cyclic.max_drift
    );
    assert!(l.max_drift.z <= 1e-7 * l.scale, "L_z drift {:e}", l.max_drift.z);
}
