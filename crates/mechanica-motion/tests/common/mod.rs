//! Mechanisms with closed-form motions, random chains and a reproducible generator.

#![allow(dead_code)]

use mechanica_dynamics::{Damper, Dynamics};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_mechanism::potentials::JointSpring;
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

/// SplitMix64, so every case is reproducible from its seed.
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
    /// 10^U(lo, hi).
    pub fn decades(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.uniform(lo, hi))
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            if v.norm() > 0.1 {
                return v.normalize();
            }
        }
    }
}

/// A mass m on a prismatic joint along x with a spring k (and a dashpot c when c > 0):
/// m ẍ + c ẋ + k x = 0.
pub fn oscillator(m: f64, k: f64, c: f64) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Prismatic { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(m, Vector3::zeros()).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism
        .add_potential(JointSpring {
            coordinate: 0,
            stiffness: k,
            rest: 0.0,
        })
        .expect("spring");
    let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
    if c > 0.0 {
        dynamics
            .add_damper(Damper::Joint {
                coordinate: 0,
                coefficient: c,
            })
            .expect("damper");
    }
    dynamics
}

/// The closed form (x, ẋ) of m ẍ + c ẋ + k x = 0 (underdamped) at t.
pub fn oscillator_motion(m: f64, k: f64, c: f64, x0: f64, v0: f64, t: f64) -> (f64, f64) {
    let omega = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let decay = zeta * omega;
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let b = (v0 + decay * x0) / wd;
    let (s, co) = (wd * t).sin_cos();
    let e = (-decay * t).exp();
    let x = e * (x0 * co + b * s);
    let v = e * (-decay * (x0 * co + b * s) + (-x0 * wd * s + b * wd * co));
    (x, v)
}

/// A point mass m at distance l below a revolute joint about x, gravity g along −z:
/// θ̈ = −(g/l) sin θ.
pub fn pendulum(m: f64, l: f64, g: f64) -> Dynamics {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let tree = builder.build().expect("tree");
    let body = MassProperties::point(m, Vector3::new(0.0, 0.0, -l)).expect("mass");
    let mut mechanism = Mechanism::new(tree, vec![body]).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -g)).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

/// A chain of `links` bodies on revolute joints with random axes and placements, random
/// masses over two decades, gravity, and random joint springs and dampers.
pub fn random_chain(rng: &mut Rng, links: usize) -> Dynamics {
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for i in 0..links {
        let parent = if i == 0 { None } else { Some(i - 1) };
        let length = rng.uniform(0.2, 1.0);
        let turn = UnitQuaternion::from_scaled_axis(rng.unit() * rng.uniform(0.0, 1.0));
        let placement = Isometry3::from_parts(Translation3::from(rng.unit() * length), turn);
        builder.add_body(parent, Joint::Revolute { axis: rng.unit() }, placement);
        let mass = rng.decades(-1.0, 1.0);
        let centre = rng.unit() * rng.uniform(0.1, length);
        let moment = mass * length * length / 12.0;
        let inertia = Matrix3::from_diagonal(&Vector3::new(moment, moment, moment * rng.uniform(0.2, 1.0)));
        bodies.push(MassProperties::new(mass, centre, inertia).expect("body"));
    }
    let tree = builder.build().expect("tree");
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    for k in 0..links {
        if rng.below(2) == 0 {
            let spring = JointSpring {
                coordinate: k,
                stiffness: rng.decades(-1.0, 1.5),
                rest: rng.uniform(-1.0, 1.0),
            };
            mechanism.add_potential(spring).expect("spring");
        }
    }
    let mut dynamics = Dynamics::new(mechanism).expect("dynamics");
    for k in 0..links {
        if rng.below(3) == 0 {
            let damper = Damper::Joint {
                coordinate: k,
                coefficient: rng.decades(-2.0, 0.0),
            };
            dynamics.add_damper(damper).expect("damper");
        }
    }
    dynamics
}

/// ‖a − b‖∞.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}
