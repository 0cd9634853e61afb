//! The power balance dT/dt = q̇ᵀ(τ − g + Σ Q) (7.48, EB1911 §22 (18)–(19)) with dampers taking
//! exactly 2D (FM 4.66) and the magnetic force doing no work, on random trees with random loads.
//! dT/dt is formed independently of the recursions: ½ q̇ᵀ Ȧ q̇ by a central difference of the
//! composite-rigid-body A(q) along q̇, plus q̇ᵀ A q̈.

mod common;

use common::{Rng, random_mechanism, random_state};
use mechanica_dynamics::{ChargedPoint, Damper, Dynamics, LoadKind, State, UniformFields};
use mechanica_mechanism::potentials::{JointSpring, PointSpring};
use mechanica_mechanism::{Anchor, Mechanism};
use nalgebra::Vector3;
use proptest::prelude::*;
use std::sync::Arc;

fn anchor(rng: &mut Rng, bodies: usize) -> Anchor {
    let body = rng.below(bodies + 1);
    Anchor {
        body: (body < bodies).then_some(body),
        point: rng.vector(1.0),
    }
}

/// Gravity, a point spring, a joint spring, three kinds of damper and a charge.
fn loaded(rng: &mut Rng, mut mechanism: Mechanism) -> Dynamics {
    let bodies = mechanism.tree().body_count();
    let n = mechanism.dof();
    mechanism.set_gravity(rng.vector(10.0)).expect("gravity");
    let (a, b) = (anchor(rng, bodies), anchor(rng, bodies));
    mechanism
        .add_potential(PointSpring {
            a,
            b,
            stiffness: rng.uniform(0.0, 100.0),
            rest_length: 0.0,
        })
        .expect("spring");
    if n > 0 {
        let coordinate = rng.below(n);
        // Joint springs are refused on rotation vectors; any other coordinate takes one.
        let _ = mechanism.add_potential(JointSpring {
            coordinate,
            stiffness: rng.uniform(0.0, 50.0),
            rest: 0.3,
        });
    }
    let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
    let coefficient = rng.uniform(0.0, 5.0);
    let (a, b) = (anchor(rng, bodies), anchor(rng, bodies));
    dynamics
        .add_damper(Damper::Points { a, b, coefficient })
        .expect("damper");
    let (a, b) = (
        Anchor {
            body: Some(rng.below(bodies)),
            point: rng.vector(1.0),
        },
        Anchor {
            body: None,
            point: rng.vector(3.0) + Vector3::new(5.0, 0.0, 0.0),
        },
    );
    dynamics
        .add_damper(Damper::Dashpot {
            a,
            b,
            coefficient: rng.uniform(0.0, 5.0),
        })
        .expect("dashpot");
    if n > 0 {
        let coordinate = rng.below(n);
        dynamics
            .add_damper(Damper::Joint {
                coordinate,
                coefficient: rng.uniform(0.0, 5.0),
            })
            .expect("joint damper");
    }
    let field = Arc::new(UniformFields {
        electric: rng.vector(3.0),
        magnetic: rng.vector(3.0),
    });
    let charge = ChargedPoint {
        body: rng.below(bodies),
        point: rng.vector(0.5),
        charge: rng.uniform(-1.0, 1.0),
        field,
    };
    dynamics.add_velocity_potential(charge).expect("charge");
    dynamics
}

fn kinetic_energy(dynamics: &mut Dynamics, q: &[f64], q_dot: &[f64]) -> f64 {
    let a = dynamics.mass_matrix(q).expect("mass matrix");
    let n = q.len();
    (0..n)
        .map(|k| (0..n).map(|l| 0.5 * q_dot[k] * a[(k, l)] * q_dot[l]).sum::<f64>())
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn power_balance_on_random_trees(seed in any::<u64>(), bodies in 1usize..9, chain in any::<bool>()) {
        let mut rng = Rng::new(seed);
        let mechanism = random_mechanism(&mut rng, bodies, 4.0, chain);
        let mut dynamics = loaded(&mut rng, mechanism);
        let (q, q_dot, _) = random_state(&mut rng, dynamics.mechanism());
        let n = q.len();
        let tau: Vec<f64> = (0..n).map(|_| rng.uniform(-5.0, 5.0)).collect();
        let state = State::new(&q, &q_dot);
        let forward = dynamics.forward_dynamics(&state, &tau).expect("forward");
        let split = dynamics.inverse_dynamics(&state, &forward.q_ddot).expect("inverse");
        // ½ q̇ᵀ Ȧ q̇ by a central difference along q̇ (error O(ε²)).
        let eps = 1e-5;
        let shifted = |sign: f64| -> Vec<f64> { q.iter().zip(&q_dot).map(|(x, v)| x + sign * eps * v).collect() };
        let t_rate = (kinetic_energy(&mut dynamics, &shifted(1.0), &q_dot) - kinetic_energy(&mut dynamics, &shifted(-1.0), &q_dot)) / (2.0 * eps);
        let a = dynamics.mass_matrix(&q).expect("mass matrix");
        let a_qdd: f64 = (0..n).map(|k| (0..n).map(|l| q_dot[k] * a[(k, l)] * forward.q_ddot[l]).sum::<f64>()).sum();
        let d_t = t_rate + a_qdd;
        let mut power = 0.0;
        let mut size = d_t.abs();
        for k in 0..n {
            let loads: f64 = split.loads.iter().map(|l| l.force[k]).sum();
            let term = q_dot[k] * (tau[k] - split.gravity[k] + loads);
            power += term;
            size += (q_dot[k] * tau[k]).abs() + (q_dot[k] * split.gravity[k]).abs() + split.loads.iter().map(|l| (q_dot[k] * l.force[k]).abs()).sum::<f64>();
        }
        prop_assert!((d_t - power).abs() <= 1e-6 * size, "dT/dt = {d_t} but q̇ᵀ(τ − g + ΣQ) = {power} (size {size})");
        let damper_power: f64 = split.loads.iter().filter(|l| l.kind == LoadKind::Damper)
            .map(|l| (0..n).map(|k| l.force[k] * q_dot[k]).sum::<f64>()).sum();
        prop_assert!((damper_power + 2.0 * split.dissipation).abs() <= 1e-12 * (split.dissipation + size * 1e-3));
        prop_assert!(split.dissipation >= 0.0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// C(q) is symmetric, and the dampers' generalized force is −C q̇ with D = ½ q̇ᵀ C q̇.
    #[test]
    fn damping_matrix_matches_the_damper_forces(seed in any::<u64>(), bodies in 1usize..8) {
        let mut rng = Rng::new(seed);
        let mechanism = random_mechanism(&mut rng, bodies, 4.0, false);
        let mut dynamics = loaded(&mut rng, mechanism);
        let (q, q_dot, _) = random_state(&mut rng, dynamics.mechanism());
        let n = q.len();
        let c = dynamics.damping_matrix(&q).expect("damping matrix");
        let split = dynamics.inverse_dynamics(&State::new(&q, &q_dot), &vec![0.0; n]).expect("inverse");
        let mut damper_force = vec![0.0; n];
        for load in split.loads.iter().filter(|l| l.kind == LoadKind::Damper) {
            for k in 0..n {
                damper_force[k] += load.force[k];
            }
        }
        let size: f64 = (0..n).map(|k| (0..n).map(|l| (c[(k, l)] * q_dot[l]).abs()).sum::<f64>()).fold(0.0, f64::max);
        for k in 0..n {
            let c_qd: f64 = (0..n).map(|l| c[(k, l)] * q_dot[l]).sum();
            prop_assert!((damper_force[k] + c_qd).abs() <= 1e-12 * (size + 1e-300), "k = {k}: Q = {} but −C q̇ = {}", damper_force[k], -c_qd);
            for l in 0..n {
                prop_assert!((c[(k, l)] - c[(l, k)]).abs() <= 1e-14 * (c[(k, k)].abs() + c[(l, l)].abs()));
            }
        }
        let quadratic: f64 = (0..n).map(|k| (0..n).map(|l| 0.5 * q_dot[k] * c[(k, l)] * q_dot[l]).sum::<f64>()).sum();
        prop_assert!((quadratic - split.dissipation).abs() <= 1e-12 * (split.dissipation + size * 1e-3));
    }
}
