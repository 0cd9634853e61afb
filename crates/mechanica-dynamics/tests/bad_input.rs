//! Bad inputs give typed errors that name what was wrong; nothing panics and no NaN leaves.

mod common;

use common::{Rng, random_mechanism};
use mechanica_dynamics::{ChargedPoint, Damper, Dynamics, DynamicsError, ForwardMethod, State, UniformFields};
use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Anchor, Mechanism};
use nalgebra::{Isometry3, Matrix3, Vector3};
use std::sync::Arc;

fn sample() -> Dynamics {
    let mut rng = Rng::new(3);
    let mut mechanism = random_mechanism(&mut rng, 5, 2.0, true);
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

#[test]
fn wrong_lengths_name_the_vector() {
    let mut dynamics = sample();
    let n = dynamics.dof();
    let (q, v) = (vec![0.1; n], vec![0.2; n]);
    let short = vec![0.0; n - 1];
    let state = State::new(&q, &v);
    let cases = [
        dynamics.inverse_dynamics(&state, &short).err(),
        dynamics.forward_dynamics(&state, &short).err(),
        dynamics.forward_dynamics(&State::new(&short, &v), &q).err(),
        dynamics.forward_dynamics(&State::new(&q, &short), &q).err(),
    ];
    for (case, what) in cases.into_iter().zip(["q_ddot", "tau", "q", "q_dot"]) {
        match case {
            Some(DynamicsError::WrongLength {
                what: named,
                expected,
                got,
            }) => {
                assert_eq!((named, expected, got), (what, n, n - 1));
            }
            other => panic!("{what}: expected WrongLength, got {other:?}"),
        }
    }
    let mut out = vec![0.0; n + 1];
    assert!(matches!(
        dynamics.rnea_into(&q, &v, &q, &mut out),
        Err(DynamicsError::WrongLength { .. })
    ));
    assert!(matches!(
        dynamics.aba_into(&q, &v, &q, &mut out),
        Err(DynamicsError::WrongLength { .. })
    ));
    assert_eq!(out, vec![0.0; n + 1], "outputs are not written on failure");
}

#[test]
fn non_finite_inputs_are_refused() {
    let mut dynamics = sample();
    let n = dynamics.dof();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut q = vec![0.1; n];
        q[n / 2] = bad;
        let v = vec![0.0; n];
        let result = dynamics.forward_dynamics(&State::new(&q, &v), &v);
        assert!(
            matches!(result, Err(DynamicsError::NonFiniteInput { what: "q", .. })),
            "{result:?}"
        );
        let q = vec![0.1; n];
        let result = dynamics.forward_dynamics(&State::new(&q, &v).at_time(bad), &v);
        assert!(
            matches!(result, Err(DynamicsError::NonFiniteInput { what: "time", .. })),
            "{result:?}"
        );
    }
}

#[test]
fn overflowing_states_give_non_finite_result_errors() {
    let mut dynamics = sample();
    let n = dynamics.dof();
    let (q, v) = (vec![0.1; n], vec![1e200; n]);
    let result = dynamics.forward_dynamics(&State::new(&q, &v), &vec![0.0; n]);
    assert!(
        matches!(
            result,
            Err(DynamicsError::NonFiniteResult { .. }) | Err(DynamicsError::Kinematics(_))
        ),
        "{result:?}"
    );
    let mut out = vec![0.0; n];
    let result = dynamics.rnea_into(&q, &v, &vec![1e300; n], &mut out);
    assert!(result.is_err(), "{result:?}");
    assert!(out.iter().all(|x| x.is_finite()));
}

#[test]
fn bad_dampers_and_charges_are_refused() {
    let mut dynamics = sample();
    let (n, bodies) = (dynamics.dof(), dynamics.tree().body_count());
    for coefficient in [-1.0, f64::NAN, f64::INFINITY] {
        let result = dynamics.add_damper(Damper::Joint {
            coordinate: 0,
            coefficient,
        });
        assert!(
            matches!(
                result,
                Err(DynamicsError::OutOfRange {
                    what: "damping coefficient",
                    ..
                })
            ),
            "{result:?}"
        );
    }
    let result = dynamics.add_damper(Damper::Joint {
        coordinate: n,
        coefficient: 1.0,
    });
    assert!(
        matches!(result, Err(DynamicsError::NoSuchCoordinate { .. })),
        "{result:?}"
    );
    let far = Anchor {
        body: Some(bodies),
        point: Vector3::zeros(),
    };
    let ground = Anchor {
        body: None,
        point: Vector3::zeros(),
    };
    let result = dynamics.add_damper(Damper::Points {
        a: far,
        b: ground,
        coefficient: 1.0,
    });
    assert!(matches!(result, Err(DynamicsError::NoSuchBody { .. })), "{result:?}");
    let field = Arc::new(UniformFields {
        electric: Vector3::zeros(),
        magnetic: Vector3::z(),
    });
    let charge = ChargedPoint {
        body: bodies,
        point: Vector3::zeros(),
        charge: 1.0,
        field,
    };
    assert!(matches!(
        dynamics.add_velocity_potential(charge),
        Err(DynamicsError::NoSuchBody { .. })
    ));
    assert!(dynamics.dampers().is_empty() && dynamics.velocity_potentials().is_empty());
}

#[test]
fn a_dashpot_whose_points_meet_has_no_direction() {
    let mut dynamics = sample();
    let n = dynamics.dof();
    let a = Anchor {
        body: Some(0),
        point: Vector3::zeros(),
    };
    dynamics
        .add_damper(Damper::Dashpot {
            a,
            b: a,
            coefficient: 1.0,
        })
        .expect("valid damper");
    let (q, v) = (vec![0.0; n], vec![0.1; n]);
    let result = dynamics.forward_dynamics(&State::new(&q, &v), &vec![0.0; n]);
    assert!(matches!(result, Err(DynamicsError::Dissipation { .. })), "{result:?}");
}

/// A massless leaf makes A(q) singular: both routes say so instead of returning NaN or ∞.
#[test]
fn massless_coordinates_are_a_singular_mass_matrix() {
    let mut builder = TreeBuilder::new();
    let root = builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    builder.add_body(
        Some(root),
        Joint::Revolute { axis: Vector3::x() },
        Isometry3::translation(1.0, 0.0, 0.0),
    );
    let tree = builder.build().expect("tree");
    let heavy = MassProperties::new(2.0, Vector3::new(0.5, 0.0, 0.0), Matrix3::identity()).expect("mass");
    let massless = MassProperties {
        mass: 0.0,
        p_oc: Vector3::zeros(),
        inertia_c: Matrix3::zeros(),
    };
    let mut dynamics =
        Dynamics::new(Mechanism::new(tree, vec![heavy, massless]).expect("mechanism")).expect("dynamics");
    let (q, v) = ([0.3, 0.2], [0.1, 0.4]);
    let result = dynamics.forward_dynamics(&State::new(&q, &v), &[1.0, 1.0]);
    assert!(
        matches!(result, Err(DynamicsError::SingularMassMatrix { pivot: 1, .. })),
        "{result:?}"
    );
    let mut out = [7.0; 2];
    let result = dynamics.aba_into(&q, &v, &[1.0, 1.0], &mut out);
    assert!(
        matches!(result, Err(DynamicsError::SingularMassMatrix { .. })),
        "{result:?}"
    );
    assert_eq!(out, [7.0; 2]);
}

/// Loads near the bottom of the range (a charge of 1e-312…1e-295 in a field of order 10 on
/// bodies of 1e-3…1e3 kg): τ_k's rounding estimate is never below the rounding of τ_k itself (the
/// sums of squares of the old Euclidean norms underflowed to an estimate of 0), and a forward
/// solve whose q̈ underflows reports a nonzero backward error for its nonzero residual.
#[test]
fn tiny_loads_keep_their_rounding_estimate() {
    let mut rng = Rng::new(41);
    for case in 0..200 {
        let bodies = 1 + rng.below(6);
        let mut mechanism = random_mechanism(&mut rng, bodies, 6.0, case % 2 == 0);
        mechanism.set_gravity(Vector3::zeros()).expect("gravity");
        let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
        let field = Arc::new(UniformFields {
            electric: rng.vector(100.0),
            magnetic: rng.vector(1.0),
        });
        let charge = ChargedPoint {
            body: rng.below(bodies),
            point: rng.vector(1.0),
            charge: 10f64.powf(rng.uniform(-312.0, -295.0)),
            field,
        };
        dynamics.add_velocity_potential(charge).expect("charge");
        let n = dynamics.dof();
        let (q, zero) = (common::random_state(&mut rng, dynamics.mechanism()).0, vec![0.0; n]);
        let state = State::new(&q, &zero);
        let inverse = dynamics.inverse_dynamics(&state, &zero).expect("inverse dynamics");
        for (k, (tau, estimate)) in inverse.tau.iter().zip(&inverse.error_estimate).enumerate() {
            assert!(
                *estimate >= f64::EPSILON / 2.0 * tau.abs(),
                "case {case}: τ[{k}] = {tau:e} with rounding estimate {estimate:e}"
            );
        }
        for result in [
            dynamics.forward_dynamics(&state, &zero),
            dynamics.forward_dynamics_crba(&state, &zero),
        ] {
            let forward = match result {
                Ok(forward) => forward,
                Err(DynamicsError::SingularMassMatrix { .. }) => continue,
                Err(other) => panic!("case {case}: {other}"),
            };
            let residual = forward.residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
            assert!(
                residual == 0.0 || forward.backward_error > 0.0,
                "case {case}: residual {residual:e} with backward error 0"
            );
        }
    }
}

/// A joint about a random axis a carrying only a point mass at L·a (stored rounded): the mass
/// matrix is singular to working precision, since the joint moves the mass by the rounding of
/// its position alone. The articulated-body pivot sᵀIᴬs is then rounding noise against
/// |s|ᵀ|Iᴬ||s|; the forward dynamics must say so (an error, or the mass-matrix route with an
/// error estimate as large as q̈), never return the noise's q̈ as accurate.
#[test]
fn a_point_mass_on_its_joint_axis_is_not_solved_silently() {
    let mut rng = Rng::new(77);
    for case in 0..200 {
        let axis = rng.unit();
        let tree = two_revolute_links(&mut rng, Vector3::z(), axis);
        let heavy = MassProperties::new(2.0, rng.vector(0.5), Matrix3::identity()).expect("mass");
        let length = 10f64.powf(rng.uniform(-2.0, 2.0));
        let point = MassProperties {
            mass: 10f64.powf(rng.uniform(-3.0, 3.0)),
            p_oc: axis * length,
            inertia_c: Matrix3::zeros(),
        };
        let dynamics = Dynamics::new(Mechanism::new(tree, vec![heavy, point]).expect("mechanism")).expect("dynamics");
        assert_singular_is_said(dynamics, &mut rng, case, false);
    }
}

/// Two joints about random axes a₁, a₂ through one point, the second carrying only a point mass
/// at x·a₁ + y·a₂ (the inner link massless or a point mass at the joint, as iCub's neck): the
/// combination of the two rotations about the axis along the mass moves nothing, so A(q) is
/// singular, although no single joint's articulated pivot cancels against its own terms (the
/// cancellation happens when the outer joint is condensed onto the inner one). The outer
/// joint stays at 0, where its body frame carries a₁ unchanged.
#[test]
fn two_joints_that_together_move_nothing_are_not_solved_silently() {
    let mut rng = Rng::new(78);
    for case in 0..200 {
        let (first, second) = (rng.unit(), rng.unit());
        let mut builder = TreeBuilder::new();
        let root = builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
        let offset = rng.vector(1.0);
        let inner = builder.add_body(
            Some(root),
            Joint::Revolute { axis: first },
            Isometry3::translation(offset.x, offset.y, offset.z),
        );
        builder.add_body(Some(inner), Joint::Revolute { axis: second }, Isometry3::identity());
        let tree = builder.build().expect("tree");
        let heavy = MassProperties::new(2.0, rng.vector(0.5), Matrix3::identity()).expect("mass");
        let at_joint = MassProperties {
            mass: if case % 2 == 0 { 0.0 } else { 0.1 },
            p_oc: Vector3::zeros(),
            inertia_c: Matrix3::zeros(),
        };
        let scale = 10f64.powf(rng.uniform(-2.0, 1.0));
        let point = MassProperties {
            mass: 10f64.powf(rng.uniform(-3.0, 3.0)),
            p_oc: (first * rng.uniform(-1.0, 1.0) + second * rng.uniform(-1.0, 1.0)) * scale,
            inertia_c: Matrix3::zeros(),
        };
        let dynamics =
            Dynamics::new(Mechanism::new(tree, vec![heavy, at_joint, point]).expect("mechanism")).expect("dynamics");
        assert_singular_is_said(dynamics, &mut rng, case, true);
    }
}

/// The checked forward dynamics of a mechanism whose A(q) is singular to working precision, at
/// a random state (the last coordinate 0 when `last_at_zero`): an error, or a q̈ whose error
/// estimate admits that it has no correct digit.
fn assert_singular_is_said(mut dynamics: Dynamics, rng: &mut Rng, case: usize, last_at_zero: bool) {
    let n = dynamics.dof();
    let mut q: Vec<f64> = (0..n).map(|_| rng.uniform(-3.0, 3.0)).collect();
    if last_at_zero {
        q[n - 1] = 0.0;
    }
    let v: Vec<f64> = (0..n)
        .map(|k| if k == 0 { rng.uniform(-1.0, 1.0) } else { 0.0 })
        .collect();
    let tau: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
    match dynamics.forward_dynamics(&State::new(&q, &v), &tau) {
        Err(DynamicsError::SingularMassMatrix { .. } | DynamicsError::SingularArticulatedInertia { .. }) => {}
        Err(other) => panic!("case {case}: {other}"),
        Ok(forward) => {
            let largest = forward.q_ddot.iter().fold(0.0f64, |m, a| m.max(a.abs()));
            let estimate = forward.error_estimate.unwrap_or(0.0);
            assert!(
                estimate >= 0.5 * largest,
                "case {case}: q̈ = {:?} by {:?} with error estimate {:?}",
                forward.q_ddot,
                forward.method,
                forward.error_estimate
            );
        }
    }
}

/// A thin body spun about its own axis (moments 1, 1, ε with ε down to 1e-12) has a small
/// pivot but a well-conditioned A = [ε]: the checked forward dynamics keeps the articulated
/// route and gets q̈ = τ/ε to the rounding level.
#[test]
fn a_thin_body_about_its_axis_keeps_the_articulated_route() {
    let mut rng = Rng::new(79);
    for case in 0..100 {
        let mut builder = TreeBuilder::new();
        builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
        let tree = builder.build().expect("tree");
        let thin = 10f64.powf(rng.uniform(-12.0, -6.0));
        let body = MassProperties::new(
            1.0,
            Vector3::zeros(),
            Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, thin)),
        )
        .expect("a valid thin body");
        let mut dynamics = Dynamics::new(Mechanism::new(tree, vec![body]).expect("mechanism")).expect("dynamics");
        let tau = rng.uniform(-1.0, 1.0);
        let forward = dynamics
            .forward_dynamics(&State::new(&[rng.uniform(-3.0, 3.0)], &[0.0]), &[tau])
            .expect("forward dynamics");
        assert_eq!(forward.method, ForwardMethod::ArticulatedBody, "case {case}");
        let exact = tau / thin;
        assert!(
            (forward.q_ddot[0] - exact).abs() <= 1e-14 * exact.abs(),
            "case {case}: {:?} vs {exact}",
            forward.q_ddot
        );
    }
}

/// A point mass at 10^U(−9, −3) from its joint's random axis, behind a heavy link: A(q) has
/// condition numbers from 1e6 past 1/u. τ is formed by the inverse dynamics from a random q̈;
/// the mass-matrix route's error estimate must cover its distance to that q̈ (the rounding of
/// τ itself moves the exact solution by about one more estimate), and is +∞ where n·κ∞·u ≥ 1/2
/// (there the computed ‖A⁻¹‖ says nothing: on chains of some twenty rods and point masses an
/// estimate formed anyway was exceeded 135 times).
#[test]
fn the_mass_matrix_estimate_covers_near_singular_mechanisms() {
    let mut rng = Rng::new(80);
    let mut infinite = 0;
    for case in 0..300 {
        let axis = rng.unit();
        let root_axis = rng.unit();
        let tree = two_revolute_links(&mut rng, root_axis, axis);
        let heavy =
            MassProperties::new(10f64.powf(rng.uniform(0.0, 3.0)), rng.vector(0.5), Matrix3::identity()).expect("mass");
        let off_axis = axis.cross(&rng.unit()).normalize() * 10f64.powf(rng.uniform(-9.0, -3.0));
        let point = MassProperties {
            mass: 10f64.powf(rng.uniform(-3.0, 1.0)),
            p_oc: axis * rng.uniform(0.1, 2.0) + off_axis,
            inertia_c: Matrix3::zeros(),
        };
        let mut dynamics =
            Dynamics::new(Mechanism::new(tree, vec![heavy, point]).expect("mechanism")).expect("dynamics");
        let q = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)];
        let v = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        let q_ddot = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        let state = State::new(&q, &v);
        let tau = dynamics.inverse_dynamics(&state, &q_ddot).expect("inverse").tau;
        let forward = match dynamics.forward_dynamics_crba(&state, &tau) {
            Ok(forward) => forward,
            Err(DynamicsError::SingularMassMatrix { .. }) => continue,
            Err(other) => panic!("case {case}: {other}"),
        };
        let estimate = forward.error_estimate.expect("an estimate");
        let condition = forward.condition.expect("a condition number");
        if estimate.is_infinite() {
            assert!(
                2.0 * condition * f64::EPSILON >= 0.5,
                "case {case}: +∞ at κ = {condition:e}"
            );
            infinite += 1;
            continue;
        }
        let error = forward
            .q_ddot
            .iter()
            .zip(&q_ddot)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            error <= 2.0 * estimate,
            "case {case}: error {error:e} above twice the estimate {estimate:e} (κ∞ = {condition:e})"
        );
    }
    assert!(
        (10..290).contains(&infinite),
        "{infinite} of 300 cases beyond the estimate's reach"
    );
}

/// A root revolute joint about `root_axis` at the origin and a second about `axis` at a
/// random offset.
fn two_revolute_links(rng: &mut Rng, root_axis: Vector3<f64>, axis: Vector3<f64>) -> KinematicTree {
    let mut builder = TreeBuilder::new();
    let root = builder.add_body(None, Joint::Revolute { axis: root_axis }, Isometry3::identity());
    let offset = rng.vector(1.0);
    builder.add_body(
        Some(root),
        Joint::Revolute { axis },
        Isometry3::translation(offset.x, offset.y, offset.z),
    );
    builder.build().expect("tree")
}
