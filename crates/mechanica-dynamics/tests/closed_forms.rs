//! Closed forms: the pendulum in a steadily rotating frame, the charge in uniform fields
//! (Lorentz force, cyclotron motion), the damped oscillator, and the pendulum's pivot reaction.
//! Each family draws its parameters at random over many decades.

mod common;

use common::Rng;
use mechanica_dynamics::{
    ChargedPoint, Damper, Dynamics, ElectromagneticField, FieldPotentials, Frame, State, UniformFields,
};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::{ConstantForce, JointSpring};
use mechanica_mechanism::{Anchor, Mechanism, RotatingFrame};
use nalgebra::{Isometry3, Matrix3, Unit, Vector3};
use proptest::prelude::*;
use std::sync::Arc;

fn close(a: f64, b: f64, relative: f64, scale: f64) -> bool {
    (a - b).abs() <= relative * (a.abs().max(b.abs()) + scale)
}

/// A point mass m at distance l below a revolute joint about x.
fn pendulum(m: f64, l: f64) -> Mechanism {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("mass");
    Mechanism::new(tree, vec![body]).expect("mechanism")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// In a frame turning at Ω about the vertical, θ̈ = sin θ (Ω² cos θ − g/l) (§8e), whatever
    /// θ̇: the Coriolis force is normal to the pendulum's plane.
    #[test]
    fn pendulum_in_a_rotating_frame(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let (m, l) = (10f64.powf(rng.uniform(-3.0, 3.0)), 10f64.powf(rng.uniform(-2.0, 2.0)));
        let (g, omega) = (rng.uniform(0.0, 20.0), rng.uniform(-10.0, 10.0));
        let (theta, theta_dot) = (rng.uniform(-3.1, 3.1), rng.uniform(-5.0, 5.0));
        let mut mechanism = pendulum(m, l);
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
        mechanism
            .set_rotating_frame(Some(RotatingFrame { axis: Unit::new_normalize(Vector3::z()), rate: omega }))
            .expect("frame");
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let (q, q_dot) = ([theta], [theta_dot]);
        let state = State::new(&q, &q_dot);
        let result = dynamics.forward_dynamics(&state, &[0.0]).expect("forward");
        let expected = theta.sin() * (omega * omega * theta.cos() - g / l);
        // The centrifugal term l θ̇² lies along the rod: its torque vanishes exactly, but its
        // rounding does not, so θ̇² belongs to the scale of θ̈'s rounding.
        let scale = omega * omega + g / l + theta_dot * theta_dot;
        prop_assert!(close(result.q_ddot[0], expected, 1e-13, scale), "θ̈ = {} against {expected}", result.q_ddot[0]);
    }

    /// The pivot's reaction on the bob is m (ẍ_C − g), with ẍ_C from θ, θ̇ and θ̈ = −(g/l) sin θ
    /// + τ/(m l²); the joint frame's components follow by R_WJ = I.
    #[test]
    fn pendulum_pivot_reaction(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let (m, l, g) = (10f64.powf(rng.uniform(-3.0, 3.0)), 10f64.powf(rng.uniform(-2.0, 2.0)), rng.uniform(0.0, 20.0));
        let (theta, theta_dot, tau) = (rng.uniform(-3.1, 3.1), rng.uniform(-5.0, 5.0), rng.uniform(-1.0, 1.0) * m * g * l);
        let mut mechanism = pendulum(m, l);
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let (q, q_dot) = ([theta], [theta_dot]);
        let state = State::new(&q, &q_dot);
        let theta_ddot = -(g / l) * theta.sin() + tau / (m * l * l);
        let forward = dynamics.forward_dynamics(&state, &[tau]).expect("forward");
        // θ̈'s rounding scales with every term of the recursion, the centrifugal θ̇² among them.
        let scale_ddot = g / l + tau.abs() / (m * l * l) + theta_dot * theta_dot;
        prop_assert!(close(forward.q_ddot[0], theta_ddot, 1e-13, scale_ddot));
        let inverse = dynamics.inverse_dynamics(&state, &[theta_ddot]).expect("inverse");
        prop_assert!(close(inverse.tau[0], tau, 1e-12, m * l * l * scale_ddot));
        // x_C = (0, l sin θ, −l cos θ).
        let (s, c) = theta.sin_cos();
        let a_c = Vector3::new(0.0, l * (theta_ddot * c - theta_dot * theta_dot * s), l * (theta_ddot * s + theta_dot * theta_dot * c));
        let expected = (a_c - Vector3::new(0.0, 0.0, -g)) * m;
        let reaction = inverse.reactions[0].expressed_in(&dynamics, Frame::Joint).expect("reaction");
        let scale = m * (g + l * (theta_ddot.abs() + theta_dot * theta_dot));
        prop_assert!((reaction.force - expected).norm() <= 1e-13 * scale, "F = {} against {expected}", reaction.force);
        // About the pivot the bob's moment is carried by τ alone: M = τ along x, zero across.
        prop_assert!((reaction.moment - Vector3::new(tau, 0.0, 0.0)).norm() <= 1e-12 * scale * l);
        // In the body frame the force is the same vector turned by R_WB⁻¹.
        let in_body = inverse.reactions[0].expressed_in(&dynamics, Frame::Body).expect("reaction");
        let r = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), theta);
        prop_assert!((r * in_body.force - expected).norm() <= 1e-13 * scale);
    }
}

/// Three prismatic joints along x, y, z carrying a point mass m at the last body.
fn particle(m: f64) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let b0 = builder.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
    let b1 = builder.add_body(Some(b0), Joint::Prismatic { axis: Vector3::y() }, Isometry3::identity());
    builder.add_body(Some(b1), Joint::Prismatic { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let massless = MassProperties {
        mass: 0.0,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::zeros(),
    };
    let bob = MassProperties::point(m, Vector3::zeros()).expect("mass");
    Mechanism::new(tree, vec![massless, massless, bob]).expect("mechanism")
}

/// Uniform fields in another gauge: φ' = φ − ∂χ/∂t, 𝐀' = 𝐀 + ∇χ with χ = ½ xᵀ S x + t c·x.
#[derive(Debug)]
struct Regauged {
    fields: UniformFields,
    s: Matrix3<f64>,
    c: Vector3<f64>,
}

impl ElectromagneticField for Regauged {
    fn potentials(&self, x: &Vector3<f64>, t: f64) -> FieldPotentials {
        let p = self.fields.potentials(x, t);
        FieldPotentials {
            phi: p.phi - self.c.dot(x),
            grad_phi: p.grad_phi - self.c,
            a: p.a + self.s * x + self.c * t,
            grad_a: p.grad_a + self.s,
            a_t: p.a_t + self.c,
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// q̈ = (e/m)(E + v × B) (the Lorentz force, FM 4.91) from the Lagrangian of FM 4.105 in
    /// two gauges; the magnetic part does no work, so q̇ᵀQ = e E·v.
    #[test]
    fn charge_in_uniform_fields(seed in any::<u64>(), regauge in any::<bool>()) {
        let mut rng = Rng::new(seed);
        let m = 10f64.powf(rng.uniform(-6.0, 3.0));
        let e = rng.uniform(-1.0, 1.0) * 10f64.powf(rng.uniform(-6.0, 0.0));
        let (e_size, b_size) = (10f64.powf(rng.uniform(-2.0, 3.0)), 10f64.powf(rng.uniform(-2.0, 1.0)));
        let (electric, magnetic) = (rng.vector(e_size), rng.vector(b_size));
        let fields = UniformFields { electric, magnetic };
        let s = Matrix3::from_fn(|i, j| ((i + 1) * (j + 1)) as f64 * rng.uniform(-1.0, 1.0));
        let field: Arc<dyn ElectromagneticField> = if regauge {
            Arc::new(Regauged { fields, s: s + s.transpose(), c: rng.vector(5.0) })
        } else {
            Arc::new(fields)
        };
        let mut dynamics = Dynamics::new(particle(m)).expect("dynamics");
        dynamics.add_velocity_potential(ChargedPoint { body: 2, point: Vector3::zeros(), charge: e, field }).expect("charge");
        let (x, v) = (rng.vector(3.0), rng.vector(100.0));
        let t = rng.uniform(0.0, 10.0);
        let state = State::new(x.as_slice(), v.as_slice()).at_time(t);
        let result = dynamics.forward_dynamics(&state, &[0.0; 3]).expect("forward");
        let lorentz = (electric + v.cross(&magnetic)) * (e / m);
        let scale = (electric.norm() + v.norm() * magnetic.norm()) * (e.abs() / m);
        for k in 0..3 {
            prop_assert!(close(result.q_ddot[k], lorentz[k], 1e-12, scale), "q̈{k} = {} against {}", result.q_ddot[k], lorentz[k]);
        }
        // The mass-matrix route sees the same time (the regauged field depends on t).
        let crba = dynamics.forward_dynamics_crba(&state, &[0.0; 3]).expect("crba");
        for k in 0..3 {
            prop_assert!(close(crba.q_ddot[k], lorentz[k], 1e-12, scale), "CRBA q̈{k} = {} against {}", crba.q_ddot[k], lorentz[k]);
        }
        let inverse = dynamics.inverse_dynamics(&state, &[0.0; 3]).expect("inverse");
        let power: f64 = (0..3).map(|k| inverse.loads[0].force[k] * v[k]).sum();
        prop_assert!(close(power, e * electric.dot(&v), 1e-12, e.abs() * electric.norm() * v.norm() + scale * m * v.norm()));
    }

    /// A prismatic mass with a joint spring and a damper: q̈ = −(k (q − q₀) + c q̇)/m, whether the
    /// damper sits on the joint or is a dashpot from the ground along the axis; the dampers'
    /// power is −2D.
    #[test]
    fn damped_oscillator(seed in any::<u64>(), dashpot in any::<bool>()) {
        let mut rng = Rng::new(seed);
        let m = 10f64.powf(rng.uniform(-4.0, 4.0));
        let (k, c) = (m * 10f64.powf(rng.uniform(-4.0, 8.0)), m * 10f64.powf(rng.uniform(-4.0, 4.0)));
        let rest = rng.uniform(-1.0, 1.0);
        let mut builder = TreeBuilder::new();
        builder.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
        let tree = builder.build().expect("tree");
        let mut mechanism = Mechanism::new(tree, vec![MassProperties::point(m, Vector3::zeros()).expect("mass")]).expect("mechanism");
        mechanism.add_potential(JointSpring { coordinate: 0, stiffness: k, rest }).expect("spring");
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let damper = if dashpot {
            Damper::Dashpot {
                a: Anchor { body: Some(0), point: Vector3::zeros() },
                b: Anchor { body: None, point: Vector3::new(-5.0, 0.0, 0.0) },
                coefficient: c,
            }
        } else {
            Damper::Joint { coordinate: 0, coefficient: c }
        };
        dynamics.add_damper(damper).expect("damper");
        let (q, q_dot) = (rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
        let (qs, q_dots) = ([q], [q_dot]);
        let state = State::new(&qs, &q_dots);
        let result = dynamics.forward_dynamics(&state, &[0.0]).expect("forward");
        let expected = -(k * (q - rest) + c * q_dot) / m;
        prop_assert!(close(result.q_ddot[0], expected, 1e-12, (k * (q - rest).abs() + c * q_dot.abs()) / m));
        prop_assert!(close(result.dissipation, 0.5 * c * q_dot * q_dot, 1e-14, 0.0));
        let inverse = dynamics.inverse_dynamics(&state, &[0.0]).expect("inverse");
        let damper_term = inverse.loads.iter().find(|l| l.kind == mechanica_dynamics::LoadKind::Damper).expect("damper term");
        prop_assert!(close(damper_term.force[0] * q_dot, -2.0 * inverse.dissipation, 1e-13, 0.0));
    }
}

/// A constant force at a body point reaches τ through the point's Jacobian, and the joint
/// reaction of a body carrying it balances it (statics: τ = −J_xᵀ F at rest without gravity).
#[test]
fn constant_force_at_rest_is_balanced_by_the_joints() {
    let mut rng = Rng::new(7);
    for _ in 0..50 {
        let bodies = 1 + rng.below(8);
        let mut mechanism = common::random_mechanism(&mut rng, bodies, 6.0, false);
        let body = rng.below(mechanism.tree().body_count());
        let (point, force) = (rng.vector(1.0), rng.vector(10.0));
        mechanism
            .add_potential(ConstantForce { body, point, force })
            .expect("force");
        let n = mechanism.dof();
        let (q, _, _) = common::random_state(&mut rng, &mechanism);
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let rest = vec![0.0; n];
        let state = State::new(&q, &rest);
        let tau = dynamics.inverse_dynamics(&state, &vec![0.0; n]).expect("inverse").tau;
        let mut jacobian = vec![0.0; 3 * n];
        let tree = dynamics.tree().clone();
        tree.point_jacobian(dynamics.workspace(), body, &point, &mut jacobian)
            .expect("jacobian");
        for k in 0..n {
            let q_k: f64 = (0..3).map(|r| jacobian[3 * k + r] * force[r]).sum();
            let scale = force.norm() * (0..3).map(|r| jacobian[3 * k + r].abs()).sum::<f64>();
            assert!(
                close(tau[k], -q_k, 1e-12, scale),
                "coordinate {k}: τ = {} against −J_kᵀF = {}",
                tau[k],
                -q_k
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A base accelerating upwards at a adds to gravity: θ̈ = −((g + a)/l) sin θ; and a base
    /// turning steadily (prescribed through the tree's `SteadyRotation`, at any t) gives the
    /// rotating frame's θ̈ = sin θ (Ω² cos θ − g/l).
    #[test]
    fn pendulum_on_a_prescribed_base(seed in any::<u64>()) {
        use mechanica_kinematics::tree::{BaseMotion, BaseState, SteadyRotation};
        #[derive(Debug)]
        struct Lift(f64);
        impl BaseMotion for Lift {
            fn state_at(&self, _t: f64) -> BaseState {
                BaseState { acceleration: Vector3::new(0.0, 0.0, self.0), ..BaseState::default() }
            }
        }
        let mut rng = Rng::new(seed);
        let (m, l, g) = (10f64.powf(rng.uniform(-3.0, 3.0)), 10f64.powf(rng.uniform(-2.0, 2.0)), rng.uniform(0.0, 20.0));
        let (a, omega, t) = (rng.uniform(-5.0, 30.0), rng.uniform(-10.0, 10.0), rng.uniform(-100.0, 100.0));
        let (q, q_dot) = ([rng.uniform(-3.1, 3.1)], [rng.uniform(-5.0, 5.0)]);
        let mut mechanism = pendulum(m, l);
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        dynamics.set_base_motion(Some(Arc::new(Lift(a)))).expect("lift");
        let lifted = dynamics.forward_dynamics(&State::new(&q, &q_dot), &[0.0]).expect("forward").q_ddot[0];
        let expected = -((g + a) / l) * q[0].sin();
        let centrifugal = q_dot[0] * q_dot[0];
        prop_assert!(close(lifted, expected, 1e-13, (g + a.abs()) / l + centrifugal), "θ̈ = {lifted} against {expected}");
        let spin = SteadyRotation { axis: Unit::new_normalize(Vector3::z()), rate: omega };
        dynamics.set_base_motion(Some(Arc::new(spin))).expect("spin");
        let spun = dynamics.forward_dynamics(&State::new(&q, &q_dot).at_time(t), &[0.0]).expect("forward").q_ddot[0];
        let expected = q[0].sin() * (omega * omega * q[0].cos() - g / l);
        prop_assert!(close(spun, expected, 1e-12, omega * omega + g / l + centrifugal), "θ̈ = {spun} against {expected}");
    }
}

