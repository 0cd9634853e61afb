//! Builders shared by the integration tests.
#![allow(dead_code)]

use mechanica_kinematics::tree::{Joint, KinematicTree, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

pub const G: f64 = 9.81;

/// A planar chain of `n` point masses `m` on massless links of length `l`, hanging along −z
/// from revolute joints about y, with gravity −g z.
pub fn pendulum_chain(n: usize, m: f64, l: f64) -> Mechanism {
    let mut builder = TreeBuilder::new();
    for i in 0..n {
        let parent = i.checked_sub(1);
        let placement = if i == 0 {
            Isometry3::identity()
        } else {
            Isometry3::translation(0.0, 0.0, -l)
        };
        builder.add_body(parent, Joint::Revolute { axis: Vector3::y() }, placement);
    }
    let tree = builder.build().expect("valid chain");
    let bodies = vec![MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("point"); n];
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -G)).expect("gravity");
    mechanism
}

/// A random tree of `n` bodies with random joints (revolute, prismatic, planar, and, when
/// `spherical`, spherical), random placements and random solid mass properties.
pub fn random_tree(n: usize, seed: u64, spherical: bool) -> (KinematicTree, Vec<MassProperties>) {
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for i in 0..n {
        let parent = if i == 0 {
            None
        } else {
            Some((next() * i as f64) as usize)
        };
        let axis = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
        let kind = (next() * if spherical { 4.0 } else { 3.0 }) as usize;
        let joint = match kind {
            0 => Joint::Revolute { axis },
            1 => Joint::Prismatic { axis },
            2 => Joint::Planar,
            _ => Joint::Spherical,
        };
        let rotation = UnitQuaternion::from_scaled_axis(Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 2.0);
        let placement = Isometry3::from_parts(Translation3::new(next() - 0.5, next() - 0.5, next() - 0.5), rotation);
        builder.add_body(parent, joint, placement);
        let (a, b, c) = (0.1 + next(), 0.1 + next(), 0.1 + next());
        let mass = 0.5 + next();
        let box_inertia = nalgebra::Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b))
            * (mass / 12.0);
        let r = UnitQuaternion::from_scaled_axis(Vector3::new(next(), next(), next())).to_rotation_matrix();
        let inertia = r.matrix() * box_inertia * r.matrix().transpose();
        let com = Vector3::new(next() - 0.5, next() - 0.5, next() - 0.5);
        bodies.push(MassProperties::new(mass, com, inertia).expect("valid body"));
    }
    (builder.build().expect("valid random tree"), bodies)
}

/// A reproducible pseudo-random vector in [−s, s]ⁿ.
pub fn random_vector(n: usize, seed: u64, s: f64) -> Vec<f64> {
    let mut state = seed ^ 0x9E3779B97F4A7C15;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (((state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0) * s
        })
        .collect()
}
