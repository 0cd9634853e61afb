//! Criterion benchmarks: kinematic trees.
//!
//! Forward kinematics (all body poses plus every joint's world motion column, i.e. what
//! Pinocchio's `computeJointJacobians` produces) and forward kinematics plus the 6×nv
//! Jacobian of every body, on the same models as `tools/kinematics_pinocchio_bench.py`:
//! - `arm7`: 7 revolute joints, axes z y z y z y z, links 0.3 m;
//! - `humanoid34`: Pinocchio's `buildSampleModelHumanoid` topology (free flyer + 28 revolute);
//! - `humanoid44`: free flyer + 43 revolute joints (legs, chest, head, arms, fingers).
//!
//! Peer numbers (Pinocchio from Python) are in `tools/kinematics_pinocchio_bench.txt`.

use criterion::{Criterion, criterion_group, criterion_main};
use mechanica::kinematics::nalgebra::{Isometry3, Vector3};
use mechanica::kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use std::hint::black_box;

fn axis(c: char) -> Joint {
    let a = match c {
        'x' => Vector3::x(),
        'y' => Vector3::y(),
        _ => Vector3::z(),
    };
    Joint::Revolute { axis: a }
}

fn chain(b: &mut TreeBuilder, parent: usize, axes: &str, offset: [f64; 3]) -> usize {
    let mut p = parent;
    for (i, c) in axes.chars().enumerate() {
        let t = if i == 0 { offset } else { [0.0, 0.0, -0.25] };
        p = b.add_body(Some(p), axis(c), Isometry3::translation(t[0], t[1], t[2]));
    }
    p
}

fn arm7() -> KinematicTree {
    let mut b = TreeBuilder::new();
    let mut p = None;
    for c in "zyzyzyz".chars() {
        p = Some(b.add_body(p, axis(c), Isometry3::translation(0.0, 0.0, 0.3)));
    }
    b.build().expect("valid arm")
}

fn humanoid(chest_axes: &str, arm_axes: &str, fingers: bool) -> KinematicTree {
    let mut b = TreeBuilder::new();
    let root = b.add_body(None, Joint::Free, Isometry3::identity());
    chain(&mut b, root, "xyzyxy", [0.0, -0.1, -0.1]);
    chain(&mut b, root, "xyzyxy", [0.0, 0.1, -0.1]);
    let chest = chain(&mut b, root, chest_axes, [0.0, 0.0, 0.1]);
    chain(&mut b, chest, "xy", [0.0, 0.0, 0.3]);
    for y in [-0.2, 0.2] {
        let hand = chain(&mut b, chest, arm_axes, [0.0, y, 0.25]);
        if fingers {
            for f in 0..3 {
                chain(&mut b, hand, "yy", [0.02 * f64::from(f), 0.0, -0.05]);
            }
        }
    }
    b.build().expect("valid humanoid")
}

fn configuration(n: usize) -> Vec<f64> {
    (0..n).map(|i| ((i as f64) * 0.7).sin()).collect()
}

fn bench_tree(c: &mut Criterion, name: &str, tree: &KinematicTree) {
    let nv = tree.dof();
    let q = configuration(nv);
    let mut ws = tree.workspace();
    let mut group = c.benchmark_group(format!("kinematics/{name} (nv = {nv}, bodies = {})", tree.body_count()));
    group.bench_function("forward kinematics + joint columns", |bch| {
        bch.iter(|| {
            tree.update_positions(&mut ws, black_box(&q)).expect("valid q");
            black_box(&ws);
        })
    });
    let mut jac = vec![0.0; 6 * nv * tree.body_count()];
    let origin = Vector3::zeros();
    group.bench_function("forward kinematics + all body Jacobians", |bch| {
        bch.iter(|| {
            tree.update_positions(&mut ws, black_box(&q)).expect("valid q");
            for (body, out) in jac.chunks_exact_mut(6 * nv).enumerate() {
                tree.body_jacobian(&ws, body, &origin, out).expect("valid body");
            }
            black_box(&jac);
        })
    });
    group.finish();
}

fn kinematics(c: &mut Criterion) {
    bench_tree(c, "arm7", &arm7());
    bench_tree(c, "humanoid34", &humanoid("xy", "xyzyxy", false));
    bench_tree(c, "humanoid44", &humanoid("xyz", "xyzyxyz", true));
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
