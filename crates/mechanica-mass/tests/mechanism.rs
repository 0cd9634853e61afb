//! The composite-rigid-body mass matrix against the definition (8.28) evaluated from point
//! Jacobians of point masses, and the kinetic energy against point velocities from the
//! kinematics crate's velocity recursion.

use mechanica_kinematics::tree::{BaseState, Joint, KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::{DragField, SplitBuffers, TreeMass};
use nalgebra::{DMatrix, Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

type Cloud = Vec<(f64, Vector3<f64>)>;

#[derive(Debug, Clone)]
struct Spec {
    parent_pick: f64,
    joint: u8,
    axis: [f64; 3],
    offset: [f64; 3],
    angles: [f64; 3],
    cloud: Vec<(f64, [f64; 3])>,
}

fn spec() -> impl Strategy<Value = Spec> {
    (
        0.0f64..1.0,
        0u8..6,
        proptest::array::uniform3(-1.0f64..1.0),
        proptest::array::uniform3(-1.0f64..1.0),
        proptest::array::uniform3(-3.0f64..3.0),
        proptest::collection::vec((0.1f64..3.0, proptest::array::uniform3(-0.5f64..0.5)), 4..6),
    )
        .prop_map(|(parent_pick, joint, axis, offset, angles, cloud)| Spec {
            parent_pick,
            joint,
            axis,
            offset,
            angles,
            cloud,
        })
}

fn build(specs: &[Spec]) -> (KinematicTree, Vec<Cloud>) {
    let mut builder = TreeBuilder::new();
    let mut clouds = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        let parent = if i == 0 {
            None
        } else {
            Some(((s.parent_pick * i as f64) as usize).min(i - 1))
        };
        let mut axis = Vector3::from(s.axis);
        if axis.norm() < 0.1 {
            axis = Vector3::z();
        }
        let axis = axis.normalize();
        let joint = match s.joint {
            0 => Joint::Revolute { axis },
            1 => Joint::Prismatic { axis },
            2 => Joint::Spherical,
            3 => Joint::Free,
            4 => Joint::Planar,
            _ => Joint::Revolute { axis },
        };
        let joint = if i == 0 && matches!(joint, Joint::Fixed) {
            Joint::Free
        } else {
            joint
        };
        let placement = Isometry3::from_parts(
            Translation3::from(Vector3::from(s.offset)),
            UnitQuaternion::from_euler_angles(s.angles[0], s.angles[1], s.angles[2]),
        );
        builder.add_body(parent, joint, placement);
        clouds.push(s.cloud.iter().map(|(m, p)| (*m, Vector3::from(*p))).collect());
    }
    (builder.build().expect("valid tree"), clouds)
}

fn body_properties(cloud: &Cloud) -> MassProperties {
    let points: Vec<MassProperties> = cloud
        .iter()
        .map(|(m, p)| MassProperties::point(*m, *p).expect("valid point"))
        .collect();
    MassProperties::sum(&points).expect("positive mass")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn crba_equals_the_jacobian_definition_and_is_positive_definite(
        specs in proptest::collection::vec(spec(), 1..9),
        seed in proptest::collection::vec(-1.0f64..1.0, 60),
    ) {
        let (tree, clouds) = build(&specs);
        let n = tree.dof();
        let q: Vec<f64> = (0..n).map(|k| seed[k % seed.len()]).collect();
        let q_dot: Vec<f64> = (0..n).map(|k| seed[(k + 7) % seed.len()] * 2.0).collect();
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");

        let bodies: Vec<MassProperties> = clouds.iter().map(body_properties).collect();
        let mut mass = TreeMass::new(&tree, bodies).expect("valid bodies");
        let mut a = vec![0.0; n * n];
        mass.mass_matrix(&tree, &ws, &mut a).expect("mass matrix");

        // (8.28): α_kl = Σ m ∂x/∂q_k · ∂x/∂q_l over every point mass.
        let mut reference = DMatrix::<f64>::zeros(n, n);
        let mut jac = vec![0.0; 3 * n];
        let mut t_reference = 0.0;
        let mut total_mass = 0.0;
        let mut com_jac = DMatrix::<f64>::zeros(3, n);
        for (b, cloud) in clouds.iter().enumerate() {
            for (m, p) in cloud {
                tree.point_jacobian(&ws, b, p, &mut jac).expect("jacobian");
                let j = DMatrix::from_column_slice(3, n, &jac);
                reference += *m * j.transpose() * &j;
                com_jac += *m * &j;
                total_mass += *m;
                let v = ws.point_velocity(b, p).expect("velocity");
                t_reference += 0.5 * *m * v.norm_squared();
            }
        }
        com_jac /= total_mass;
        let a_mat = DMatrix::from_column_slice(n, n, &a);
        let scale = reference.amax().max(1.0);
        prop_assert!((&a_mat - &reference).amax() <= 1e-12 * scale,
            "max diff {}", (&a_mat - &reference).amax());
        prop_assert!(a_mat.clone().cholesky().is_some(), "A is not positive definite");

        let mut p = vec![0.0; n];
        let t = mass.momenta_and_energy(&tree, &ws, &q_dot, &mut a, &mut p).expect("energy");
        prop_assert!((t - t_reference).abs() <= 1e-11 * t_reference.max(1.0), "{t} vs {t_reference}");
        let p_reference = &reference * DMatrix::from_column_slice(n, 1, &q_dot);
        for k in 0..n {
            prop_assert!((p[k] - p_reference[k]).abs() <= 1e-11 * scale * 10.0);
        }

        let mut cj = vec![0.0; 3 * n];
        let total = mass.centre_of_mass(&tree, &ws, &mut cj).expect("com");
        prop_assert!((total.mass - total_mass).abs() <= 1e-13 * total_mass);
        let cj = DMatrix::from_column_slice(3, n, &cj);
        prop_assert!((&cj - &com_jac).amax() <= 1e-12 * com_jac.amax().max(1.0));
    }
}

fn vec3() -> impl Strategy<Value = Vector3<f64>> {
    proptest::array::uniform3(-2.0f64..2.0).prop_map(Vector3::from)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// T₀ + T₁ + T₂ (9.7–9.10) on a moving base equals the kinetic energy of the bodies with
    /// their full world velocities (base motion included), computed two independent ways: as
    /// Σ ½ m v² over the point masses, and as Σ (½ m v_c² + ½ ω·J ω) over the rigid bodies
    /// (König, 3.41); each of T₀, b = ∂T₁/∂q̇ and A is checked against its integral definition
    /// evaluated from the point Jacobians and the drag velocity ∂x/∂t.
    #[test]
    fn energy_split_sums_to_the_energy_with_world_velocities(
        specs in proptest::collection::vec(spec(), 1..8),
        seed in proptest::collection::vec(-1.0f64..1.0, 60),
        base_angles in proptest::array::uniform3(-3.0f64..3.0),
        base_position in vec3(), base_omega in vec3(), base_velocity in vec3(),
    ) {
        let (tree, clouds) = build(&specs);
        let n = tree.dof();
        let q: Vec<f64> = (0..n).map(|k| seed[k % seed.len()]).collect();
        let q_dot: Vec<f64> = (0..n).map(|k| seed[(k + 11) % seed.len()] * 2.0).collect();
        let mut ws = tree.workspace();
        ws.set_base(BaseState {
            rotation: Rotation3::from_euler_angles(base_angles[0], base_angles[1], base_angles[2]),
            position: base_position,
            omega: base_omega,
            velocity: base_velocity,
            ..BaseState::default()
        }).expect("finite base");
        tree.update_positions(&mut ws, &q).expect("positions");
        tree.update_velocities(&mut ws, &q_dot).expect("velocities");

        let bodies: Vec<MassProperties> = clouds.iter().map(body_properties).collect();
        let mut mass = TreeMass::new(&tree, bodies.clone()).expect("valid bodies");
        let (mut a, mut b, mut p) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        let split = mass.energy_split(&tree, &ws, &DragField::from(ws.base()), &q_dot, SplitBuffers { mass_matrix: &mut a, b: &mut b, momenta: &mut p }).expect("split");

        // References from the point masses: T, T₀ (9.8), b_k (9.9), A (9.10).
        let (mut t_points, mut t0_ref) = (0.0, 0.0);
        let mut b_ref = vec![0.0; n];
        let mut a_ref = DMatrix::<f64>::zeros(n, n);
        let mut jac = vec![0.0; 3 * n];
        for (body, cloud) in clouds.iter().enumerate() {
            for (m, x) in cloud {
                let v = ws.point_velocity(body, x).expect("velocity");
                let drag = ws.drag_velocity(body, x).expect("drag");
                t_points += 0.5 * m * v.norm_squared();
                t0_ref += 0.5 * m * drag.norm_squared();
                tree.point_jacobian(&ws, body, x, &mut jac).expect("jacobian");
                let j = DMatrix::from_column_slice(3, n, &jac);
                a_ref += *m * j.transpose() * &j;
                for k in 0..n {
                    b_ref[k] += m * (j[(0, k)] * drag.x + j[(1, k)] * drag.y + j[(2, k)] * drag.z);
                }
            }
        }
        // The rigid bodies with world velocities.
        let mut t_bodies = 0.0;
        for (i, body) in bodies.iter().enumerate() {
            let r = ws.rotation(i).expect("rotation");
            let world = body.transformed(&Isometry3::from_parts(
                Translation3::from(ws.position(i).expect("position")),
                UnitQuaternion::from_rotation_matrix(&r),
            ));
            let v_c = ws.point_velocity(i, &body.p_oc).expect("velocity");
            let omega = ws.angular_velocity(i).expect("omega");
            t_bodies += world.kinetic_energy(&v_c, &omega);
        }
        // Each reference is a sum of O(100) products of O(10) terms: 1e-11 relative to the
        // largest energy scale is ~10⁴ ε.
        let scale = t_points.max(t0_ref).max(1.0);
        prop_assert!((split.total() - t_points).abs() <= 1e-11 * scale, "{} vs {t_points}", split.total());
        prop_assert!((split.total() - t_bodies).abs() <= 1e-11 * scale, "{} vs {t_bodies}", split.total());
        prop_assert!((split.t0 - t0_ref).abs() <= 1e-11 * scale);
        let b_scale = b_ref.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for k in 0..n {
            prop_assert!((b[k] - b_ref[k]).abs() <= 1e-11 * b_scale, "b[{k}] {} vs {}", b[k], b_ref[k]);
        }
        let t1_ref: f64 = (0..n).map(|k| b_ref[k] * q_dot[k]).sum();
        prop_assert!((split.t1 - t1_ref).abs() <= 1e-11 * scale);
        let a_mat = DMatrix::from_column_slice(n, n, &a);
        prop_assert!((&a_mat - &a_ref).amax() <= 1e-12 * a_ref.amax().max(1.0));
        let qd = DMatrix::from_column_slice(n, 1, &q_dot);
        let t2_ref = 0.5 * (qd.transpose() * &a_ref * &qd)[(0, 0)];
        prop_assert!((split.t2 - t2_ref).abs() <= 1e-11 * scale);
        // Generalized momenta ∂T/∂q̇ = A q̇ + b.
        let p_ref = &a_ref * &qd;
        for k in 0..n {
            prop_assert!((p[k] - p_ref[k] - b_ref[k]).abs() <= 1e-11 * scale.max(b_scale) * 10.0);
        }
        // A fixed base: T₀ = T₁ = 0 (9.12), and T₂ equals momenta_and_energy's T.
        ws.set_base(BaseState::default()).expect("base");
        tree.update_positions(&mut ws, &q).expect("positions");
        let split = mass.energy_split(&tree, &ws, &DragField::from(ws.base()), &q_dot, SplitBuffers { mass_matrix: &mut a, b: &mut b, momenta: &mut p }).expect("split");
        prop_assert_eq!(split.t0, 0.0);
        prop_assert_eq!(split.t1, 0.0);
        prop_assert!(b.iter().all(|&x| x == 0.0));
        let mut p2 = vec![0.0; n];
        let t = mass.momenta_and_energy(&tree, &ws, &q_dot, &mut a, &mut p2).expect("energy");
        prop_assert_eq!(t, split.t2);
        prop_assert_eq!(p2, p);
    }
}

/// A bead of mass m sliding along a rod (coordinate r) that turns about the vertical z axis at
/// rate Ω while the axis translates with velocity V e_x: x = r e_r(θ), θ = Ωt, so
/// ∂x/∂t = V e_x + rΩ e_θ and ∂x/∂r = e_r, giving T₂ = ½ m ṙ², T₁ = m V cos θ ṙ and
/// T₀ = ½ m (V² − 2 V r Ω sin θ + r² Ω²).
#[test]
fn bead_on_a_rotating_translating_rod_matches_the_closed_form() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let m = 0.7;
    let mut mass = TreeMass::new(&tree, vec![MassProperties::point(m, Vector3::zeros()).expect("bead")]).expect("ok");
    let (omega, v, theta, r, r_dot) = (1.3, 0.4, 0.9, 1.7, -0.6);
    let mut ws = tree.workspace();
    ws.set_base(BaseState {
        rotation: Rotation3::from_axis_angle(&Vector3::z_axis(), theta),
        omega: Vector3::new(0.0, 0.0, omega),
        velocity: Vector3::new(v, 0.0, 0.0),
        ..BaseState::default()
    })
    .expect("base");
    tree.update_positions(&mut ws, &[r]).expect("positions");
    let (mut a, mut b, mut p) = ([0.0], [0.0], [0.0]);
    let split = mass
        .energy_split(
            &tree,
            &ws,
            &DragField::from(ws.base()),
            &[r_dot],
            SplitBuffers {
                mass_matrix: &mut a,
                b: &mut b,
                momenta: &mut p,
            },
        )
        .expect("split");
    let tol = 8.0 * f64::EPSILON;
    let close = |got: f64, expected: f64| (got - expected).abs() <= tol * expected.abs().max(m);
    assert!(close(a[0], m), "A = {}", a[0]);
    assert!(close(split.t2, 0.5 * m * r_dot * r_dot));
    assert!(close(b[0], m * v * theta.cos()), "b = {}", b[0]);
    assert!(close(split.t1, m * v * theta.cos() * r_dot));
    let t0 = 0.5 * m * (v * v - 2.0 * v * r * omega * theta.sin() + r * r * omega * omega);
    assert!(close(split.t0, t0), "T0 = {} vs {t0}", split.t0);
    assert!(close(p[0], m * r_dot + m * v * theta.cos()));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// A(q) does not depend on where the base sits; far from the world origin (1e6) only the
    /// rounding of the body positions (1e6·ε absolute per placement, accumulated over a depth
    /// of at most 6 and a few products) enters, so the matrices agree to 64·1e6·ε relative to
    /// the tree's unit size. A recursion taking moments about the
    /// world origin would lose about 1e12·ε instead.
    #[test]
    fn mass_matrix_keeps_its_accuracy_far_from_the_origin(
        specs in proptest::collection::vec(spec(), 1..7),
        seed in proptest::collection::vec(-1.0f64..1.0, 40),
    ) {
        let (tree, clouds) = build(&specs);
        let n = tree.dof();
        let q: Vec<f64> = (0..n).map(|k| seed[k % seed.len()]).collect();
        let bodies: Vec<MassProperties> = clouds.iter().map(body_properties).collect();
        let mut mass = TreeMass::new(&tree, bodies).expect("valid bodies");
        let mut at = |position: Vector3<f64>| {
            let mut ws = tree.workspace();
            ws.set_base(BaseState { position, ..BaseState::default() }).expect("base");
            tree.update_positions(&mut ws, &q).expect("positions");
            let mut a = vec![0.0; n * n];
            mass.mass_matrix(&tree, &ws, &mut a).expect("mass matrix");
            DMatrix::from_column_slice(n, n, &a)
        };
        let near = at(Vector3::zeros());
        let far = at(Vector3::new(1e6, -1e6, 1e6));
        let tol = 64.0 * 1e6 * f64::EPSILON * near.amax().max(1.0);
        prop_assert!((&far - &near).amax() <= tol, "{} > {tol}", (&far - &near).amax());
    }
}

#[test]
fn wrong_lengths_are_named() {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::z() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(1.0, Vector3::x()).expect("point");
    assert!(matches!(
        TreeMass::new(&tree, vec![body, body]),
        Err(mechanica_mass::MassError::WrongLength {
            expected: 1,
            got: 2,
            ..
        })
    ));
    // A bad body is named by its index.
    let mut nan = body;
    nan.inertia_c[(0, 1)] = f64::NAN;
    let err = TreeMass::new(&tree, vec![nan]).expect_err("NaN inertia");
    assert!(matches!(&err, mechanica_mass::MassError::Body { body: 0, .. }), "{err}");
    assert!(
        err.to_string().starts_with("body 0: body inertia is not finite"),
        "{err}"
    );
    let mut negative = body;
    negative.mass = -1.0;
    assert!(matches!(
        TreeMass::new(&tree, vec![negative]),
        Err(mechanica_mass::MassError::Body { body: 0, .. })
    ));
    let mut mass = TreeMass::new(&tree, vec![body]).expect("ok");
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &[0.3]).expect("positions");
    let mut a = vec![0.0; 4];
    assert!(matches!(
        mass.mass_matrix(&tree, &ws, &mut a),
        Err(mechanica_mass::MassError::WrongLength {
            expected: 1,
            got: 4,
            ..
        })
    ));
    // Pendulum: a point mass 1 at distance 1 from a revolute axis: A = m r² = 1.
    let mut a = vec![0.0; 1];
    mass.mass_matrix(&tree, &ws, &mut a).expect("ok");
    assert!((a[0] - 1.0).abs() <= 1e-15);
}

/// A chain of three revolute joints about z with unit links along x: bodies of mass `masses`
/// at the end of each link.
fn planar_chain(masses: [f64; 3], link: f64) -> (KinematicTree, Vec<MassProperties>) {
    let mut builder = TreeBuilder::new();
    let mut parent = None;
    for i in 0..3 {
        let offset = if i == 0 { Vector3::zeros() } else { Vector3::x() * link };
        let placement = Isometry3::from_parts(Translation3::from(offset), UnitQuaternion::identity());
        parent = Some(builder.add_body(parent, Joint::Revolute { axis: Vector3::z() }, placement));
    }
    let bodies = masses
        .iter()
        .map(|&m| MassProperties {
            mass: m,
            p_oc: Vector3::x() * link,
            inertia_c: nalgebra::Matrix3::zeros(),
        })
        .collect();
    (builder.build().expect("valid tree"), bodies)
}

/// A massless last body adds exact zeros; the entries match the closed form of point masses on
/// a straight chain (α_kl = Σ_{b ≥ max(k,l)} m_b (x_b − x_k)·(x_b − x_l) along the line).
#[test]
fn massless_bodies_add_nothing_and_point_masses_match_the_closed_form() {
    for masses in [[1.0, 2.0, 0.0], [0.0, 0.0, 3.0], [1e-12, 1.0, 1e12]] {
        let (tree, bodies) = planar_chain(masses, 0.5);
        let mut ws = tree.workspace();
        tree.update_positions(&mut ws, &[0.0; 3]).expect("positions");
        let mut mass = TreeMass::new(&tree, bodies).expect("valid bodies");
        let mut a = vec![0.0; 9];
        mass.mass_matrix(&tree, &ws, &mut a).expect("mass matrix");
        // Body b sits at x = 0.5 (b + 1); joint k at x = 0.5 k.
        for k in 0..3 {
            for l in 0..3 {
                let expected: f64 = (k.max(l)..3)
                    .map(|b| masses[b] * (0.5 * (b + 1 - k) as f64) * (0.5 * (b + 1 - l) as f64))
                    .sum();
                let scale: f64 = masses.iter().sum::<f64>() * 2.25;
                assert!(
                    (a[k + 3 * l] - expected).abs() <= 8.0 * f64::EPSILON * scale,
                    "{masses:?}: α[{k}][{l}] = {} against {expected}",
                    a[k + 3 * l]
                );
                if masses[k.max(l)..].iter().all(|&m| m == 0.0) {
                    assert_eq!(a[k + 3 * l], 0.0, "{masses:?}: α[{k}][{l}] of a massless subtree");
                }
            }
        }
    }
}

/// Entries beyond the double range are a typed error, not ∞ or NaN.
#[test]
fn an_overflowing_mass_matrix_is_a_typed_error() {
    let (tree, bodies) = planar_chain([1.0, 1.0, 1e300], 1e10);
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &[0.0; 3]).expect("positions");
    let mut mass = TreeMass::new(&tree, bodies).expect("valid bodies");
    let mut a = vec![0.0; 9];
    let result = mass.mass_matrix(&tree, &ws, &mut a);
    assert!(
        matches!(
            result,
            Err(mechanica_mass::MassError::NonFiniteResult {
                quantity: "mass matrix"
            })
        ),
        "{result:?}"
    );
}
