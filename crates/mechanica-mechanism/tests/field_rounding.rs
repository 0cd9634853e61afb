//! The componentwise bound on the rounding of the field's Hessian holds against a reference
//! that has not rounded the same way: the same mechanism moved as a whole.
//!
//! Moving every body by d along the field's axis leaves the exact Hessian unchanged (gravity
//! shifts U by the constant −M g·d; the centrifugal potential of rotation about that axis is
//! unchanged), while the computed Hessians round differently, the moved one from moments and
//! columns of the size of |d|. So |B(moved) − B(near)| ≤ E(moved) + E(near) entry by entry.
//! Random trees of every joint kind, lengths and masses over 1e±3, offsets from 1e2 to 1e8
//! lengths, gravity alone or with a rotating frame.

mod common;

use common::{random_scaled_tree, random_vector};
use mechanica_kinematics::tree::{KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, RotatingFrame};
use nalgebra::{Isometry3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};

/// The tree with every root's placement moved by `offset`.
fn moved(tree: &KinematicTree, offset: &Vector3<f64>) -> KinematicTree {
    let mut builder = TreeBuilder::new();
    for i in 0..tree.body_count() {
        let (r, p) = tree.placement(i).expect("placement");
        let parent = tree.parent(i);
        let p = if parent.is_none() { p + offset } else { p };
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
        let joint = *tree.joint(i).expect("joint");
        builder.add_body(parent, joint, Isometry3::from_parts(Translation3::from(p), rotation));
    }
    builder.build().expect("moved tree")
}

fn with_field(
    tree: KinematicTree,
    bodies: Vec<MassProperties>,
    axis: Unit<Vector3<f64>>,
    g: f64,
    rate: f64,
) -> Mechanism {
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(axis.into_inner() * -g).expect("gravity");
    if rate > 0.0 {
        mechanism
            .set_rotating_frame(Some(RotatingFrame { axis, rate }))
            .expect("frame");
    }
    mechanism
}

/// q with random angles and translations of size L, rotation vectors zero.
fn configuration(tree: &KinematicTree, seed: u64) -> Vec<f64> {
    let mut q = random_vector(tree.dof(), seed, 1.0);
    for body in 0..tree.body_count() {
        if tree.joint(body).is_some_and(|j| j.has_rotation_vector()) {
            let end = tree.dof_range(body).end;
            q[end - 3..end].iter_mut().for_each(|v| *v = 0.0);
        }
    }
    q
}

#[test]
fn the_field_rounding_bound_covers_the_change_of_the_hessian_under_a_rigid_shift() {
    let mut worst: f64 = 0.0;
    for seed in 0..120 {
        let n = 2 + (seed as usize * 5) % 14;
        let (tree, bodies, length) = random_scaled_tree(n, seed, seed % 2 == 0, seed % 5 == 0);
        if tree.dof() == 0 {
            continue;
        }
        let draws = random_vector(4, seed + 500, 1.0);
        let axis = Unit::new_normalize(Vector3::new(draws[0], draws[1], 1.0));
        let g = 9.81 * 10f64.powf(draws[2]);
        let rate = if seed % 3 == 0 { (g / length).sqrt() } else { 0.0 };
        let offset = axis.into_inner() * length * 10f64.powf(5.0 + 3.0 * draws[3]);
        let q = configuration(&tree, seed + 900);
        let near = with_field(tree.clone(), bodies.clone(), axis, g, rate);
        let far = with_field(moved(&tree, &offset), bodies, axis, g, rate);
        let b_near = near.potential(&q, true).expect("U").hessian.expect("B");
        let b_far = far.potential(&q, true).expect("U").hessian.expect("B");
        let e_near = near.field_hessian_rounding(&q).expect("E");
        let e_far = far.field_hessian_rounding(&q).expect("E");
        let scale = b_near.norm_max();
        for k in 0..tree.dof() {
            for l in 0..tree.dof() {
                let change = (b_far[(k, l)] - b_near[(k, l)]).abs();
                let bound = e_far[(k, l)] + e_near[(k, l)];
                assert!(
                    change <= bound,
                    "seed {seed}: B[{k},{l}] moved by {change:e} > bound {bound:e} (|B| ≤ {scale:e})"
                );
                if change > 0.0 {
                    worst = worst.max(change / bound);
                }
            }
        }
    }
    // The family does exercise the bound: the shift's rounding reaches a visible part of it.
    assert!(worst > 1e-4, "largest change/bound {worst:e}");
}
