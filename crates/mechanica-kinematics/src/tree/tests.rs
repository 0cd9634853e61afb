//! Tests of kinematic trees: closed forms, Jacobians against central differences of forward
//! kinematics on random trees, time derivatives, base motion and bad input.

use super::*;
use crate::rotation::{log_map, skew};
use nalgebra::{Translation3, UnitQuaternion};
use proptest::prelude::*;

const EPS: f64 = f64::EPSILON;

/// A small deterministic generator (xorshift64*), so that proptest only has to shrink a seed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn vec3(&mut self, s: f64) -> Vector3<f64> {
        Vector3::new(self.uniform(-s, s), self.uniform(-s, s), self.uniform(-s, s))
    }
    fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = self.vec3(1.0);
            if v.norm() > 0.1 {
                return v.normalize();
            }
        }
    }
}

/// Link length bound of the random trees: every placement translation has |p| ≤ √3·0.5 and
/// prismatic/free/planar translations |q| ≤ √3, so |x − o_i| ≤ depth · LINK for any body point.
const LINK: f64 = 0.5 * 1.8 + 1.8;

fn random_tree(seed: u64, n: usize) -> (KinematicTree, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = Rng(seed.max(1));
    let mut b = TreeBuilder::new();
    for i in 0..n {
        let parent = if i == 0 {
            None
        } else {
            Some((rng.next() % i as u64) as usize)
        };
        let joint = match rng.next() % 6 {
            0 | 1 => Joint::Revolute { axis: rng.unit() },
            2 => Joint::Prismatic { axis: rng.unit() },
            3 => Joint::Spherical,
            4 => {
                if i == 0 {
                    Joint::Free
                } else {
                    Joint::Planar
                }
            }
            _ => Joint::Fixed,
        };
        let placement = Isometry3::from_parts(
            Translation3::from(rng.vec3(0.5)),
            UnitQuaternion::from_scaled_axis(rng.vec3(2.0)),
        );
        b.add_body(parent, joint, placement);
    }
    let tree = b.build().expect("valid random tree");
    let nv = tree.dof();
    let q = (0..nv).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let qd = (0..nv).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let qdd = (0..nv).map(|_| rng.uniform(-1.0, 1.0)).collect();
    (tree, q, qd, qdd)
}

fn point_world(tree: &KinematicTree, ws: &mut Workspace, q: &[f64], body: usize, p: &Vector3<f64>) -> Vector3<f64> {
    tree.update_positions(ws, q).expect("valid q");
    ws.point_position(body, p).expect("body exists")
}

fn rotation_world(tree: &KinematicTree, ws: &mut Workspace, q: &[f64], body: usize) -> Rotation3<f64> {
    tree.update_positions(ws, q).expect("valid q");
    ws.rotation(body).expect("body exists")
}

fn col(m: &[f64], k: usize) -> Vector3<f64> {
    Vector3::new(m[3 * k], m[3 * k + 1], m[3 * k + 2])
}

#[test]
fn planar_two_link_arm_closed_form() {
    // Two revolute joints about z, links l1 along x of body 0 and l2 along x of body 1.
    let (l1, l2) = (0.7, 0.4);
    let mut b = TreeBuilder::new();
    let z = Vector3::z();
    let b0 = b.add_body(None, Joint::Revolute { axis: z }, Isometry3::identity());
    let b1 = b.add_body(
        Some(b0),
        Joint::Revolute { axis: z },
        Isometry3::translation(l1, 0.0, 0.0),
    );
    let tree = b.build().expect("valid");
    let mut ws = tree.workspace();
    let (t1, t2, w1, w2, a1, a2) = (0.3, -1.1, 0.8, 1.7, -0.4, 0.9);
    tree.update_positions(&mut ws, &[t1, t2]).expect("ok");
    tree.update_velocities(&mut ws, &[w1, w2]).expect("ok");
    tree.update_accelerations(&mut ws, &[a1, a2]).expect("ok");
    let tip = Vector3::new(l2, 0.0, 0.0);
    let x = ws.point_position(b1, &tip).expect("ok");
    let (s1, c1, s12, c12) = (t1.sin(), t1.cos(), (t1 + t2).sin(), (t1 + t2).cos());
    assert!((x - Vector3::new(l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0.0)).norm() < 4.0 * EPS);
    let mut j = vec![0.0; 6];
    tree.point_jacobian(&ws, b1, &tip, &mut j).expect("ok");
    let j_exact = [-l1 * s1 - l2 * s12, l1 * c1 + l2 * c12, 0.0, -l2 * s12, l2 * c12, 0.0];
    for (a, e) in j.iter().zip(j_exact) {
        assert!((a - e).abs() < 4.0 * EPS);
    }
    // ẍ = J q̈ + J̇ q̇ with J̇ in closed form.
    let w12 = w1 + w2;
    let acc = ws.point_acceleration(b1, &tip).expect("ok");
    let ax = -l1 * (c1 * w1 * w1 + s1 * a1) - l2 * (c12 * w12 * w12 + s12 * (a1 + a2));
    let ay = l1 * (-s1 * w1 * w1 + c1 * a1) + l2 * (-s12 * w12 * w12 + c12 * (a1 + a2));
    assert!((acc - Vector3::new(ax, ay, 0.0)).norm() < 16.0 * EPS);
    assert!((ws.angular_velocity(b1).expect("ok") - Vector3::new(0.0, 0.0, w12)).norm() < 4.0 * EPS);
    assert!((ws.angular_acceleration(b1).expect("ok") - Vector3::new(0.0, 0.0, a1 + a2)).norm() < 4.0 * EPS);
}

/// Checks Jacobians, Jacobian rates, velocities and accelerations of every body of a tree
/// against central differences of forward kinematics.
fn check_against_finite_differences(tree: &KinematicTree, q: &[f64], qd: &[f64], qdd: &[f64]) {
    let nv = tree.dof();
    let mut ws = tree.workspace();
    let mut fd_ws = tree.workspace();
    tree.update_positions(&mut ws, q).expect("ok");
    tree.update_velocities(&mut ws, qd).expect("ok");
    tree.update_accelerations(&mut ws, qdd).expect("ok");
    let p = Vector3::new(0.3, -0.2, 0.25);
    let mut j = vec![0.0; 3 * nv];
    let mut jw = vec![0.0; 3 * nv];
    let mut jd = vec![0.0; 3 * nv];
    let mut jwd = vec![0.0; 3 * nv];
    let mut j6 = vec![0.0; 6 * nv];
    for body in 0..tree.body_count() {
        tree.point_jacobian(&ws, body, &p, &mut j).expect("ok");
        tree.angular_jacobian(&ws, body, &mut jw).expect("ok");
        tree.point_jacobian_rate(&ws, body, &p, &mut jd).expect("ok");
        tree.angular_jacobian_rate(&ws, body, &mut jwd).expect("ok");
        tree.body_jacobian(&ws, body, &p, &mut j6).expect("ok");
        // Error budget of a central difference with step h on a function whose third
        // derivative is bounded by C·L (L = lever arm ≤ (depth + 2)·LINK, C ≤ 8 for chains of
        // rotations with |q| ≤ 1 and exp-coordinate Jacobians): C·L·h²/6 + eps·|x|/h.
        let depth = tree.depth(body).expect("ok") as f64 + 2.0;
        let scale = depth * LINK;
        let h = 1e-5;
        let tol = 8.0 * scale * (h * h + 4.0 * EPS / h) * depth;
        let mut qp = q.to_vec();
        for k in 0..nv {
            qp[k] = q[k] + h;
            let xp = point_world(tree, &mut fd_ws, &qp, body, &p);
            let rp = rotation_world(tree, &mut fd_ws, &qp, body);
            qp[k] = q[k] - h;
            let xm = point_world(tree, &mut fd_ws, &qp, body, &p);
            let rm = rotation_world(tree, &mut fd_ws, &qp, body);
            qp[k] = q[k];
            let dx = (xp - xm) / (2.0 * h);
            let dw = log_map(&(rp * rm.inverse())) / (2.0 * h);
            assert!(
                (col(&j, k) - dx).norm() < tol,
                "body {body} dof {k}: {} vs {dx}",
                col(&j, k)
            );
            assert!((col(&jw, k) - dw).norm() < tol, "body {body} dof {k}: ω column");
            for r in 0..3 {
                assert_eq!(j6[6 * k + r], jw[3 * k + r]);
                assert_eq!(j6[6 * k + 3 + r], j[3 * k + r]);
            }
        }
        // J̇ against differences of J along q(t) = q + t q̇ (1.41: d/dt ∂x/∂q_k = ∂ẋ/∂q_k).
        let mut jp = vec![0.0; 3 * nv];
        let mut jm = vec![0.0; 3 * nv];
        let mut jwp = vec![0.0; 3 * nv];
        let mut jwm = vec![0.0; 3 * nv];
        let qplus: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + h * b).collect();
        let qminus: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a - h * b).collect();
        tree.update_positions(&mut fd_ws, &qplus).expect("ok");
        tree.point_jacobian(&fd_ws, body, &p, &mut jp).expect("ok");
        tree.angular_jacobian(&fd_ws, body, &mut jwp).expect("ok");
        tree.update_positions(&mut fd_ws, &qminus).expect("ok");
        tree.point_jacobian(&fd_ws, body, &p, &mut jm).expect("ok");
        tree.angular_jacobian(&fd_ws, body, &mut jwm).expect("ok");
        let qd_norm = qd.iter().map(|v| v * v).sum::<f64>().sqrt();
        let tol_rate = tol * (1.0 + qd_norm * qd_norm * qd_norm);
        for k in 0..nv {
            let fd = (col(&jp, k) - col(&jm, k)) / (2.0 * h);
            assert!(
                (col(&jd, k) - fd).norm() < tol_rate,
                "body {body} dof {k}: J̇ {} vs {fd}",
                col(&jd, k)
            );
            let fdw = (col(&jwp, k) - col(&jwm, k)) / (2.0 * h);
            assert!((col(&jwd, k) - fdw).norm() < tol_rate, "body {body} dof {k}: J̇ω");
        }
        // Velocity and acceleration consistency: ẋ = J q̇, ẍ = J q̈ + J̇ q̇, ω = J_ω q̇.
        let (mut v, mut a, mut w, mut bias) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        for k in 0..nv {
            v += col(&j, k) * qd[k];
            w += col(&jw, k) * qd[k];
            a += col(&j, k) * qdd[k] + col(&jd, k) * qd[k];
            bias += col(&jd, k) * qd[k];
        }
        let mag = scale * depth * (1.0 + qd_norm * qd_norm);
        assert!((ws.point_velocity(body, &p).expect("ok") - v).norm() < 64.0 * EPS * mag);
        assert!((ws.angular_velocity(body).expect("ok") - w).norm() < 64.0 * EPS * mag);
        assert!((ws.point_acceleration(body, &p).expect("ok") - a).norm() < 64.0 * EPS * mag * (1.0 + qd_norm));
        let b = tree.point_bias_acceleration(&ws, body, &p).expect("ok");
        assert!((b - bias).norm() < 64.0 * EPS * mag * (1.0 + qd_norm));
    }
}

#[test]
fn acceleration_matches_second_differences_of_x_of_t() {
    // x(t) = FK(q + t q̇ + t²/2 q̈): ẍ(0) by a second central difference, step h = 1e-4:
    // truncation h²/12·|x''''| and rounding 4 eps |x| / h².
    let (tree, q, qd, qdd) = random_tree(0xDEADBEEF, 12);
    let nv = tree.dof();
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &q).expect("ok");
    tree.update_velocities(&mut ws, &qd).expect("ok");
    tree.update_accelerations(&mut ws, &qdd).expect("ok");
    let mut fd = tree.workspace();
    let h = 1e-4;
    let at = |t: f64| -> Vec<f64> { (0..nv).map(|k| q[k] + t * qd[k] + 0.5 * t * t * qdd[k]).collect() };
    let p = Vector3::new(0.1, 0.2, -0.3);
    for body in 0..tree.body_count() {
        let x0 = point_world(&tree, &mut fd, &at(0.0), body, &p);
        let xp = point_world(&tree, &mut fd, &at(h), body, &p);
        let xm = point_world(&tree, &mut fd, &at(-h), body, &p);
        let scale = (tree.depth(body).expect("ok") as f64 + 2.0) * LINK;
        let v_fd = (xp - xm) / (2.0 * h);
        let a_fd = (xp - 2.0 * x0 + xm) / (h * h);
        let tol = 1e3 * scale * (h * h + 4.0 * EPS / (h * h));
        assert!((ws.point_velocity(body, &p).expect("ok") - v_fd).norm() < tol);
        assert!(
            (ws.point_acceleration(body, &p).expect("ok") - a_fd).norm() < tol,
            "body {body}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn jacobians_match_central_differences_on_random_trees(seed in 1u64..u64::MAX, n in 1usize..=50) {
        let (tree, q, qd, qdd) = random_tree(seed, n);
        check_against_finite_differences(&tree, &q, &qd, &qdd);
    }
}

/// A tree of `n` bodies whose parents are drawn at random among bodies of any index (numbered
/// by a random permutation of a parents-first order), with joints of every coordinate count.
fn randomly_numbered_tree(rng: &mut Rng, n: usize) -> KinematicTree {
    let mut label: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        label.swap(i, (rng.next() % (i as u64 + 1)) as usize);
    }
    let mut specs = vec![None; n];
    for created in 0..n {
        let parent = (created > 0).then(|| label[(rng.next() % created as u64) as usize]);
        let joint = match rng.next() % 5 {
            0 => Joint::Revolute { axis: rng.unit() },
            1 => Joint::Spherical,
            2 if created == 0 => Joint::Free,
            2 => Joint::Planar,
            3 => Joint::Fixed,
            _ => Joint::Prismatic { axis: rng.unit() },
        };
        specs[label[created]] = Some((parent, joint));
    }
    let mut b = TreeBuilder::new();
    for (parent, joint) in specs.into_iter().flatten() {
        b.add_body(parent, joint, Isometry3::identity());
    }
    b.build().expect("valid random tree")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn previous_dofs_walk_exactly_the_carriers_of_each_coordinate(seed in 1u64..u64::MAX, n in 1usize..=30) {
        let tree = randomly_numbered_tree(&mut Rng(seed), n);
        let body = |k: usize| tree.dof_body(k).expect("coordinate in range");
        for k in 0..tree.dof() {
            let mut walked = Vec::new();
            let mut next = Some(k);
            while let Some(l) = next {
                prop_assert!(walked.len() <= tree.dof(), "the walk from {} does not end", k);
                walked.push(l);
                next = tree.previous_dof(l);
            }
            walked.sort_unstable();
            let carriers: Vec<usize> = (0..tree.dof())
                .filter(|&l| tree.is_ancestor_or_self(body(l), body(k)) && (body(l) != body(k) || l <= k))
                .collect();
            prop_assert_eq!(walked, carriers, "coordinate {}", k);
        }
        prop_assert_eq!(tree.previous_dof(tree.dof()), None);
    }
}

#[test]
fn a_fifty_joint_tree_with_every_joint_type() {
    let (tree, q, qd, qdd) = random_tree(42, 50);
    check_against_finite_differences(&tree, &q, &qd, &qdd);
}

#[test]
fn steady_base_rotation_gives_drag_velocities() {
    // A pendulum on a turntable (§8e): base spins at Ω about z. With q̇ = 0 every point moves
    // with the drag velocity Ω e_z × x, and ∂x/∂t by differences in t equals it.
    let mut b = TreeBuilder::new();
    let r = b.add_body(
        None,
        Joint::Revolute { axis: Vector3::x() },
        Isometry3::translation(0.5, 0.0, 1.0),
    );
    b.add_body(Some(r), Joint::Spherical, Isometry3::translation(0.0, 0.0, -0.8));
    let tree = b.build().expect("valid");
    let motion = SteadyRotation {
        axis: Vector3::z_axis(),
        rate: 1.3,
    };
    let q = [0.4, 0.1, -0.2, 0.3];
    let zero = [0.0; 4];
    let p = Vector3::new(0.0, 0.1, -0.3);
    let t = 0.7;
    let mut ws = tree.workspace();
    ws.set_base(motion.state_at(t)).expect("finite");
    tree.update_positions(&mut ws, &q).expect("ok");
    tree.update_velocities(&mut ws, &zero).expect("ok");
    tree.update_accelerations(&mut ws, &zero).expect("ok");
    let x = ws.point_position(1, &p).expect("ok");
    let drag = ws.drag_velocity(1, &p).expect("ok");
    assert!((drag - Vector3::new(0.0, 0.0, 1.3).cross(&x)).norm() < 8.0 * EPS);
    assert!((ws.point_velocity(1, &p).expect("ok") - drag).norm() < 8.0 * EPS);
    // Centripetal acceleration −Ω² (x_x, x_y, 0).
    let a = ws.point_acceleration(1, &p).expect("ok");
    assert!((a + 1.69 * Vector3::new(x.x, x.y, 0.0)).norm() < 32.0 * EPS);
    let h = 1e-5;
    let mut fd = tree.workspace();
    let mut x_at = |s: f64| {
        fd.set_base(motion.state_at(s)).expect("finite");
        tree.update_positions(&mut fd, &q).expect("ok");
        fd.point_position(1, &p).expect("ok")
    };
    let dxdt = (x_at(t + h) - x_at(t - h)) / (2.0 * h);
    assert!((dxdt - drag).norm() < 10.0 * (h * h + EPS / h) * 2.0);
}

#[test]
fn rebase_keeps_poses_and_velocities() {
    let (mut tree, mut q, mut qd, _) = random_tree(7, 20);
    for v in q.iter_mut() {
        *v *= 2.5;
    }
    let mut before = tree.workspace();
    tree.update_positions(&mut before, &q).expect("ok");
    tree.update_velocities(&mut before, &qd).expect("ok");
    tree.rebase(&mut q, &mut qd).expect("ok");
    let mut after = tree.workspace();
    tree.update_positions(&mut after, &q).expect("ok");
    tree.update_velocities(&mut after, &qd).expect("ok");
    for body in 0..tree.body_count() {
        let dr = (before.rotation(body).expect("ok").matrix() - after.rotation(body).expect("ok").matrix()).norm();
        assert!(dr < 1e-13, "body {body}: {dr}");
        assert!((before.position(body).expect("ok") - after.position(body).expect("ok")).norm() < 1e-12);
        assert!(
            (before.angular_velocity(body).expect("ok") - after.angular_velocity(body).expect("ok")).norm() < 1e-12
        );
        assert!((before.origin_velocity(body).expect("ok") - after.origin_velocity(body).expect("ok")).norm() < 1e-12);
        if tree.joint(body).expect("ok").has_rotation_vector() {
            let r = tree.dof_range(body);
            let o = tree.joint(body).expect("ok").rotation_offset();
            assert!(q[r.start + o..r.start + o + 3].iter().all(|&v| v == 0.0));
        }
    }
}

#[test]
fn forward_parent_references_are_allowed() {
    // Child added before its parent; the topological order puts the parent first.
    let mut b = TreeBuilder::new();
    let child = b.add_body(
        Some(1),
        Joint::Revolute { axis: Vector3::y() },
        Isometry3::translation(1.0, 0.0, 0.0),
    );
    let root = b.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
    let tree = b.build().expect("valid");
    assert_eq!(tree.topological_order(), &[root, child]);
    assert_eq!(tree.parent(child), Some(root));
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, &[0.0, 2.0]).expect("ok");
    assert!((ws.position(child).expect("ok") - Vector3::new(3.0, 0.0, 0.0)).norm() < 4.0 * EPS);
    assert_eq!(tree.dof_range(child), 0..1);
    assert_eq!(tree.dof_body(1), Some(root));
    assert!(tree.is_ancestor_or_self(root, child));
    assert!(!tree.is_ancestor_or_self(child, root));
    assert_eq!(skew(&Vector3::x()) * Vector3::y(), Vector3::z());
}

#[test]
fn bad_trees_are_typed_errors() {
    let id = Isometry3::identity();
    let rev = |axis| Joint::Revolute { axis };
    assert_eq!(TreeBuilder::new().build(), Err(KinematicsError::EmptyTree));
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, id);
    b.add_body(Some(0), rev(Vector3::new(0.0, 0.0, 2.0)), id);
    assert_eq!(b.build(), Err(KinematicsError::JointAxisNotUnit { body: 1, norm: 2.0 }));
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Prismatic { axis: Vector3::zeros() }, id);
    assert_eq!(b.build(), Err(KinematicsError::JointAxisNotUnit { body: 0, norm: 0.0 }));
    let mut b = TreeBuilder::new();
    b.add_body(None, rev(Vector3::new(f64::NAN, 0.0, 1.0)), id);
    assert!(matches!(
        b.build(),
        Err(KinematicsError::NonFiniteEntry { index: 0, .. })
    ));
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, Isometry3::translation(0.0, f64::INFINITY, 0.0));
    assert!(matches!(
        b.build(),
        Err(KinematicsError::NonFiniteEntry {
            what: "body placement",
            index: 0,
            ..
        })
    ));
    // Two roots = disconnected.
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, id);
    b.add_body(None, Joint::Fixed, id);
    assert_eq!(b.build(), Err(KinematicsError::MultipleRoots { first: 0, second: 1 }));
    // Cycle 1 → 2 → 1 beside the root 0; also a body hanging below the cycle.
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, id);
    b.add_body(Some(2), Joint::Fixed, id);
    b.add_body(Some(1), Joint::Fixed, id);
    assert_eq!(b.build(), Err(KinematicsError::Cycle { body: 1 }));
    let mut b = TreeBuilder::new();
    b.add_body(Some(0), Joint::Fixed, id);
    assert_eq!(b.build(), Err(KinematicsError::NoRoot));
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, id);
    b.add_body(Some(5), Joint::Fixed, id);
    assert_eq!(
        b.build(),
        Err(KinematicsError::ParentOutOfRange {
            body: 1,
            parent: 5,
            bodies: 2
        })
    );
    // Self-parent is a cycle.
    let mut b = TreeBuilder::new();
    b.add_body(None, Joint::Fixed, id);
    b.add_body(Some(1), Joint::Fixed, id);
    assert_eq!(b.build(), Err(KinematicsError::Cycle { body: 1 }));
}

#[test]
fn bad_states_are_typed_errors() {
    let (tree, q, qd, _) = random_tree(3, 6);
    let nv = tree.dof();
    let mut ws = tree.workspace();
    assert!(matches!(
        tree.update_velocities(&mut ws, &qd),
        Err(KinematicsError::WorkspaceNotReady { .. })
    ));
    assert!(matches!(ws.position(0), Err(KinematicsError::WorkspaceNotReady { .. })));
    assert_eq!(
        tree.update_positions(&mut ws, &q[..nv - 1]),
        Err(KinematicsError::WrongLength {
            what: "q",
            expected: nv,
            got: nv - 1
        })
    );
    let mut bad = q.clone();
    bad[nv - 1] = f64::NAN;
    assert!(matches!(
        tree.update_positions(&mut ws, &bad),
        Err(KinematicsError::NonFiniteEntry { what: "q", index, .. }) if index == nv - 1
    ));
    tree.update_positions(&mut ws, &q).expect("ok");
    let mut bad = qd.clone();
    bad[0] = f64::INFINITY;
    assert!(matches!(
        tree.update_velocities(&mut ws, &bad),
        Err(KinematicsError::NonFiniteEntry {
            what: "q_dot",
            index: 0,
            ..
        })
    ));
    assert!(matches!(
        tree.update_velocities(&mut ws, &qd[1..]),
        Err(KinematicsError::WrongLength { what: "q_dot", .. })
    ));
    let mut j = vec![0.0; 3 * nv];
    assert_eq!(
        tree.point_jacobian(&ws, 99, &Vector3::zeros(), &mut j),
        Err(KinematicsError::BodyOutOfRange { body: 99, bodies: 6 })
    );
    assert!(matches!(
        tree.point_jacobian(&ws, 0, &Vector3::zeros(), &mut j[1..]),
        Err(KinematicsError::WrongLength { .. })
    ));
    assert!(matches!(
        tree.point_jacobian_rate(&ws, 0, &Vector3::zeros(), &mut j),
        Err(KinematicsError::WorkspaceNotReady { .. })
    ));
    let (other, _, _, _) = random_tree(4, 9);
    let mut other_ws = other.workspace();
    assert!(matches!(
        tree.update_positions(&mut other_ws, &q),
        Err(KinematicsError::WorkspaceNotReady { .. })
    ));
    let mut base = BaseState::default();
    base.omega.x = f64::NAN;
    assert!(ws.set_base(base).is_err());
}
