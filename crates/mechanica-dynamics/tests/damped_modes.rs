//! Damped modes of mechanisms against the proportional-damping closed form: a chain of point
//! masses on prismatic joints with joint springs, dampers from each mass to the ground
//! (c_i = α m_i, so C_ground = α A) and joint dampers (c_k = β k_k, so C_joint = β B) has
//! s = −ζω ± iω√(1 − ζ²), ζ = (α/ω + βω)/2, with ω² the eigenvalues of (A, B) from the modal
//! crate's symmetric solver; overdamped modes (ζ > 1) have s = −ζω ± ω√(ζ² − 1).

mod common;

use common::Rng;
use mechanica_dynamics::{Damper, Dynamics};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::JointSpring;
use mechanica_mechanism::{Anchor, Mechanism};
use mechanica_modal::{PencilProblem, QuadraticModeKind, QuadraticOptions, SolveOptions, solve};
use nalgebra::{Isometry3, Vector3};
use proptest::prelude::*;

fn chain(rng: &mut Rng, n: usize, alpha: f64, beta: f64) -> Dynamics {
    let mut builder = TreeBuilder::new();
    let mut masses = Vec::new();
    for i in 0..n {
        let parent = i.checked_sub(1);
        builder.add_body(
            parent,
            Joint::Prismatic { axis: Vector3::x() },
            Isometry3::translation(1.0, 0.0, 0.0),
        );
        masses.push(10f64.powf(rng.uniform(-2.0, 2.0)));
    }
    let tree = builder.build().expect("tree");
    let bodies = masses
        .iter()
        .map(|&m| MassProperties::point(m, Vector3::zeros()).expect("mass"))
        .collect();
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    let stiffness: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-1.0, 3.0))).collect();
    for (k, &s) in stiffness.iter().enumerate() {
        mechanism
            .add_potential(JointSpring {
                coordinate: k,
                stiffness: s,
                rest: 0.0,
            })
            .expect("spring");
    }
    let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
    for (i, &m) in masses.iter().enumerate() {
        let a = Anchor {
            body: Some(i),
            point: Vector3::zeros(),
        };
        let b = Anchor {
            body: None,
            point: Vector3::new(-10.0, 3.0, 0.0),
        };
        dynamics
            .add_damper(Damper::Points {
                a,
                b,
                coefficient: alpha * m,
            })
            .expect("ground damper");
        dynamics
            .add_damper(Damper::Joint {
                coordinate: i,
                coefficient: beta * stiffness[i],
            })
            .expect("joint damper");
    }
    dynamics
}

/// The roots (re, im) of s² + (α + βω²)s + ω² = 0: a conjugate pair when ζ < 1, else the
/// small root (from the product ω², free of cancellation) and the large one.
fn closed_form_roots(alpha: f64, beta: f64, omega_sq: f64) -> [(f64, f64); 2] {
    let omega = omega_sq.sqrt();
    let zeta = 0.5 * (alpha / omega + beta * omega);
    let root = (zeta * zeta - 1.0).abs().sqrt() * omega;
    if zeta < 1.0 {
        [(-zeta * omega, root), (-zeta * omega, -root)]
    } else {
        let large = -zeta * omega - root;
        [(omega_sq / large, 0.0), (large, 0.0)]
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn proportional_damping_matches_its_closed_form(seed in any::<u64>(), n in 1usize..9) {
        let mut rng = Rng::new(seed);
        let alpha = 10f64.powf(rng.uniform(-3.0, 1.5));
        let beta = 10f64.powf(rng.uniform(-4.0, -0.5));
        let mut dynamics = chain(&mut rng, n, alpha, beta);
        let q0 = vec![0.0; n];
        let modes = dynamics.damped_modes(&q0, &QuadraticOptions::default()).expect("damped modes");
        let undamped = solve(
            &PencilProblem::new(modes.mass_matrix.as_ref(), modes.stiffness_matrix.as_ref()).expect("pencil"),
            &SolveOptions::default(),
        )
        .expect("undamped modes");
        // Each closed-form pair with its own uncertainty: the spread of the roots over the
        // undamped ω²'s bound interval (the roots move with ω², by up to 1/α per unit near
        // heavily overdamped modes).
        let mut expected = Vec::new();
        for mode in &undamped.modes {
            let nominal = closed_form_roots(alpha, beta, mode.omega_sq);
            let spread = [mode.omega_sq - mode.error_bound, mode.omega_sq + mode.error_bound]
                .into_iter()
                .flat_map(|end| {
                    let moved = closed_form_roots(alpha, beta, end.max(0.0));
                    (0..2).map(move |k| (moved[k].0 - nominal[k].0).hypot(moved[k].1 - nominal[k].1))
                })
                .fold(0.0, f64::max);
            expected.extend(nominal.iter().map(|&root| (root, spread)));
        }
        prop_assert_eq!(modes.solution.eigenvalues.len(), 2 * n);
        for value in &modes.solution.eigenvalues {
            let s = value.s.expect("finite eigenvalue");
            let excess = expected
                .iter()
                .map(|&((re, im), spread)| (s.re - re).hypot(s.im - im) - spread)
                .fold(f64::INFINITY, f64::min);
            let slack = 1e-9 * s.norm();
            prop_assert!(excess <= value.error_bound + slack, "s = {s}: closed form {excess:e} beyond its spread > bound {:e}", value.error_bound);
        }
        for mode in &modes.solution.modes {
            if let Some(zeta) = mode.damping_ratio {
                let kind = mode.kind;
                if zeta < 0.9 {
                    prop_assert_eq!(kind, QuadraticModeKind::Underdamped);
                } else if zeta > 1.1 {
                    prop_assert_eq!(kind, QuadraticModeKind::Overdamped);
                }
            }
        }
    }
}

/// Velocity-dependent potentials have no linearization in (A, C, G, B): refused, not ignored.
#[test]
fn damped_modes_refuse_velocity_potentials() {
    use mechanica_dynamics::{ChargedPoint, DynamicsError, UniformFields};
    use std::sync::Arc;
    let mut rng = Rng::new(11);
    let mut dynamics = chain(&mut rng, 2, 0.1, 0.01);
    let field = Arc::new(UniformFields {
        electric: Vector3::zeros(),
        magnetic: Vector3::z(),
    });
    dynamics
        .add_velocity_potential(ChargedPoint {
            body: 0,
            point: Vector3::zeros(),
            charge: 1.0,
            field,
        })
        .expect("charge");
    let result = dynamics.damped_modes(&[0.0, 0.0], &QuadraticOptions::default());
    assert!(matches!(result, Err(DynamicsError::OutOfRange { .. })), "{result:?}");
}

/// The bits of every eigenvalue, bound and backward error, and the kinds of the modes.
fn fingerprint(modes: &mechanica_dynamics::DampedModes) -> (Vec<[u64; 4]>, Vec<QuadraticModeKind>) {
    let values = modes
        .solution
        .eigenvalues
        .iter()
        .map(|e| {
            let s = e.s.map_or([u64::MAX; 2], |s| [s.re.to_bits(), s.im.to_bits()]);
            [s[0], s[1], e.error_bound.to_bits(), e.backward_error.to_bits()]
        })
        .collect();
    (values, modes.solution.modes.iter().map(|m| m.kind).collect())
}

/// Two identical calls give identical modes, bit for bit, and leave the dynamics as it was:
/// the re-centring of spherical and free joints that the Hessian needs happens on a copy, so
/// q₀ names the same configuration in the second call (re-centring the dynamics itself made
/// the second call linearize about R_ref exp(φ) exp(φ), with other modes and another count).
#[test]
fn identical_damped_mode_calls_agree_bit_for_bit_and_keep_the_charts() {
    use common::{random_mechanism, random_state};
    let mut with_rotation_vectors = 0;
    for seed in 0..24u64 {
        let mut rng = Rng::new(seed);
        let bodies = 2 + rng.below(4);
        let mut mechanism = random_mechanism(&mut rng, bodies, 6.0, false);
        mechanism.set_gravity(Vector3::new(0.3, -0.5, -9.81)).expect("gravity");
        with_rotation_vectors += usize::from(mechanism.has_rotation_vectors());
        let (q0, _, _) = random_state(&mut rng, &mechanism);
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let a = Anchor {
            body: Some(bodies - 1),
            point: rng.vector(0.5),
        };
        let b = Anchor {
            body: None,
            point: rng.vector(2.0),
        };
        dynamics
            .add_damper(Damper::Points {
                a,
                b,
                coefficient: 10f64.powf(rng.uniform(-2.0, 2.0)),
            })
            .expect("damper");
        let mass_before = dynamics.mass_matrix(&q0).expect("mass matrix");
        let first = dynamics.damped_modes(&q0, &QuadraticOptions::default());
        let second = dynamics.damped_modes(&q0, &QuadraticOptions::default());
        let mass_after = dynamics.mass_matrix(&q0).expect("mass matrix");
        assert_eq!(mass_before, mass_after, "seed {seed}: the call moved the charts");
        match (first, second) {
            (Ok(first), Ok(second)) => {
                assert_eq!(fingerprint(&first), fingerprint(&second), "seed {seed}");
                assert_eq!(first.q, second.q, "seed {seed}");
            }
            (Err(e1), Err(e2)) => assert_eq!(e1.to_string(), e2.to_string(), "seed {seed}"),
            (r1, r2) => panic!("seed {seed}: {:?} then {:?}", r1.map(|m| m.q), r2.map(|m| m.q)),
        }
    }
    assert!(
        with_rotation_vectors >= 8,
        "only {with_rotation_vectors} trees with rotation vectors"
    );
}
