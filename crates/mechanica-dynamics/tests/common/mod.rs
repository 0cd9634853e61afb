//! Random mechanisms for the property tests: trees of every joint type with masses graded at
//! random over twelve decades, random placements and random states.

#![allow(dead_code)]

use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// SplitMix64: a small, well-mixed generator, so every case is reproducible from its seed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed ^ 0x9e37_79b9_7f4a_7c15)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn vector(&mut self, scale: f64) -> Vector3<f64> {
        Vector3::new(
            self.uniform(-scale, scale),
            self.uniform(-scale, scale),
            self.uniform(-scale, scale),
        )
    }
    pub fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = self.vector(1.0);
            if v.norm() > 0.1 {
                return v.normalize();
            }
        }
    }
    pub fn rotation(&mut self) -> Rotation3<f64> {
        Rotation3::new(self.vector(3.0))
    }
}

/// A physical central inertia tensor: principal moments that satisfy the triangle
/// inequalities, turned to random axes, of size mass·size².
pub fn random_inertia(rng: &mut Rng, mass: f64, size: f64) -> Matrix3<f64> {
    let (a, b, c) = (rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0));
    // Moments of a box with half-sides a, b, c: m(b² + c²)/3 and so on.
    let d =
        Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b)) * (mass * size * size / 3.0);
    let r = rng.rotation();
    r.matrix() * d * r.matrix().transpose()
}

pub fn random_joint(rng: &mut Rng, kinds: usize) -> Joint {
    match rng.below(kinds) {
        0 | 1 => Joint::Revolute { axis: rng.unit() },
        2 => Joint::Prismatic { axis: rng.unit() },
        3 => Joint::Spherical,
        4 => Joint::Planar,
        5 => Joint::Free,
        _ => Joint::Fixed,
    }
}

/// A random tree of `bodies` bodies (each body's parent drawn among the earlier ones, or a
/// chain when `chain`), with every joint type, masses 10^U(−grading/2, grading/2) kg and link
/// lengths 10^U(−1, 0.5) m.
pub fn random_mechanism(rng: &mut Rng, bodies: usize, grading: f64, chain: bool) -> Mechanism {
    let mut builder = TreeBuilder::new();
    let mut masses = Vec::new();
    for i in 0..bodies {
        let parent = if i == 0 {
            None
        } else if chain {
            Some(i - 1)
        } else {
            Some(rng.below(i))
        };
        let joint = random_joint(rng, 7);
        let length = 10f64.powf(rng.uniform(-1.0, 0.5));
        let q = UnitQuaternion::from_rotation_matrix(&rng.rotation());
        let placement = Isometry3::from_parts(Translation3::from(rng.unit() * length), q);
        builder.add_body(parent, joint, placement);
        let mass = 10f64.powf(rng.uniform(-grading / 2.0, grading / 2.0));
        let centre = rng.vector(length);
        let inertia = random_inertia(rng, mass, length.max(0.05));
        masses.push(MassProperties::new(mass, centre, inertia).expect("valid body"));
    }
    let tree = builder.build().expect("valid tree");
    Mechanism::new(tree, masses).expect("valid mechanism")
}

/// A random state: angles in (−π, π), lengths in (−1, 1), rotation vectors shorter than 2.
pub fn random_state(rng: &mut Rng, mechanism: &Mechanism) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let tree = mechanism.tree();
    let n = tree.dof();
    let mut q = vec![0.0; n];
    for body in 0..tree.body_count() {
        let range = tree.dof_range(body);
        for k in range.clone() {
            q[k] = rng.uniform(-1.0, 1.0);
        }
        if let Some(Joint::Revolute { .. }) = tree.joint(body) {
            q[range.start] = rng.uniform(-3.1, 3.1);
        }
    }
    let q_dot = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
    let q_ddot = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
    (q, q_dot, q_ddot)
}

/// ‖x‖∞.
pub fn norm_inf(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}
