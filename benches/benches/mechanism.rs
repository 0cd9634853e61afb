//! Criterion benchmarks: modes of a whole mechanism.
//!
//! A 44-DOF tree: a torso fixed to the ground carrying two legs of 6 joints, two arms of 7, a
//! head of 2 and four fingers of 4 (44 revolute joints, axes cycling x, y, z), rod links of
//! 0.25 m and 1 kg, a torsional spring of 50 N·m/rad in every joint, and gravity. Steps:
//! - `assemble_a`: A(q) by the composite-rigid-body recursion (8.28);
//! - `assemble_b`: U*, its gradient and its exact Hessian B(q) (8.85);
//! - `modes_all`: A, B, the dense solve of every mode with its accuracy report, body
//!   displacements and effective masses (`mechanism_modes`).
//!
//! There is no peer that computes the modes of a mechanism from its description; the
//! building blocks are compared elsewhere (A(q) against Pinocchio in `kinematics`/`mass`, the
//! dense pencil solve against LAPACK in `modal`).

use criterion::{Criterion, criterion_group, criterion_main};
use mechanica::kinematics::nalgebra::{Isometry3, Vector3};
use mechanica::kinematics::tree::{Joint, TreeBuilder};
use mechanica::mass::primitives::{Amount, rod};
use mechanica::mechanism::potentials::JointSpring;
use mechanica::mechanism::{Mechanism, mechanism_modes};
use mechanica::modal::SolveOptions;
use std::hint::black_box;

/// Branches of (length) joints hanging from a fixed torso; 44 joints in all.
fn humanoid44() -> Mechanism {
    let mut builder = TreeBuilder::new();
    let torso = builder.add_body(None, Joint::Fixed, Isometry3::identity());
    let branches = [6, 6, 7, 7, 2, 4, 4, 4, 4];
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    let mut count = 0;
    for (b, &length) in branches.iter().enumerate() {
        let angle = b as f64 * 0.7;
        let mut parent = torso;
        for j in 0..length {
            let offset = if j == 0 {
                Isometry3::translation(0.2 * angle.cos(), 0.2 * angle.sin(), 0.0)
            } else {
                Isometry3::translation(0.0, 0.0, -0.25)
            };
            parent = builder.add_body(Some(parent), Joint::Revolute { axis: axes[count % 3] }, offset);
            count += 1;
        }
    }
    let tree = builder.build().expect("tree");
    let mut link = rod(0.25, Amount::Mass(1.0)).expect("rod");
    link.p_oc = Vector3::new(0.0, 0.0, -0.125);
    let mut bodies = vec![link; tree.body_count()];
    bodies[0] = rod(0.4, Amount::Mass(10.0)).expect("torso");
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    for k in 0..mechanism.dof() {
        mechanism
            .add_potential(JointSpring {
                coordinate: k,
                stiffness: 50.0,
                rest: 0.0,
            })
            .expect("spring");
    }
    mechanism
}

fn bench(c: &mut Criterion) {
    let mut mechanism = humanoid44();
    let n = mechanism.dof();
    assert_eq!(n, 44);
    let q: Vec<f64> = (0..n).map(|k| 0.1 * ((k as f64) * 0.37).sin()).collect();
    let mut group = c.benchmark_group("mechanism_44dof");
    group.bench_function("assemble_a", |b| {
        b.iter(|| black_box(mechanism.mass_matrix(black_box(&q)).expect("A")))
    });
    group.bench_function("assemble_b", |b| {
        b.iter(|| black_box(mechanism.potential(black_box(&q), true).expect("B")))
    });
    group.bench_function("modes_all", |b| {
        b.iter(|| black_box(mechanism_modes(&mut mechanism, black_box(&q), &SolveOptions::default()).expect("modes")))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
