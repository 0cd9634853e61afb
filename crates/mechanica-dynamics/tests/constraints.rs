//! Constraints by multipliers against closed forms and independent recursions:
//! - a free body held by a rod to the ground moves like the point-mass pendulum (and the
//!   revolute pendulum) and the rod's tension is m (g cos θ + l θ̇²);
//! - a body point on a fixed plane under gravity: the normal force is −m g·n;
//! - random trees with a random point-on-plane and locked-coordinate constraint: the
//!   constraint accelerations from the kinematics vanish and τ − RNEA(q̈) is the reactions'
//!   generalized force, within the reported backward error;
//! - the constrained equilibrium of a hanging rod and of a locked pendulum;
//! - bad input gives typed errors.

mod common;

use common::{Rng, random_mechanism, random_state};
use mechanica_dynamics::{
    Baumgarte, ConstrainedDynamics, ConstrainedEquilibriumOptions, Constraint, Dynamics, DynamicsError,
    ProjectionOptions, State,
};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Anchor, Mechanism};
use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;

/// One body on a free joint with its centre at `p_b` (body coordinates).
fn free_body(rng: &mut Rng, m: f64, p_b: Vector3<f64>, gravity: Vector3<f64>) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Free, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let size = 10f64.powf(rng.uniform(-1.0, 0.5));
    let body = MassProperties::new(m, p_b, common::random_inertia(rng, m, size)).expect("body");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism.set_gravity(gravity).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

/// (q, q̇) of the free body with random orientation and spin whose point `p_b` is at `x` with
/// velocity `v`.
fn place(
    rng: &mut Rng,
    dynamics: &Dynamics,
    p_b: &Vector3<f64>,
    x: Vector3<f64>,
    v: Vector3<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let phi = rng.vector(1.0);
    let spin = rng.vector(2.0);
    let tree = dynamics.tree();
    let mut ws = tree.workspace();
    let mut q = vec![0.0, 0.0, 0.0, phi.x, phi.y, phi.z];
    let mut q_dot = vec![0.0, 0.0, 0.0, spin.x, spin.y, spin.z];
    tree.update_positions(&mut ws, &q).expect("positions");
    tree.update_velocities(&mut ws, &q_dot).expect("velocities");
    let (offset, spin_velocity) = (
        ws.point_position(0, p_b).expect("x"),
        ws.point_velocity(0, p_b).expect("v"),
    );
    for i in 0..3 {
        q[i] = x[i] - offset[i];
        q_dot[i] = v[i] - spin_velocity[i];
    }
    (q, q_dot)
}

/// A point mass m at distance l below a revolute joint about x.
fn revolute_pendulum(m: f64, l: f64, g: f64) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A free body whose centre hangs on a rod of length l from a ground point, in a vertical
    /// plane of random azimuth ψ, spinning at random: its centre moves like the pendulum,
    /// a_C = l θ̈ e_θ − l θ̇² e_r with θ̈ = −(g/l) sin θ (the revolute pendulum's q̈), it spins
    /// freely (J ω̇ + ω × J ω = 0), and the tension is m (g cos θ + l θ̇²).
    #[test]
    fn rod_pendulum_matches_the_closed_form(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let (m, l, g) = (10f64.powf(rng.uniform(-3.0, 3.0)), 10f64.powf(rng.uniform(-2.0, 2.0)), rng.uniform(1.0, 20.0));
        let (theta, theta_dot, psi) = (rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0) * (g / l).sqrt(), rng.uniform(-3.1, 3.1));
        let p_b = rng.vector(l);
        let pivot = rng.vector(10.0 * l);
        let dynamics = free_body(&mut rng, m, p_b, Vector3::new(0.0, 0.0, -g));
        let e_r = Vector3::new(theta.sin() * psi.cos(), theta.sin() * psi.sin(), -theta.cos());
        let e_theta = Vector3::new(theta.cos() * psi.cos(), theta.cos() * psi.sin(), theta.sin());
        let (q, q_dot) = place(&mut rng, &dynamics, &p_b, pivot + e_r * l, e_theta * (l * theta_dot));
        let inertia = dynamics.mechanism().bodies()[0].inertia_c;
        let mut constrained = ConstrainedDynamics::new(dynamics.clone());
        let rod = Constraint::Distance { a: Anchor { body: Some(0), point: p_b }, b: Anchor { body: None, point: pivot }, length: l };
        constrained.add_constraint("rod", rod).expect("rod");
        let result = constrained.forward_dynamics(&State::new(&q, &q_dot), &[0.0; 6]).expect("forward");

        let tree = dynamics.tree().clone();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");
        tree.update_accelerations(&mut ws, &result.q_ddot).expect("accelerations");
        let a_c = ws.point_acceleration(0, &p_b).expect("a_C");
        let theta_ddot = -(g / l) * theta.sin();
        let expected = e_theta * (l * theta_ddot) - e_r * (l * theta_dot * theta_dot);
        let (omega, omega_dot) = (ws.angular_velocity(0).expect("ω"), ws.angular_acceleration(0).expect("ω̇"));
        let acceleration_scale = g + l * theta_dot * theta_dot + omega.norm_squared() * p_b.norm();
        prop_assert!((a_c - expected).norm() <= 1e-11 * acceleration_scale, "a_C = {a_c} against {expected}");
        let revolute = revolute_pendulum(m, l, g).forward_dynamics(&State::new(&[theta], &[theta_dot]), &[0.0]).expect("revolute");
        prop_assert!((a_c.dot(&e_theta) / l - revolute.q_ddot[0]).abs() <= 1e-11 * acceleration_scale / l);
        let r = ws.rotation(0).expect("R");
        let j_world = r.matrix() * inertia * r.matrix().transpose();
        let euler = j_world * omega_dot + omega.cross(&(j_world * omega));
        // The moments about the centre are summed from forces m·a at the lever |p_b| as well.
        let moment_scale = j_world.norm() * (omega.norm_squared() + omega_dot.norm()) + m * (acceleration_scale + g) * p_b.norm();
        prop_assert!(euler.norm() <= 1e-11 * moment_scale, "J ω̇ + ω × J ω = {euler}");
        let tension = m * (g * theta.cos() + l * theta_dot * theta_dot);
        let force_scale = m * (g + l * theta_dot * theta_dot);
        prop_assert!((result.multipliers[0] - tension).abs() <= 1e-11 * force_scale, "λ = {} against T = {tension}", result.multipliers[0]);
        prop_assert!((result.reactions[0].force + e_r * tension).norm() <= 1e-11 * force_scale);
        prop_assert!(result.position_drift <= 1e-13 * (l + pivot.norm()));
    }

    /// A body point (its centre) on a fixed plane of random normal under gravity in a random
    /// direction: a_C = g − (g·n) n and the plane pushes with −m (g·n) n, so λ = m g·n.
    #[test]
    fn point_on_a_plane_feels_the_normal_force(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let m = 10f64.powf(rng.uniform(-3.0, 3.0));
        let gravity = rng.vector(20.0);
        let p_b = rng.vector(1.0);
        let normal = rng.unit();
        let x = rng.vector(5.0);
        let dynamics = free_body(&mut rng, m, p_b, gravity);
        let slide = rng.vector(3.0);
        let (q, q_dot) = place(&mut rng, &dynamics, &p_b, x, slide - normal * normal.dot(&slide));
        let mut constrained = ConstrainedDynamics::new(dynamics.clone());
        let plane = Constraint::PointOnPlane { point: Anchor { body: Some(0), point: p_b }, normal: normal * 3.0, offset: 3.0 * normal.dot(&x) };
        constrained.add_constraint("floor", plane).expect("plane");
        let result = constrained.forward_dynamics(&State::new(&q, &q_dot), &[0.0; 6]).expect("forward");
        let tree = dynamics.tree().clone();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");
        tree.update_accelerations(&mut ws, &result.q_ddot).expect("accelerations");
        let a_c = ws.point_acceleration(0, &p_b).expect("a_C");
        let omega = ws.angular_velocity(0).expect("ω");
        let scale = gravity.norm() + omega.norm_squared() * p_b.norm() + slide.norm_squared();
        prop_assert!((a_c - (gravity - normal * gravity.dot(&normal))).norm() <= 1e-11 * scale, "a_C = {a_c}");
        let normal_force = -m * gravity.dot(&normal);
        prop_assert!((result.reactions[0].force - normal * normal_force).norm() <= 1e-11 * m * scale);
        prop_assert!((result.multipliers[0] - m * gravity.dot(&normal)).abs() <= 1e-11 * m * scale);
        prop_assert!(result.position_drift <= 1e-13 * (x.norm() + p_b.norm()));
    }

    /// Random trees (every joint type, masses graded over six decades) with a random body point
    /// on a random plane and, when independent of it, a locked coordinate: the point's
    /// acceleration along n (kinematics at q̈) and q̈ of the locked coordinate vanish, and
    /// τ − RNEA(q̈) equals the generalized force of the reported reaction force (through the
    /// kinematics' point Jacobian) and lock, each within the reported backward error.
    #[test]
    fn random_trees_satisfy_the_multiplier_equations(seed in any::<u64>(), bodies in 1usize..10, chain in any::<bool>()) {
        let mut rng = Rng::new(seed);
        let mut mechanism = random_mechanism(&mut rng, bodies, 6.0, chain);
        mechanism.set_gravity(Vector3::new(0.3, -9.81, 1.2)).expect("gravity");
        let (q, q_dot, _) = random_state(&mut rng, &mechanism);
        let n = q.len();
        let tree = mechanism.tree().clone();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");
        let body = rng.below(bodies);
        let point = rng.vector(1.0);
        let normal = rng.unit();
        let mut jacobian = vec![0.0; 3 * n];
        tree.point_jacobian(&ws, body, &point, &mut jacobian).expect("J");
        let row: Vec<f64> = (0..n).map(|k| normal.dot(&Vector3::new(jacobian[3 * k], jacobian[3 * k + 1], jacobian[3 * k + 2]))).collect();
        let row_norm = row.iter().map(|x| x.abs()).sum::<f64>();
        prop_assume!(row_norm > 1e-3);
        let locked = rng.below(n.max(1));
        let others = row.iter().enumerate().filter(|(k, _)| *k != locked).map(|(_, x)| x.abs()).sum::<f64>();
        let lock = n > 1 && others > 1e-3 * row_norm;
        let x = ws.point_position(body, &point).expect("x");
        let mut constrained = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
        let offset = normal.dot(&x) + rng.uniform(-0.01, 0.01);
        constrained.add_constraint("plane", Constraint::PointOnPlane { point: Anchor { body: Some(body), point }, normal, offset }).expect("plane");
        if lock {
            constrained.add_constraint("lock", Constraint::Coordinate { index: locked, value: q[locked] }).expect("lock");
        }
        let tau: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let state = State::new(&q, &q_dot);
        let result = constrained.forward_dynamics(&state, &tau).expect("forward");
        prop_assert!(result.backward_error <= 64.0 * (n + 2) as f64 * f64::EPSILON, "η = {:e} (κ(A) = {:e}, κ(S) = {:e})",
            result.backward_error, result.mass_condition, result.schur_condition);

        tree.update_accelerations(&mut ws, &result.q_ddot).expect("accelerations");
        let a = ws.point_acceleration(body, &point).expect("a");
        let bias = tree.point_bias_acceleration(&ws, body, &point).expect("b");
        let q_ddot_norm = result.acceleration_scale;
        let terms = row_norm * q_ddot_norm + bias.norm();
        let factor = result.backward_error + 64.0 * (bodies as f64 + 4.0) * f64::EPSILON;
        prop_assert!(normal.dot(&a).abs() <= factor * terms, "n·a = {:e} against {:e}", normal.dot(&a), factor * terms);
        if lock {
            prop_assert!(result.q_ddot[locked].abs() <= factor * q_ddot_norm);
        }

        let dynamics = constrained.dynamics_mut();
        let rnea = dynamics.inverse_dynamics(&state, &result.q_ddot).expect("rnea");
        let bias_terms = dynamics.inverse_dynamics(&state, &vec![0.0; n]).expect("h");
        let a_matrix = dynamics.mass_matrix(&q).expect("A");
        let force = result.reactions[0].force;
        for k in 0..n {
            let column = Vector3::new(jacobian[3 * k], jacobian[3 * k + 1], jacobian[3 * k + 2]);
            let mut reaction = force.dot(&column);
            let mut size = (force.norm() * column.norm()) + (tau[k] - bias_terms.tau[k]).abs();
            if lock {
                reaction += result.reactions[1].generalized_force[k];
                size += result.reactions[1].generalized_force[k].abs();
            }
            size += (0..n).map(|l| a_matrix[(k, l)].abs()).sum::<f64>() * q_ddot_norm;
            let difference = tau[k] - rnea.tau[k] + reaction;
            let tolerance = rnea.error_estimate[k] + bias_terms.error_estimate[k] + factor * size;
            prop_assert!(difference.abs() <= tolerance, "coordinate {k}: τ − RNEA(q̈) + reaction = {difference:e} > {tolerance:e}");
        }
    }
}

/// J q̇ along the motion's direction at q + s q̇, from the public Jacobian.
fn constraint_velocity(constrained: &mut ConstrainedDynamics, q: &[f64], q_dot: &[f64], s: f64) -> Vec<f64> {
    let n = q.len();
    let shifted: Vec<f64> = q.iter().zip(q_dot).map(|(x, v)| x + s * v).collect();
    let j = constrained.constraint_jacobian(&shifted).expect("J");
    (0..j.len() / n.max(1))
        .map(|r| (0..n).map(|k| j[r * n + k] * q_dot[k]).sum())
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random trees with a rod to the ground, a coincidence of two body points along one or two
    /// random directions and, with Baumgarte gains, off the constraint manifold: J from central
    /// differences of f, and the constraint accelerations J q̈ = −J̇ q̇ − 2α J q̇ − β² f with J̇ q̇
    /// from central differences of J q̇ along q̇.
    #[test]
    fn jacobian_and_bias_match_central_differences(seed in any::<u64>(), bodies in 2usize..8, stabilised in any::<bool>()) {
        let mut rng = Rng::new(seed);
        let mut mechanism = random_mechanism(&mut rng, bodies, 3.0, false);
        mechanism.set_gravity(Vector3::new(0.0, -9.81, 0.0)).expect("gravity");
        let (q, q_dot, _) = random_state(&mut rng, &mechanism);
        let n = q.len();
        prop_assume!(n > 0);
        let mut constrained = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
        let anchor = |rng: &mut Rng| Anchor { body: Some(rng.below(bodies)), point: rng.vector(1.0) };
        let rod = Constraint::Distance { a: anchor(&mut rng), b: Anchor { body: None, point: rng.vector(2.0) }, length: rng.uniform(0.5, 2.0) };
        constrained.add_constraint("rod", rod).expect("rod");
        let directions = (0..1 + rng.below(2)).map(|_| rng.unit()).collect();
        let pair = Constraint::PointsCoincide { a: anchor(&mut rng), b: anchor(&mut rng), directions };
        constrained.add_constraint("pair", pair).expect("pair");
        let gains = Baumgarte { alpha: rng.uniform(0.0, 5.0), beta: rng.uniform(0.0, 5.0) };
        if stabilised {
            constrained.set_baumgarte(Some(gains)).expect("gains");
        }
        let m = constrained.equation_count();
        let j = constrained.constraint_jacobian(&q).expect("J");
        let h = 1e-6;
        for k in 0..n {
            let (mut plus, mut minus) = (q.clone(), q.clone());
            plus[k] += h;
            minus[k] -= h;
            let (fp, fm) = (constrained.constraint_values(&plus).expect("f+"), constrained.constraint_values(&minus).expect("f−"));
            for r in 0..m {
                let difference = (fp[r] - fm[r]) / (2.0 * h);
                prop_assert!((difference - j[r * n + k]).abs() <= 1e-6 * (1.0 + j[r * n + k].abs()), "∂f_{r}/∂q_{k}: {difference} against {}", j[r * n + k]);
            }
        }
        let tau = vec![0.0; n];
        let result = match constrained.forward_dynamics(&State::new(&q, &q_dot), &tau) {
            Ok(result) => result,
            Err(DynamicsError::RedundantConstraint { .. }) => return Err(TestCaseError::reject("dependent constraints drawn")),
            Err(other) => return Err(TestCaseError::fail(format!("{other}"))),
        };
        let velocity = constraint_velocity(&mut constrained, &q, &q_dot, 0.0);
        let (vp, vm) = (constraint_velocity(&mut constrained, &q, &q_dot, h), constraint_velocity(&mut constrained, &q, &q_dot, -h));
        let f = constrained.constraint_values(&q).expect("f");
        for r in 0..m {
            let j_dot_q_dot = (vp[r] - vm[r]) / (2.0 * h);
            let j_q_ddot: f64 = (0..n).map(|k| j[r * n + k] * result.q_ddot[k]).sum();
            let mut expected = -j_dot_q_dot;
            if stabilised {
                expected -= 2.0 * gains.alpha * velocity[r] + gains.beta * gains.beta * f[r];
            }
            let scale: f64 = 1.0 + (0..n).map(|k| (j[r * n + k] * result.q_ddot[k]).abs()).sum::<f64>() + j_dot_q_dot.abs();
            prop_assert!((j_q_ddot - expected).abs() <= 1e-6 * scale, "row {r}: J q̈ = {j_q_ddot} against {expected}");
        }
    }
}

/// A body hanging on a rod from a ground point settles with its centre straight below the
/// pivot, the rod's tension m g; a pendulum locked at θ₀ needs the torque m g l sin θ₀.
#[test]
fn equilibria_of_a_hanging_rod_and_a_locked_pendulum() {
    let mut rng = Rng::new(11);
    for _ in 0..16 {
        let (m, l, g) = (
            10f64.powf(rng.uniform(-2.0, 2.0)),
            10f64.powf(rng.uniform(-1.0, 1.0)),
            rng.uniform(1.0, 20.0),
        );
        let p_b = rng.vector(l);
        let pivot = rng.vector(3.0 * l);
        let dynamics = free_body(&mut rng, m, p_b, Vector3::new(0.0, 0.0, -g));
        let direction = (Vector3::new(0.0, 0.0, -1.0) + rng.vector(0.3)).normalize();
        let (q0, _) = place(&mut rng, &dynamics, &p_b, pivot + direction * l, Vector3::zeros());
        let mut constrained = ConstrainedDynamics::new(dynamics);
        let rod = Constraint::Distance {
            a: Anchor {
                body: Some(0),
                point: p_b,
            },
            b: Anchor {
                body: None,
                point: pivot,
            },
            length: l,
        };
        constrained.add_constraint("rod", rod).expect("rod");
        let result = constrained
            .equilibrium(&q0, &ConstrainedEquilibriumOptions::default())
            .expect("equilibrium");
        let tree = constrained.dynamics().tree().clone();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &result.q).expect("positions");
        let x = ws.point_position(0, &p_b).expect("x");
        assert!(
            (x - (pivot - Vector3::z() * l)).norm() <= 1e-10 * l,
            "centre at {x}, pivot {pivot}"
        );
        assert!(
            (result.multipliers[0] - m * g).abs() <= 1e-10 * m * g,
            "tension {}",
            result.multipliers[0]
        );
        assert!((result.reactions[0].force - Vector3::new(0.0, 0.0, m * g)).norm() <= 1e-10 * m * g);
        assert!(result.stationarity <= result.stationarity_tolerance);

        let theta0 = rng.uniform(-3.0, 3.0);
        let mut locked = ConstrainedDynamics::new(revolute_pendulum(m, l, g));
        locked
            .add_constraint(
                "lock",
                Constraint::Coordinate {
                    index: 0,
                    value: theta0,
                },
            )
            .expect("lock");
        let result = locked
            .equilibrium(&[theta0 + 0.1], &ConstrainedEquilibriumOptions::default())
            .expect("locked");
        assert!((result.q[0] - theta0).abs() <= 1e-14 * (1.0 + theta0.abs()));
        // U = −m g l cos θ: the lock's generalized force −λ balances −∂U/∂θ = −m g l sin θ₀.
        let torque = m * g * l * theta0.sin();
        assert!((result.reactions[0].generalized_force[0] - torque).abs() <= 1e-12 * m * g * l);
    }
}

/// Bad input: typed errors, never a panic.
#[test]
fn bad_input_gives_typed_errors() {
    let mut rng = Rng::new(3);
    let dynamics = free_body(&mut rng, 1.0, Vector3::zeros(), Vector3::new(0.0, 0.0, -9.81));
    let mut c = ConstrainedDynamics::new(dynamics);
    let ground = Anchor {
        body: None,
        point: Vector3::zeros(),
    };
    let body = Anchor {
        body: Some(0),
        point: Vector3::zeros(),
    };
    let add = |c: &mut ConstrainedDynamics, constraint| c.add_constraint("bad", constraint);
    assert!(matches!(
        add(&mut c, Constraint::Coordinate { index: 6, value: 0.0 }),
        Err(DynamicsError::NoSuchCoordinate { index: 6, .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::points_coincide(Anchor { body: Some(1), ..body }, ground)
        ),
        Err(DynamicsError::NoSuchBody { body: 1, .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointOnPlane {
                point: body,
                normal: Vector3::zeros(),
                offset: 0.0
            }
        ),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointOnPlane {
                point: body,
                normal: Vector3::new(f64::NAN, 0.0, 1.0),
                offset: 0.0
            }
        ),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointOnPlane {
                point: body,
                normal: Vector3::z(),
                offset: f64::INFINITY
            }
        ),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::Distance {
                a: body,
                b: ground,
                length: 0.0
            }
        ),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::Distance {
                a: Anchor {
                    point: Vector3::new(f64::NAN, 0.0, 0.0),
                    ..body
                },
                b: ground,
                length: 1.0
            }
        ),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointsCoincide {
                a: body,
                b: ground,
                directions: vec![]
            }
        ),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointsCoincide {
                a: body,
                b: ground,
                directions: vec![Vector3::x(); 4]
            }
        ),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        add(
            &mut c,
            Constraint::PointsCoincide {
                a: body,
                b: ground,
                directions: vec![Vector3::new(1e-300, 0.0, 0.0), Vector3::zeros()]
            }
        ),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert_eq!(c.constraints().len(), 0);
    assert!(matches!(
        c.set_baumgarte(Some(Baumgarte { alpha: -1.0, beta: 0.0 })),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        c.set_baumgarte(Some(Baumgarte {
            alpha: 1.0,
            beta: f64::NAN
        })),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        c.set_pivot_tolerance(1.5),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        c.set_pivot_tolerance(f64::NAN),
        Err(DynamicsError::OutOfRange { .. })
    ));

    // The same plane twice: the second equation is redundant.
    let plane = Constraint::PointOnPlane {
        point: body,
        normal: Vector3::z(),
        offset: 0.0,
    };
    c.add_constraint("floor", plane.clone()).expect("plane");
    c.add_constraint("floor again", plane).expect("plane");
    let (q, q_dot) = (vec![0.0; 6], vec![0.0; 6]);
    match c.forward_dynamics(&State::new(&q, &q_dot), &[0.0; 6]) {
        Err(DynamicsError::RedundantConstraint {
            constraint: 1, name, ..
        }) => assert!(name.contains("floor again"), "{name}"),
        other => panic!("expected a redundant constraint, got {other:?}"),
    }
    let mut c = ConstrainedDynamics::new(c.into_dynamics());
    c.add_constraint(
        "rod",
        Constraint::Distance {
            a: body,
            b: ground,
            length: 1.0,
        },
    )
    .expect("rod");
    // The rod's points coincide at q = 0: its direction is undefined.
    assert!(matches!(
        c.forward_dynamics(&State::new(&q, &q_dot), &[0.0; 6]),
        Err(DynamicsError::OutOfRange { .. })
    ));
    let q = vec![0.0, 0.0, -1.0, 0.0, 0.0, 0.0];
    assert!(matches!(
        c.forward_dynamics(&State::new(&q, &q_dot), &[0.0; 5]),
        Err(DynamicsError::WrongLength { what: "tau", .. })
    ));
    assert!(matches!(
        c.forward_dynamics(&State::new(&q[..5], &q_dot), &[0.0; 6]),
        Err(DynamicsError::WrongLength { .. })
    ));
    let nan_q = vec![0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0];
    assert!(matches!(
        c.forward_dynamics(&State::new(&nan_q, &q_dot), &[0.0; 6]),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        c.forward_dynamics(&State::new(&q, &q_dot), &[f64::INFINITY; 6]),
        Err(DynamicsError::NonFiniteInput { .. })
    ));
    assert!(matches!(
        c.project_velocities(&q, &q_dot[..2]),
        Err(DynamicsError::WrongLength { .. })
    ));
    let far = vec![0.0, 0.0, -3.0, 0.0, 0.0, 0.0];
    let none = ProjectionOptions {
        max_iterations: 0,
        ..Default::default()
    };
    assert!(matches!(
        c.project_positions(&far, &none),
        Err(DynamicsError::NotConverged { iterations: 0, .. })
    ));
    let negative = ProjectionOptions {
        tolerance: Some(-1.0),
        ..Default::default()
    };
    assert!(matches!(
        c.project_positions(&far, &negative),
        Err(DynamicsError::OutOfRange { .. })
    ));
    let projected = c
        .project_positions(&far, &ProjectionOptions::default())
        .expect("projection");
    assert!((projected.q[2] + 1.0).abs() <= 1e-15, "{:?}", projected.q);
    let bad_step = ConstrainedEquilibriumOptions {
        max_step: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        c.equilibrium(&far, &bad_step),
        Err(DynamicsError::OutOfRange { .. })
    ));
    assert!(matches!(
        c.equilibrium(&far[..3], &Default::default()),
        Err(DynamicsError::WrongLength { .. })
    ));
    assert_eq!(c.equation_range(0), Some(0..1));
    assert_eq!(c.equation_range(1), None);
    assert_eq!(c.constraint_name(0), Some("rod"));
}
