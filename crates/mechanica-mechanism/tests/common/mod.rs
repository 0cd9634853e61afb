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

/// A random tree for comparing assemblies, drawn from `seed`: `n` bodies, each hanging from
/// the previous one with a probability drawn per tree (from chains to bushy trees) and else
/// from a random earlier body; joints of every kind (revolute, prismatic, planar, spherical,
/// free, fixed; no rotation-vector joints unless `rotation_vectors`); lengths and masses
/// scaled by per-tree factors L and M between 1e-3 and 1e3; with `massless`, about one body in
/// eight without mass. Returns the tree, the bodies and L.
pub fn random_scaled_tree(
    n: usize,
    seed: u64,
    rotation_vectors: bool,
    massless: bool,
) -> (KinematicTree, Vec<MassProperties>, f64) {
    let mut draw = {
        let mut state = random_vector(1, seed, 1.0)[0].to_bits() ^ seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        }
    };
    let length = 10f64.powf(6.0 * draw() - 3.0);
    let mass = 10f64.powf(6.0 * draw() - 3.0);
    let chain_bias = draw();
    let kinds = if rotation_vectors { 6.0 } else { 4.0 };
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for i in 0..n {
        let parent = match i {
            0 => None,
            _ if draw() < chain_bias => Some(i - 1),
            _ => Some((draw() * i as f64) as usize),
        };
        let axis = spread(1.0, &mut draw).normalize();
        let joint = match (draw() * kinds) as usize {
            0 => Joint::Revolute { axis },
            1 => Joint::Prismatic { axis },
            2 => Joint::Planar,
            3 => Joint::Fixed,
            4 => Joint::Spherical,
            _ => Joint::Free,
        };
        let rotation = UnitQuaternion::from_scaled_axis(spread(4.0, &mut draw));
        let placement = Isometry3::from_parts(Translation3::from(spread(2.0 * length, &mut draw)), rotation);
        builder.add_body(parent, joint, placement);
        let sides = Vector3::new(0.1 + draw(), 0.1 + draw(), 0.1 + draw()) * length;
        let m = if massless && draw() < 0.125 {
            0.0
        } else {
            mass * (0.2 + draw())
        };
        let [a, b, c] = [sides.x, sides.y, sides.z];
        let box_inertia =
            nalgebra::Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b)) * (m / 12.0);
        let r = UnitQuaternion::from_scaled_axis(spread(4.0, &mut draw)).to_rotation_matrix();
        let inertia = r.matrix() * box_inertia * r.matrix().transpose();
        let com = spread(2.0 * length, &mut draw);
        bodies.push(MassProperties {
            mass: m,
            p_oc: com,
            inertia_c: inertia,
        });
    }
    (builder.build().expect("valid random tree"), bodies, length)
}

/// A vector of independent uniform entries in [−s/2, s/2].
fn spread(s: f64, draw: &mut impl FnMut() -> f64) -> Vector3<f64> {
    Vector3::new(draw() - 0.5, draw() - 0.5, draw() - 0.5) * s
}
