//! The composite-rigid-body mass matrix against the definition (8.28) evaluated from point
//! Jacobians of point masses, and the kinetic energy against point velocities from the
//! kinematics crate's velocity recursion.

use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mass::mechanism::TreeMass;
use nalgebra::{DMatrix, Isometry3, Translation3, UnitQuaternion, Vector3};
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
