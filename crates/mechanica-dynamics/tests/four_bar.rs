//! The planar four-bar linkage closed by a pin, against a hand derivation: statics under
//! gravity (virtual work for the crank torque, moment balances for the pin force), dynamics
//! (constraint acceleration and power balance from the kinematics, pin force from the moment
//! balances with d'Alembert's inertial forces), projections and the constrained equilibrium.
//!
//! The linkage: ground pivots O = 0 and D = (d, 0, 0); crank OB (length a), coupler BC
//! (length b), rocker CD (length c), all in the xy-plane, modelled as the chain
//! crank → coupler → rocker of revolute joints about z (coordinates θ1, θ2, θ3 relative), the
//! rocker's end pinned to D along x and y. Absolute angles φ1 = θ1, φ2 = θ1 + θ2,
//! φ3 = φ2 + θ3; e(φ) = (cos φ, sin φ). Uniform bars: centre at the middle, I_z = m L²/12.
//!
//! **Velocity ratios.** The loop a e(φ1) + b e(φ2) + c e(φ3) = D gives
//! a φ̇1 e⊥(φ1) + b φ̇2 e⊥(φ2) + c φ̇3 e⊥(φ3) = 0 with e⊥(φ)·e(ψ) = sin(ψ − φ); dotting with
//! e(φ3) and e(φ2): k2 = φ̇2/φ̇1 = −a sin(φ3 − φ1)/(b sin(φ3 − φ2)),
//! k3 = φ̇3/φ̇1 = −a sin(φ2 − φ1)/(c sin(φ2 − φ3)).
//!
//! **Crank torque (virtual work).** With gravity (0, −g), the centre heights
//! y1 = (a/2) sin φ1, y2 = a sin φ1 + (b/2) sin φ2, y3 = a sin φ1 + b sin φ2 + (c/2) sin φ3 and
//! τ δφ1 = δV:  τ = −Σ m_i g·∂x_Ci/∂φ1 =
//! g [m1 (a/2) cos φ1 + m2 (a cos φ1 + (b/2) k2 cos φ2) + m3 (a cos φ1 + b k2 cos φ2 + (c/2) k3 cos φ3)].
//!
//! **Pin force.** F_D, the ground's force on the rocker at D. The rocker's moment balance
//! about C (the joint at C carries the torque τ3 onto the rocker):
//!   τ3 + (D − C) × F_D + (G3 − C) × m3 (g − a3) − I3 α3 = 0;
//! the rocker's force balance gives the coupler's force at C, F_D + m3 (g − a3), and the
//! coupler's moment balance about B (τ2 onto the coupler, −τ3 from the rocker's joint):
//!   τ2 − τ3 + (C − B) × (F_D + m3 (g − a3)) + (G2 − B) × m2 (g − a2) − I2 α2 = 0.
//! Two linear equations for F_D (statics: all accelerations zero). The crank's moment balance
//! about O, τ1 − τ2 + B × (F_D + (m2 + m3) g) + G1 × m1 g = 0 in statics, checks the
//! virtual-work torque against the same pin force.

mod common;

use common::Rng;
use mechanica_dynamics::{
    ConstrainedDynamics, ConstrainedEquilibriumOptions, Constraint, Dynamics, DynamicsError, ProjectionMetric,
    ProjectionOptions, State,
};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::GeneralizedForce;
use mechanica_mechanism::{Anchor, Mechanism};
use nalgebra::{Isometry3, Matrix3, Translation3, Vector2, Vector3};
use proptest::prelude::*;

/// A four-bar and one of its closed configurations.
struct FourBar {
    lengths: [f64; 3],
    d: f64,
    masses: [f64; 3],
    g: f64,
    /// Absolute angles φ1, φ2, φ3.
    phi: [f64; 3],
}

fn e(phi: f64) -> Vector2<f64> {
    Vector2::new(phi.cos(), phi.sin())
}

fn cross2(r: &Vector2<f64>, f: &Vector2<f64>) -> f64 {
    r.x * f.y - r.y * f.x
}

impl FourBar {
    /// Random lengths on a scale 10^U(−1, 1), random masses, and a closed configuration: C
    /// from the intersection of the circles |C − B| = b and |C − D| = c.
    fn random(rng: &mut Rng) -> Self {
        let scale = 10f64.powf(rng.uniform(-1.0, 1.0));
        loop {
            let lengths = [rng.uniform(0.3, 1.0), rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.5)].map(|l| l * scale);
            let d = rng.uniform(0.5, 1.5) * scale;
            let phi1 = rng.uniform(-3.1, 3.1);
            let b_point = e(phi1) * lengths[0];
            let to_d = Vector2::new(d, 0.0) - b_point;
            let s = to_d.norm();
            let [_, b, c] = lengths;
            // Stay away from the toggle positions (C, B, D aligned).
            if s <= (b - c).abs() + 0.1 * scale || s >= b + c - 0.1 * scale {
                continue;
            }
            let unit = to_d / s;
            let along = (b * b - c * c + s * s) / (2.0 * s);
            let height = (b * b - along * along).sqrt() * if rng.uniform(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
            let c_point = b_point + unit * along + Vector2::new(-unit.y, unit.x) * height;
            let phi2 = (c_point - b_point).y.atan2((c_point - b_point).x);
            let phi3 = (Vector2::new(d, 0.0) - c_point)
                .y
                .atan2((Vector2::new(d, 0.0) - c_point).x);
            let masses = [0, 1, 2].map(|_| 10f64.powf(rng.uniform(-2.0, 2.0)));
            return Self {
                lengths,
                d,
                masses,
                g: rng.uniform(1.0, 20.0),
                phi: [phi1, phi2, phi3],
            };
        }
    }

    fn q(&self) -> Vec<f64> {
        let [p1, p2, p3] = self.phi;
        vec![p1, p2 - p1, p3 - p2]
    }

    /// (k2, k3) = (dφ2/dφ1, dφ3/dφ1).
    fn ratios(&self) -> (f64, f64) {
        let [a, b, c] = self.lengths;
        let [p1, p2, p3] = self.phi;
        (
            -a * (p3 - p1).sin() / (b * (p3 - p2).sin()),
            -a * (p2 - p1).sin() / (c * (p2 - p3).sin()),
        )
    }

    /// q̇ on the constraint for the crank rate `rate`.
    fn q_dot(&self, rate: f64) -> Vec<f64> {
        let (k2, k3) = self.ratios();
        vec![rate, (k2 - 1.0) * rate, (k3 - k2) * rate]
    }

    fn inertia(&self, i: usize) -> f64 {
        self.masses[i] * self.lengths[i] * self.lengths[i] / 12.0
    }

    fn constrained(&self, directions: Vec<Vector3<f64>>) -> ConstrainedDynamics {
        let mut builder = TreeBuilder::new();
        let z = Joint::Revolute { axis: Vector3::z() };
        builder.add_body(None, z, Isometry3::identity());
        for i in 0..2 {
            let at = Isometry3::from_parts(Translation3::new(self.lengths[i], 0.0, 0.0), Default::default());
            builder.add_body(Some(i), z, at);
        }
        let tree = builder.build().expect("tree");
        let bodies = (0..3)
            .map(|i| {
                let (m, l) = (self.masses[i], self.lengths[i]);
                let tensor =
                    Matrix3::from_diagonal(&Vector3::new(1e-3 * m * l * l, m * l * l / 12.0, m * l * l / 12.0));
                MassProperties::new(m, Vector3::new(l / 2.0, 0.0, 0.0), tensor).expect("bar")
            })
            .collect();
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, -self.g, 0.0)).expect("gravity");
        let mut constrained = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
        let pin = Constraint::PointsCoincide {
            a: Anchor {
                body: Some(2),
                point: Vector3::new(self.lengths[2], 0.0, 0.0),
            },
            b: Anchor {
                body: None,
                point: Vector3::new(self.d, 0.0, 0.0),
            },
            directions,
        };
        constrained.add_constraint("pin at D", pin).expect("pin");
        constrained
    }

    fn pin_only_in_plane(&self) -> ConstrainedDynamics {
        self.constrained(vec![Vector3::x(), Vector3::y()])
    }

    /// The crank torque that holds the linkage at rest (virtual work, module docs).
    fn static_torque(&self) -> f64 {
        let [a, b, c] = self.lengths;
        let [m1, m2, m3] = self.masses;
        let [p1, p2, p3] = self.phi;
        let (k2, k3) = self.ratios();
        self.g
            * (m1 * a / 2.0 * p1.cos()
                + m2 * (a * p1.cos() + b / 2.0 * k2 * p2.cos())
                + m3 * (a * p1.cos() + b * k2 * p2.cos() + c / 2.0 * k3 * p3.cos()))
    }

    /// Joint points B, C, D and centres G1, G2, G3.
    fn points(&self) -> ([Vector2<f64>; 3], [Vector2<f64>; 3]) {
        let [a, b, c] = self.lengths;
        let [p1, p2, p3] = self.phi;
        let bp = e(p1) * a;
        let cp = bp + e(p2) * b;
        let dp = cp + e(p3) * c;
        (
            [bp, cp, dp],
            [e(p1) * (a / 2.0), bp + e(p2) * (b / 2.0), cp + e(p3) * (c / 2.0)],
        )
    }

    /// F_D from the rocker's and the coupler's moment balances (module docs), with the centre
    /// accelerations `acc` and angular accelerations `alpha` of the bars and torques τ2, τ3.
    fn pin_force(&self, acc: &[Vector2<f64>; 3], alpha: &[f64; 3], tau: &[f64]) -> Vector2<f64> {
        let ([bp, cp, dp], [_, g2, g3]) = self.points();
        let gravity = Vector2::new(0.0, -self.g);
        let [_, m2, m3] = self.masses;
        let rocker_load = (gravity - acc[2]) * m3;
        let coupler_load = (gravity - acc[1]) * m2;
        // Rocker: (D − C) × F = −τ3 − (G3 − C) × rocker_load + I3 α3.
        let (r1, k1) = (
            dp - cp,
            -tau[2] - cross2(&(g3 - cp), &rocker_load) + self.inertia(2) * alpha[2],
        );
        // Coupler: (C − B) × F = −(τ2 − τ3) − (C − B) × rocker_load − (G2 − B) × coupler_load + I2 α2.
        let r2 = cp - bp;
        let k2 = -(tau[1] - tau[2]) - cross2(&r2, &rocker_load) - cross2(&(g2 - bp), &coupler_load)
            + self.inertia(1) * alpha[1];
        // r × F = r.x F.y − r.y F.x.
        let det = (-r1.y) * r2.x - r1.x * (-r2.y);
        Vector2::new((k1 * r2.x - r1.x * k2) / det, ((-r1.y) * k2 - (-r2.y) * k1) / det)
    }

    fn force_scale(&self) -> f64 {
        self.masses.iter().sum::<f64>()
            * self.g
            * (1.0 + self.lengths[0] / self.lengths[1] + self.lengths[0] / self.lengths[2])
    }
}

fn close2(a: &Vector2<f64>, b: &Vector2<f64>, tolerance: f64) -> bool {
    (a - b).norm() <= tolerance
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// At rest with the virtual-work torque on the crank, q̈ = 0 and the pin force is the
    /// moment balances' one; the crank's moment balance agrees with the virtual-work torque.
    #[test]
    fn statics_match_the_hand_derivation(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let bar = FourBar::random(&mut rng);
        let tau = bar.static_torque();
        let zero = [Vector2::zeros(); 3];
        let pin = bar.pin_force(&zero, &[0.0; 3], &[tau, 0.0, 0.0]);
        // The hand derivation's own consistency: the crank's moment balance about O.
        let ([bp, ..], [g1, ..]) = bar.points();
        let gravity = Vector2::new(0.0, -bar.g);
        let crank = -cross2(&bp, &(pin + gravity * (bar.masses[1] + bar.masses[2]))) - cross2(&g1, &(gravity * bar.masses[0]));
        let torque_scale = bar.force_scale() * bar.lengths[0];
        prop_assert!((crank - tau).abs() <= 1e-10 * torque_scale, "moment balance {crank} against virtual work {tau}");

        let mut constrained = bar.pin_only_in_plane();
        let q = bar.q();
        let result = constrained.forward_dynamics(&State::new(&q, &[0.0; 3]), &[tau, 0.0, 0.0]).expect("forward");
        let rate_scale = bar.g / bar.lengths.iter().fold(f64::INFINITY, |m, l| m.min(*l));
        for x in &result.q_ddot {
            prop_assert!(x.abs() <= 1e-10 * rate_scale, "q̈ = {:?} at the static torque", result.q_ddot);
        }
        let reaction = &result.reactions[0];
        let force = Vector2::new(reaction.force.x, reaction.force.y);
        prop_assert!(close2(&force, &pin, 1e-10 * bar.force_scale()), "pin force {force} against {pin}");
        prop_assert!(reaction.force.z == 0.0);
        prop_assert!(result.position_drift <= 1e-13 * bar.d);
        // One step of refinement leaves the backward error at the rounding level of the
        // residual, a few (n + m)·u.
        prop_assert!(result.backward_error <= 64.0 * 5.0 * f64::EPSILON, "η = {:e}", result.backward_error);
    }

    /// In motion, with random torques: the pinned point's acceleration (kinematics at the
    /// computed q̈) vanishes, the applied power equals dT/dt + dV/dt from the bodies'
    /// velocities and accelerations, the reaction does no work, and the pin force satisfies
    /// the moment balances with the inertial forces.
    #[test]
    fn dynamics_keep_the_loop_closed_and_balance_power(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let bar = FourBar::random(&mut rng);
        let rate = rng.uniform(-3.0, 3.0) * (bar.g / bar.lengths[0]).sqrt();
        let torque_scale = bar.force_scale() * bar.lengths[0];
        let tau: Vec<f64> = (0..3).map(|_| rng.uniform(-1.0, 1.0) * torque_scale).collect();
        let mut constrained = bar.pin_only_in_plane();
        let (q, q_dot) = (bar.q(), bar.q_dot(rate));
        let result = constrained.forward_dynamics(&State::new(&q, &q_dot), &tau).expect("forward");
        prop_assert!(result.velocity_drift <= 1e-12 * rate.abs() * bar.d);

        let tree = constrained.dynamics().tree().clone();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");
        tree.update_accelerations(&mut ws, &result.q_ddot).expect("accelerations");
        let end = ws.point_acceleration(2, &Vector3::new(bar.lengths[2], 0.0, 0.0)).expect("end");
        let mut acceleration_scale = 0.0;
        let (mut kinetic_rate, mut potential_rate) = (0.0, 0.0);
        let mut acc = [Vector2::zeros(); 3];
        let mut alpha = [0.0; 3];
        for i in 0..3 {
            let centre = Vector3::new(bar.lengths[i] / 2.0, 0.0, 0.0);
            let (v, a) = (ws.point_velocity(i, &centre).expect("v"), ws.point_acceleration(i, &centre).expect("a"));
            let (w, wd) = (ws.angular_velocity(i).expect("ω").z, ws.angular_acceleration(i).expect("ω̇").z);
            kinetic_rate += bar.masses[i] * v.dot(&a) + bar.inertia(i) * w * wd;
            potential_rate += bar.masses[i] * bar.g * v.y;
            acceleration_scale += a.norm() + wd.abs() * bar.lengths[i] + w * w * bar.lengths[i];
            acc[i] = Vector2::new(a.x, a.y);
            alpha[i] = wd;
        }
        prop_assert!(end.x.abs().max(end.y.abs()) <= 1e-12 * acceleration_scale, "pinned point accelerates: {end}");
        let power: f64 = tau.iter().zip(&q_dot).map(|(t, v)| t * v).sum();
        let power_scale = torque_scale * rate.abs() * 10.0 + kinetic_rate.abs();
        prop_assert!((power - kinetic_rate - potential_rate).abs() <= 1e-11 * power_scale,
            "power {power} against dT/dt + dV/dt = {}", kinetic_rate + potential_rate);
        let reaction = &result.reactions[0];
        let reaction_power: f64 = reaction.generalized_force.iter().zip(&q_dot).map(|(f, v)| f * v).sum();
        prop_assert!(reaction_power.abs() <= 1e-12 * power_scale, "the reaction's power {reaction_power}");
        let pin = bar.pin_force(&acc, &alpha, &tau);
        let force = Vector2::new(reaction.force.x, reaction.force.y);
        let force_scale = bar.force_scale() + tau.iter().map(|t| t.abs()).sum::<f64>() / bar.lengths[2]
            + bar.masses.iter().sum::<f64>() * acceleration_scale;
        prop_assert!(close2(&force, &pin, 1e-10 * force_scale), "pin force {force} against {pin}");
    }

    /// Projections: a perturbed configuration comes back onto the loop in a few Gauss–Newton
    /// iterations in both metrics (the pinned point at D, from the kinematics); random
    /// velocities are projected A-orthogonally onto the loop's tangent.
    #[test]
    fn projections_restore_the_loop(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let bar = FourBar::random(&mut rng);
        let mut constrained = bar.pin_only_in_plane();
        let q0 = bar.q();
        for metric in [ProjectionMetric::MassMatrix, ProjectionMetric::Euclidean] {
            let perturbed: Vec<f64> = q0.iter().map(|x| x + rng.uniform(-0.01, 0.01)).collect();
            let options = ProjectionOptions { metric, ..Default::default() };
            let projected = constrained.project_positions(&perturbed, &options).expect("projection");
            prop_assert!(projected.iterations <= 6, "{} iterations", projected.iterations);
            let tree = constrained.dynamics().tree().clone();
            let mut ws = tree.workspace();
            tree.update_positions(&mut ws, &projected.q).expect("positions");
            let end = ws.point_position(2, &Vector3::new(bar.lengths[2], 0.0, 0.0)).expect("end");
            prop_assert!((end.x - bar.d).abs().max(end.y.abs()) <= 1e-13 * (bar.d + bar.lengths.iter().sum::<f64>()),
                "end at {end} after projection");
        }
        let q_dot: Vec<f64> = (0..3).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let projected = constrained.project_velocities(&q0, &q_dot).expect("velocity projection");
        let tangent = bar.q_dot(1.0);
        let a = constrained.dynamics_mut().mass_matrix(&q0).expect("A");
        // The projected q̇ is a multiple of the tangent; the removed part is A-orthogonal to it.
        let removed: Vec<f64> = q_dot.iter().zip(&projected.q_dot).map(|(x, y)| x - y).collect();
        let a_t: Vec<f64> = (0..3).map(|k| (0..3).map(|l| a[(k, l)] * tangent[l]).sum()).collect();
        let inner: f64 = removed.iter().zip(&a_t).map(|(r, t)| r * t).sum();
        let scale: f64 = removed.iter().zip(&a_t).map(|(r, t)| (r * t).abs()).sum();
        prop_assert!(inner.abs() <= 1e-12 * scale, "removed part not A-orthogonal: {inner:e}");
        let ratio = projected.q_dot[0] / tangent[0];
        for k in 0..3 {
            prop_assert!((projected.q_dot[k] - ratio * tangent[k]).abs() <= 1e-12 * (1.0 + tangent[k].abs() * ratio.abs()));
        }
        let speed = q_dot.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        prop_assert!(projected.residual <= 1e-13 * (bar.d + bar.lengths.iter().sum::<f64>()) * speed,
            "‖J q̇‖ = {:e} after the projection", projected.residual);
    }

    /// The equilibrium under gravity and a constant crank torque τ (a potential −τ θ1), from a
    /// start near a configuration that τ holds: at the q found, τ equals the virtual-work torque of the hand derivation and the reaction is the
    /// moment balances' pin force.
    #[test]
    fn equilibrium_matches_virtual_work(seed in any::<u64>()) {
        let mut rng = Rng::new(seed);
        let mut bar = FourBar::random(&mut rng);
        // The drawn configuration is an equilibrium for this torque; the search starts near it.
        let tau = bar.static_torque();
        let constrained = bar.pin_only_in_plane();
        let mut mechanism = constrained.dynamics().mechanism().clone();
        mechanism.add_potential(GeneralizedForce { coordinate: 0, value: tau }).expect("torque");
        let mut constrained = {
            let pin = constrained.constraints()[0].clone();
            let mut fresh = ConstrainedDynamics::new(Dynamics::new(mechanism).expect("dynamics"));
            fresh.add_constraint("pin at D", pin).expect("pin");
            fresh
        };
        let start: Vec<f64> = bar.q().iter().map(|x| x + rng.uniform(-0.02, 0.02)).collect();
        let options = ConstrainedEquilibriumOptions { max_step: 0.3, ..Default::default() };
        let result = constrained.equilibrium(&start, &options).expect("equilibrium");
        prop_assert!(result.stationarity <= result.stationarity_tolerance);
        let q = &result.q;
        bar.phi = [q[0], q[0] + q[1], q[0] + q[1] + q[2]];
        let ([.., dp], _) = bar.points();
        prop_assert!((dp - Vector2::new(bar.d, 0.0)).norm() <= 1e-12 * bar.d, "not closed: D = {dp}");
        let torque_scale = bar.force_scale() * bar.lengths[0];
        prop_assert!((bar.static_torque() - tau).abs() <= 1e-9 * torque_scale,
            "virtual-work torque {} against the applied {tau}", bar.static_torque());
        let pin = bar.pin_force(&[Vector2::zeros(); 3], &[0.0; 3], &[tau, 0.0, 0.0]);
        let force = result.reactions[0].force;
        prop_assert!(close2(&Vector2::new(force.x, force.y), &pin, 1e-9 * bar.force_scale()), "pin {force} against {pin}");
    }
}

/// Closing the planar loop along z as well makes the third equation redundant: the error names
/// it.
#[test]
fn a_pin_in_three_directions_is_redundant() {
    let mut rng = Rng::new(7);
    for _ in 0..16 {
        let bar = FourBar::random(&mut rng);
        let mut constrained = bar.constrained(vec![Vector3::x(), Vector3::y(), Vector3::z()]);
        let q = bar.q();
        match constrained.forward_dynamics(&State::new(&q, &[0.0; 3]), &[0.0; 3]) {
            Err(DynamicsError::RedundantConstraint { constraint, name, .. }) => {
                assert_eq!(constraint, 2);
                assert!(name.contains("pin at D") && name.contains("equation 3 of 3"), "{name}");
            }
            other => panic!("expected a redundant constraint, got {other:?}"),
        }
        assert!(matches!(
            constrained.project_velocities(&q, &[0.0; 3]),
            Err(DynamicsError::RedundantConstraint { constraint: 2, .. })
        ));
    }
}
