//! Criterion benchmarks of the integrators on a 7-link chain of revolute joints (random axes
//! and placements from a fixed seed, gravity, joint springs), each integrating 1 s of motion
//! from the same state: RK4 and Störmer–Verlet at h = 1e-3 s, the implicit midpoint rule at
//! h = 1e-3 s, Dormand–Prince at rtol = 1e-8; each without and with the companion run of the
//! global error estimate. The group "contacts" runs the same chain with a unilateral contact
//! at the last body that stays open (the cost of checking every step for events, theory
//! (M.22)) beside the run without contacts.

use criterion::Criterion;
use mechanica::impulse::{BodyPoint, ContactLaw, MechanismContact, RestitutionLaw};
use mechanica::kinematics::nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use mechanica::kinematics::tree::{Joint, TreeBuilder};
use mechanica::mass::MassProperties;
use mechanica::mechanism::Mechanism;
use mechanica::mechanism::potentials::JointSpring;
use mechanica_dynamics::Dynamics;
use mechanica_motion::{Method, Options, Simulation, UnilateralContact};
use std::hint::black_box;

const LINKS: usize = 7;

/// SplitMix64, so that the chain is reproducible from the seed.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn unit(&mut self) -> Vector3<f64> {
        Vector3::new(self.uniform(-1.0, 1.0), self.uniform(-1.0, 1.0), self.uniform(0.2, 1.0)).normalize()
    }
}

fn chain() -> Dynamics {
    let mut rng = Rng(20240611);
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for i in 0..LINKS {
        let parent = if i == 0 { None } else { Some(i - 1) };
        let turn = UnitQuaternion::from_scaled_axis(rng.unit() * 0.5);
        let placement = Isometry3::from_parts(Translation3::from(rng.unit() * 0.4), turn);
        builder.add_body(parent, Joint::Revolute { axis: rng.unit() }, placement);
        let mass = rng.uniform(0.5, 3.0);
        let inertia = Matrix3::identity() * (mass * 0.01);
        bodies.push(MassProperties::new(mass, rng.unit() * 0.2, inertia).expect("body"));
    }
    let tree = builder.build().expect("tree");
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81)).expect("gravity");
    for k in 0..LINKS {
        let spring = JointSpring {
            coordinate: k,
            stiffness: 20.0,
            rest: 0.0,
        };
        mechanism.add_potential(spring).expect("spring");
    }
    Dynamics::new(mechanism).expect("dynamics")
}

fn main() {
    let mut criterion = Criterion::default().sample_size(10).configure_from_args();
    let dynamics = chain();
    let q0 = vec![0.3; LINKS];
    let v0 = vec![0.0; LINKS];
    let methods = [
        ("rk4 h=1e-3", Method::Rk4 { step: 1e-3 }),
        (
            "dopri rtol=1e-8",
            Method::DormandPrince {
                rtol: 1e-8,
                atol: 1e-10,
            },
        ),
        ("verlet h=1e-3", Method::StormerVerlet { step: 1e-3 }),
        ("midpoint h=1e-3", Method::ImplicitMidpoint { step: 1e-3 }),
    ];
    let mut group = criterion.benchmark_group("motion 7-link chain, 1 s");
    for (name, method) in methods {
        for estimate_error in [false, true] {
            let options = Options {
                estimate_error,
                ..Options::default()
            };
            let simulation = Simulation::new(dynamics.clone(), method, options).expect("simulation");
            let label = if estimate_error {
                format!("{name} + estimate")
            } else {
                name.to_string()
            };
            group.bench_function(label, |b| {
                b.iter(|| black_box(simulation.run(&q0, &v0, 1.0, 0.1).expect("run")))
            });
        }
    }
    group.finish();
    contacts(&mut criterion, &dynamics, &q0, &v0);
    criterion.final_summary();
}

/// The chain without contacts and with one open contact (a plane 100 m below the last body).
fn contacts(criterion: &mut Criterion, dynamics: &Dynamics, q0: &[f64], v0: &[f64]) {
    let far_floor = UnilateralContact {
        contact: MechanismContact {
            point: BodyPoint {
                body: LINKS - 1,
                p_bq: Vector3::zeros(),
            },
            other: None,
            normal_w: Vector3::z(),
            law: ContactLaw::new(0.5, 0.3, RestitutionLaw::Stronge).expect("law"),
        },
        offset: -100.0,
    };
    let mut group = criterion.benchmark_group("contacts 7-link chain, 1 s");
    let methods = [
        ("rk4 h=1e-3", Method::Rk4 { step: 1e-3 }),
        (
            "dopri rtol=1e-8",
            Method::DormandPrince {
                rtol: 1e-8,
                atol: 1e-10,
            },
        ),
    ];
    for (name, method) in methods {
        let options = Options {
            estimate_error: false,
            ..Options::default()
        };
        let plain = Simulation::new(dynamics.clone(), method, options).expect("simulation");
        let checked = plain.clone().with_contacts(vec![far_floor]).expect("contacts");
        for (label, simulation) in [("no contact", plain), ("open contact", checked)] {
            group.bench_function(format!("{name}, {label}"), |b| {
                b.iter(|| black_box(simulation.run(q0, v0, 1.0, 0.1).expect("run")))
            });
        }
    }
    group.finish();
}
