//! The exact gradient and Hessian of U* against central finite differences, the gyroscopic
//! matrix against a sum over point masses, and the field potential against closed forms.

mod common;

use common::{random_tree, random_vector};
use mechanica_kinematics::tree::Joint;
use mechanica_mass::MassProperties;
use mechanica_mechanism::potentials::{ConstantForce, GeneralizedForce, JointSpring, PointSpring};
use mechanica_mechanism::{Anchor, Mechanism, MechanismError, RotatingFrame};
use nalgebra::{Unit, Vector3};

/// A random mechanism with every kind of built-in potential.
fn loaded_mechanism(n: usize, seed: u64, spherical: bool, rotating: bool) -> Mechanism {
    let (tree, bodies) = random_tree(n, seed, spherical);
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    if rotating {
        mechanism
            .set_rotating_frame(Some(RotatingFrame {
                axis: Unit::new_normalize(Vector3::z()),
                rate: 2.5,
            }))
            .expect("rotation");
    }
    let last = n - 1;
    mechanism
        .add_potential(PointSpring {
            a: Anchor {
                body: Some(last),
                point: Vector3::new(0.1, 0.2, 0.3),
            },
            b: Anchor {
                body: None,
                point: Vector3::new(1.0, -1.0, 0.5),
            },
            stiffness: 40.0,
            rest_length: 0.3,
        })
        .expect("ground spring");
    mechanism
        .add_potential(PointSpring {
            a: Anchor {
                body: Some(0),
                point: Vector3::new(0.3, 0.0, 0.1),
            },
            b: Anchor {
                body: Some(last),
                point: Vector3::new(-0.2, 0.1, 0.0),
            },
            stiffness: 25.0,
            rest_length: 0.0,
        })
        .expect("body spring");
    mechanism
        .add_potential(ConstantForce {
            body: n / 2,
            point: Vector3::new(0.2, -0.1, 0.4),
            force: Vector3::new(3.0, -2.0, 1.0),
        })
        .expect("force");
    mechanism
        .add_potential(GeneralizedForce {
            coordinate: 0,
            value: 0.7,
        })
        .expect("Q");
    let tree = mechanism.tree().clone();
    for k in 0..tree.dof() {
        let body = tree.dof_body(k).expect("body");
        if !matches!(tree.joint(body), Some(Joint::Spherical)) {
            mechanism
                .add_potential(JointSpring {
                    coordinate: k,
                    stiffness: 5.0 + k as f64,
                    rest: 0.1,
                })
                .expect("joint spring");
            break;
        }
    }
    mechanism
}

/// q with the rotation vectors of spherical joints set to zero (Hessians are exact there).
fn random_q(mechanism: &Mechanism, seed: u64) -> Vec<f64> {
    let tree = mechanism.tree();
    let mut q = random_vector(tree.dof(), seed, 0.8);
    for i in 0..tree.body_count() {
        if matches!(tree.joint(i), Some(Joint::Spherical)) {
            for k in tree.dof_range(i) {
                q[k] = 0.0;
            }
        }
    }
    q
}

fn check_derivatives(mechanism: &Mechanism, q: &[f64]) {
    let n = q.len();
    let exact = mechanism.potential(q, true).expect("potential");
    let hessian = exact.hessian.expect("hessian");
    let h = 1e-5;
    let scale_g = exact.gradient.iter().fold(1.0_f64, |m, g| m.max(g.abs()));
    let scale_h = hessian.norm_max().max(1.0);
    for k in 0..n {
        let mut plus = q.to_vec();
        let mut minus = q.to_vec();
        plus[k] += h;
        minus[k] -= h;
        let up = mechanism.potential(&plus, false).expect("potential");
        let down = mechanism.potential(&minus, false).expect("potential");
        // Central differences: truncation O(h²), rounding O(u/h) relative.
        let fd_gradient = (up.value - down.value) / (2.0 * h);
        assert!(
            (fd_gradient - exact.gradient[k]).abs() <= 1e-6 * scale_g,
            "dU/dq{k}: exact {} vs finite difference {fd_gradient}",
            exact.gradient[k]
        );
        for l in 0..n {
            let fd = (up.gradient[l] - down.gradient[l]) / (2.0 * h);
            assert!(
                (fd - hessian[(l, k)]).abs() <= 1e-6 * scale_h,
                "d2U/dq{l}dq{k}: exact {} vs finite difference {fd}",
                hessian[(l, k)]
            );
        }
    }
}

#[test]
fn gradient_and_hessian_match_finite_differences_on_random_trees() {
    for seed in 0..12 {
        let n = 3 + (seed as usize % 5);
        let mechanism = loaded_mechanism(n, seed, false, seed % 2 == 1);
        let q = random_q(&mechanism, seed + 100);
        check_derivatives(&mechanism, &q);
    }
}

#[test]
fn hessian_in_rotation_vector_coordinates_is_exact_at_zero() {
    for seed in 20..30 {
        let mechanism = loaded_mechanism(5, seed, true, seed % 2 == 0);
        let q = random_q(&mechanism, seed + 7);
        check_derivatives(&mechanism, &q);
    }
}

#[test]
fn hessian_away_from_zero_rotation_vector_is_refused_and_rebasing_fixes_it() {
    for seed in 40..60 {
        let (tree, bodies) = random_tree(4, seed, true);
        if !(0..tree.body_count()).any(|i| matches!(tree.joint(i), Some(Joint::Spherical))) {
            continue;
        }
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
        let mut q = random_vector(mechanism.dof(), seed, 0.5);
        assert!(matches!(
            mechanism.potential(&q, true),
            Err(MechanismError::NotRebased { .. })
        ));
        let before = mechanism.potential(&q, false).expect("value").value;
        mechanism.rebase(&mut q).expect("rebase");
        let after = mechanism.potential(&q, true).expect("hessian after rebase");
        assert!(
            (after.value - before).abs() <= 1e-12 * before.abs().max(1.0),
            "rebasing moved a body"
        );
        check_derivatives(&mechanism, &q);
        return;
    }
    panic!("no random tree with a spherical joint");
}

/// G_kl = 2 Σ_i m_i J_k(x_i)·(Ω × J_l(x_i)) summed directly over point masses, and
/// T₀ = ½ Σ m_i |Ω × x_i|² against −U_rot.
#[test]
fn gyroscopic_matrix_and_centrifugal_potential_match_point_mass_sums() {
    for seed in 0..6 {
        let (tree, bodies) = random_tree(5, seed, false);
        let points: Vec<MassProperties> = bodies
            .iter()
            .map(|b| MassProperties::point(b.mass, b.p_oc).expect("point"))
            .collect();
        let axis = Unit::new_normalize(Vector3::new(0.3, -0.4, 1.0));
        let rate = 3.0;
        let mut mechanism = Mechanism::new(tree.clone(), points.clone()).expect("mechanism");
        mechanism
            .set_rotating_frame(Some(RotatingFrame { axis, rate }))
            .expect("rotation");
        let n = tree.dof();
        let q = random_vector(n, seed + 3, 0.7);
        let g = mechanism.gyroscopic_matrix(&q).expect("G");
        let u = mechanism.potential(&q, false).expect("U").value;
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        let omega = axis.into_inner() * rate;
        let mut expected = vec![0.0; n * n];
        let mut t0 = 0.0;
        for (i, p) in points.iter().enumerate() {
            let mut jac = vec![0.0; 3 * n];
            tree.point_jacobian(&ws, i, &p.p_oc, &mut jac).expect("jacobian");
            let x = ws.point_position(i, &p.p_oc).expect("x");
            t0 += 0.5 * p.mass * omega.cross(&x).norm_squared();
            let col = |k: usize| Vector3::new(jac[3 * k], jac[3 * k + 1], jac[3 * k + 2]);
            for k in 0..n {
                for l in 0..n {
                    expected[k + n * l] += 2.0 * p.mass * col(k).dot(&omega.cross(&col(l)));
                }
            }
        }
        let scale = expected.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        for k in 0..n {
            for l in 0..n {
                assert!(
                    (g[(k, l)] - expected[k + n * l]).abs() <= 1e-12 * scale,
                    "G[{k},{l}] = {} vs {}",
                    g[(k, l)],
                    expected[k + n * l]
                );
            }
        }
        assert!((u + t0).abs() <= 1e-12 * t0.max(1.0), "U_rot = {u}, −T0 = {}", -t0);
    }
}

/// For an extended body the centrifugal potential is −½ Ω² times the moment of inertia about
/// the rotation axis (3.23, 3.30).
#[test]
fn centrifugal_potential_of_a_solid_body_uses_its_moment_about_the_axis() {
    let (tree, bodies) = random_tree(1, 5, false);
    let axis = Unit::new_normalize(Vector3::new(1.0, 2.0, 2.0));
    let rate = 1.5;
    let mut mechanism = Mechanism::new(tree.clone(), bodies.clone()).expect("mechanism");
    mechanism
        .set_rotating_frame(Some(RotatingFrame { axis, rate }))
        .expect("rotation");
    let q = random_vector(tree.dof(), 9, 0.5);
    let u = mechanism.potential(&q, false).expect("U").value;
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &q).expect("positions");
    let r = ws.rotation(0).expect("R");
    let world = MassProperties {
        mass: bodies[0].mass,
        p_oc: ws.point_position(0, &bodies[0].p_oc).expect("c"),
        inertia_c: r.matrix() * bodies[0].inertia_c * r.matrix().transpose(),
    };
    let moment = world.moment_about_line(&Vector3::zeros(), &axis).expect("moment");
    let expected = -0.5 * rate * rate * moment;
    assert!((u - expected).abs() <= 1e-13 * expected.abs(), "{u} vs {expected}");
}

#[test]
fn bad_inputs_are_typed_errors() {
    let (tree, bodies) = random_tree(3, 1, false);
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    assert!(matches!(
        mechanism.set_gravity(Vector3::new(f64::NAN, 0.0, 0.0)),
        Err(MechanismError::NonFinite { .. })
    ));
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    assert!(matches!(
        mechanism.set_rotating_frame(Some(RotatingFrame {
            axis: Unit::new_normalize(Vector3::x()),
            rate: 1.0
        })),
        Err(MechanismError::GravityNotAlongAxis { .. })
    ));
    assert!(matches!(
        mechanism.add_potential(JointSpring {
            coordinate: 99,
            stiffness: 1.0,
            rest: 0.0
        }),
        Err(MechanismError::NoSuchCoordinate { .. })
    ));
    assert!(matches!(
        mechanism.add_potential(PointSpring {
            a: Anchor {
                body: Some(7),
                point: Vector3::zeros()
            },
            b: Anchor {
                body: None,
                point: Vector3::zeros()
            },
            stiffness: 1.0,
            rest_length: 0.0
        }),
        Err(MechanismError::NoSuchBody { .. })
    ));
    assert!(matches!(
        mechanism.add_potential(JointSpring {
            coordinate: 0,
            stiffness: -1.0,
            rest: 0.0
        }),
        Err(MechanismError::OutOfRange { .. })
    ));
    let n = mechanism.dof();
    assert!(matches!(
        mechanism.potential(&vec![0.0; n + 1], true),
        Err(MechanismError::WrongLength { .. })
    ));
    let mut q = vec![0.0; n];
    q[0] = f64::INFINITY;
    assert!(matches!(
        mechanism.potential(&q, true),
        Err(MechanismError::NonFinite { .. })
    ));
    // A spring with a rest length whose ends meet has no direction.
    mechanism
        .add_potential(PointSpring {
            a: Anchor {
                body: None,
                point: Vector3::new(5.0, 5.0, 5.0),
            },
            b: Anchor {
                body: None,
                point: Vector3::new(5.0, 5.0, 5.0),
            },
            stiffness: 1.0,
            rest_length: 1.0,
        })
        .expect("valid spring");
    assert!(matches!(
        mechanism.potential(&vec![0.0; n], true),
        Err(MechanismError::ZeroLengthSpring { .. })
    ));
}

/// The Hessian is symmetric to the last bit whatever the scales: springs up to 1e21 on random
/// trees, lever arms up to 1e6 and coordinates up to 1e4 (the two orders of each product
/// would round differently, by far more than the result when terms cancel).
#[test]
fn hessian_is_exactly_symmetric_for_stiff_springs_and_large_coordinates() {
    for seed in 0..24u64 {
        let n = 2 + (seed as usize % 6);
        let (tree, bodies) = random_tree(n, seed, false);
        let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
        let scale = random_vector(4, seed + 500, 1.0);
        let stiffness = 10f64.powf(10.5 + 10.5 * scale[0]);
        let arm = 10f64.powf(3.0 + 3.0 * scale[1]);
        mechanism
            .add_potential(PointSpring {
                a: Anchor {
                    body: Some(n - 1),
                    point: Vector3::new(arm, -0.3 * arm, 0.7),
                },
                b: Anchor {
                    body: Some(0),
                    point: Vector3::new(-0.2, arm * scale[2], 0.1),
                },
                stiffness,
                rest_length: 0.5,
            })
            .expect("spring");
        let dof = mechanism.dof();
        let q = random_vector(dof, seed + 900, 10f64.powf(2.0 + 2.0 * scale[3]));
        let hessian = mechanism
            .potential(&q, true)
            .expect("potential")
            .hessian
            .expect("hessian");
        for k in 0..dof {
            for l in 0..k {
                assert_eq!(
                    hessian[(k, l)].to_bits(),
                    hessian[(l, k)].to_bits(),
                    "seed {seed}: H[{k},{l}] = {} vs H[{l},{k}] = {}",
                    hessian[(k, l)],
                    hessian[(l, k)]
                );
            }
        }
    }
}
