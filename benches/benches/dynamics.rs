//! Criterion benchmarks: inverse dynamics (RNEA), forward dynamics (ABA), the mass matrix and
//! forward kinematics of UR5 (nv = 6), Panda (nv = 9) and Talos (free flyer + 44 revolute
//! joints, nv = 50), mechanica against Pinocchio (C++) in the same run.
//!
//! Both sides build their models from the neutral description in
//! tools/dynamics_pinocchio_reference.json (placements and inertias bit for bit the same), and
//! run over the same 1000 seeded random states: joint angles uniform in [−π, π], finger slides in
//! [0, 0.04] m, the Talos base at a position in [−1, 1]³ m with a uniformly random orientation
//! (mechanica: rotation vector φ about R_ref = I; Pinocchio: the same rotation as a quaternion),
//! velocities, accelerations and forces uniform in [−2, 2] in mechanica's coordinates, mapped
//! exactly to Pinocchio's (v_B = Rᵀṗ, ω_B = J_r(φ) φ̇, their rates, and the dual forces).
//!
//! Series: mechanica's allocation-free `rnea_into`, `aba_into` and `mass_matrix_into` (the whole
//! matrix) and the position, velocity and acceleration updates of the tree's workspace; Pinocchio's `rnea`, `aba`, `crba` (upper triangle) and `forwardKinematics` (to
//! acceleration), through the C-ABI shim of tools/pinocchio_dynamics_bench.cpp. Build it with
//! `bash tools/pinocchio_dynamics_bench.sh build` and set
//! `MECHANICA_PINOCCHIO_SHIM=/path/to/libpin_bench.so` when building this bench (benches/build.rs
//! links it); without it the Pinocchio series are skipped with a printed note.
//!
//! After criterion's groups, an interleaved summary times one pass over the 1000 states per
//! side in alternation, 15 rounds, and prints the median ns per call of each side and their
//! ratio (written to target/reports/dynamics.csv): on a shared machine, load drift then slows
//! both sides alike. With the shim, the bench first checks that Pinocchio's rnea on the
//! reference states reproduces the reference file to 1e-12 (the same model on both sides).

use criterion::Criterion;
use mechanica::kinematics::nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use mechanica::kinematics::rotation::{right_jacobian, right_jacobian_rate};
use mechanica::kinematics::tree::{Joint, TreeBuilder, Workspace};
use mechanica::mass::MassProperties;
use mechanica::mechanism::Mechanism;
use mechanica_dynamics::Dynamics;
use serde_json::Value;
use std::time::{Duration, Instant};

const STATES: usize = 1000;
const SEED: u64 = 20240611;
const ROUNDS: usize = 15;

/// SplitMix64, so that the states are reproducible from the seed.
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
    fn vector(&mut self, n: usize, scale: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(-scale, scale)).collect()
    }
}

/// One state in both coordinate systems (Pinocchio: q with a quaternion, body-frame velocities).
struct Sample {
    q: Vec<f64>,
    q_dot: Vec<f64>,
    q_ddot: Vec<f64>,
    tau: Vec<f64>,
    pin_q: Vec<f64>,
    pin_v: Vec<f64>,
    pin_a: Vec<f64>,
    pin_tau: Vec<f64>,
}

fn numbers(value: &Value, key: &str) -> Vec<f64> {
    value[key]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

fn vector3(value: &Value, key: &str) -> Vector3<f64> {
    Vector3::from_column_slice(&numbers(value, key))
}

fn matrix3(value: &Value, key: &str) -> Matrix3<f64> {
    Matrix3::from_row_slice(&numbers(value, key))
}

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tools/dynamics_pinocchio_reference.json"
    );
    let text = std::fs::read_to_string(path).expect("tools/dynamics_pinocchio_reference.json");
    serde_json::from_str(&text).expect("valid JSON")
}

/// mechanica's model of one robot of the reference file (R_ref = I for the free joint).
fn mechanica_model(robot: &Value) -> Dynamics {
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for joint in robot["joints"].as_array().expect("joints") {
        let kind = match joint["type"].as_str() {
            Some("revolute") => Joint::Revolute {
                axis: vector3(joint, "axis"),
            },
            Some("prismatic") => Joint::Prismatic {
                axis: vector3(joint, "axis"),
            },
            _ => Joint::Free,
        };
        let rotation = Rotation3::from_matrix_unchecked(matrix3(joint, "rotation"));
        let placement = Isometry3::from_parts(
            Translation3::from(vector3(joint, "translation")),
            UnitQuaternion::from_rotation_matrix(&rotation),
        );
        let parent = joint["parent"].as_u64().map(|p| p as usize);
        builder.add_body(parent, kind, placement);
        let mass = joint["mass"].as_f64().expect("mass");
        bodies.push(MassProperties::new(mass, vector3(joint, "com"), matrix3(joint, "inertia")).expect("body"));
    }
    let tree = builder.build().expect("tree");
    let mut mechanism = Mechanism::new(tree, bodies).expect("mechanism");
    mechanism.set_gravity(vector3(robot, "gravity")).expect("gravity");
    Dynamics::new(mechanism).expect("dynamics")
}

fn is_free(robot: &Value) -> bool {
    robot["free_flyer"].as_bool().unwrap_or(false)
}

/// Pinocchio's (q, v, a, τ) from mechanica's, for a root free joint on coordinates 0..6 with
/// R_ref = I: R = exp(φ), v_B = Rᵀṗ, ω_B = J_r φ̇, a_B = Rᵀp̈ − ω_B × v_B, ω̇_B = J_r φ̈ + J̇_r φ̇,
/// and the forces dual to the velocities (f_B = Rᵀ f, n_B = J_r⁻ᵀ τ_φ).
fn to_pinocchio(free: bool, q: &[f64], q_dot: &[f64], q_ddot: &[f64], tau: &[f64]) -> [Vec<f64>; 4] {
    if !free {
        return [q.to_vec(), q_dot.to_vec(), q_ddot.to_vec(), tau.to_vec()];
    }
    let slice3 = |x: &[f64], k: usize| Vector3::new(x[k], x[k + 1], x[k + 2]);
    let phi = slice3(q, 3);
    let r = Rotation3::new(phi);
    let quaternion = UnitQuaternion::from_rotation_matrix(&r);
    let (jr, jr_rate) = (right_jacobian(&phi), right_jacobian_rate(&phi, &slice3(q_dot, 3)));
    let v_b = r.transpose() * slice3(q_dot, 0);
    let w_b = jr * slice3(q_dot, 3);
    let a_b = r.transpose() * slice3(q_ddot, 0) - w_b.cross(&v_b);
    let wd_b = jr * slice3(q_ddot, 3) + jr_rate * slice3(q_dot, 3);
    let f_b = r.transpose() * slice3(tau, 0);
    let n_b = jr.transpose().try_inverse().expect("|φ| < 2π") * slice3(tau, 3);
    let join = |head: [Vector3<f64>; 2], tail: &[f64]| {
        let mut out: Vec<f64> = head.iter().flat_map(|v| v.iter().copied()).collect();
        out.extend_from_slice(tail);
        out
    };
    let mut pin_q = q[0..3].to_vec();
    pin_q.extend_from_slice(quaternion.coords.as_slice()); // (x, y, z, w), Pinocchio's order
    pin_q.extend_from_slice(&q[6..]);
    [
        pin_q,
        join([v_b, w_b], &q_dot[6..]),
        join([a_b, wd_b], &q_ddot[6..]),
        join([f_b, n_b], &tau[6..]),
    ]
}

/// A uniformly random rotation: a point uniform in the unit 4-ball (by rejection), normalised.
fn random_orientation(rng: &mut Rng) -> UnitQuaternion<f64> {
    loop {
        let x = [
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        ];
        let norm2: f64 = x.iter().map(|c| c * c).sum();
        if norm2 > 1e-4 && norm2 <= 1.0 {
            let q = mechanica::kinematics::nalgebra::Quaternion::new(x[3], x[0], x[1], x[2]);
            return UnitQuaternion::from_quaternion(q);
        }
    }
}

fn samples(robot: &Value, seed: u64) -> Vec<Sample> {
    let mut rng = Rng(seed);
    let joints = robot["joints"].as_array().expect("joints");
    let free = is_free(robot);
    let nv = robot["nv"].as_u64().expect("nv") as usize;
    (0..STATES)
        .map(|_| {
            let mut q = Vec::with_capacity(nv);
            for joint in joints {
                match joint["type"].as_str() {
                    Some("revolute") => q.push(rng.uniform(-std::f64::consts::PI, std::f64::consts::PI)),
                    Some("prismatic") => q.push(rng.uniform(0.0, 0.04)),
                    _ => {
                        q.extend(rng.vector(3, 1.0));
                        q.extend(random_orientation(&mut rng).scaled_axis().iter().copied());
                    }
                }
            }
            let (q_dot, q_ddot, tau) = (rng.vector(nv, 2.0), rng.vector(nv, 2.0), rng.vector(nv, 2.0));
            let [pin_q, pin_v, pin_a, pin_tau] = to_pinocchio(free, &q, &q_dot, &q_ddot, &tau);
            Sample {
                q,
                q_dot,
                q_ddot,
                tau,
                pin_q,
                pin_v,
                pin_a,
                pin_tau,
            }
        })
        .collect()
}

#[cfg(mechanica_pinocchio)]
mod peer {
    //! Pinocchio through the shim of tools/pinocchio_dynamics_bench.cpp (linked by build.rs).
    use super::{Value, matrix3, numbers, vector3};
    use std::ffi::c_void;

    unsafe extern "C" {
        fn pin_bench_new() -> *mut c_void;
        fn pin_bench_add_joint(
            h: *mut c_void,
            parent: i32,
            kind: i32,
            axis: *const f64,
            rotation: *const f64,
            translation: *const f64,
            mass: f64,
            com: *const f64,
            inertia: *const f64,
        ) -> i32;
        fn pin_bench_set_gravity(h: *mut c_void, g: *const f64);
        fn pin_bench_finish(h: *mut c_void);
        fn pin_bench_free(h: *mut c_void);
        fn pin_bench_nq(h: *const c_void) -> i32;
        fn pin_bench_nv(h: *const c_void) -> i32;
        fn pin_bench_rnea(h: *mut c_void, q: *const f64, v: *const f64, a: *const f64, tau: *mut f64);
        fn pin_bench_aba(h: *mut c_void, q: *const f64, v: *const f64, tau: *const f64, a: *mut f64);
        fn pin_bench_crba(h: *mut c_void, q: *const f64, m: *mut f64);
        fn pin_bench_forward_kinematics(h: *mut c_void, q: *const f64, v: *const f64, a: *const f64);
    }

    /// A Pinocchio model and data built from one robot of the reference file.
    pub struct Peer {
        handle: *mut c_void,
        nq: usize,
        nv: usize,
    }

    impl Peer {
        pub fn build(robot: &Value) -> Option<Peer> {
            // SAFETY: the shim's functions take a handle from pin_bench_new and arrays of the
            // lengths its header comment states; every array here has them.
            unsafe {
                let handle = pin_bench_new();
                let mut peer = Peer { handle, nq: 0, nv: 0 };
                for joint in robot["joints"].as_array()? {
                    let kind = match joint["type"].as_str()? {
                        "revolute" => 0,
                        "prismatic" => 1,
                        _ => 2,
                    };
                    let axis = if kind == 2 {
                        vec![0.0; 3]
                    } else {
                        numbers(joint, "axis")
                    };
                    let rotation: Vec<f64> = matrix3(joint, "rotation").transpose().as_slice().to_vec();
                    let inertia: Vec<f64> = matrix3(joint, "inertia").transpose().as_slice().to_vec();
                    let parent = joint["parent"].as_i64().unwrap_or(-1) as i32;
                    let (translation, com) = (vector3(joint, "translation"), vector3(joint, "com"));
                    let mass = joint["mass"].as_f64()?;
                    let index = pin_bench_add_joint(
                        handle,
                        parent,
                        kind,
                        axis.as_ptr(),
                        rotation.as_ptr(),
                        translation.as_ptr(),
                        mass,
                        com.as_ptr(),
                        inertia.as_ptr(),
                    );
                    if index < 0 {
                        return None;
                    }
                }
                pin_bench_set_gravity(handle, vector3(robot, "gravity").as_ptr());
                pin_bench_finish(handle);
                peer.nq = pin_bench_nq(handle) as usize;
                peer.nv = pin_bench_nv(handle) as usize;
                Some(peer)
            }
        }

        pub fn rnea(&mut self, q: &[f64], v: &[f64], a: &[f64], tau: &mut [f64]) {
            self.check(q, &[v, a], tau.len());
            // SAFETY: lengths checked against the model's nq and nv.
            unsafe { pin_bench_rnea(self.handle, q.as_ptr(), v.as_ptr(), a.as_ptr(), tau.as_mut_ptr()) }
        }

        pub fn aba(&mut self, q: &[f64], v: &[f64], tau: &[f64], a: &mut [f64]) {
            self.check(q, &[v, tau], a.len());
            // SAFETY: lengths checked against the model's nq and nv.
            unsafe { pin_bench_aba(self.handle, q.as_ptr(), v.as_ptr(), tau.as_ptr(), a.as_mut_ptr()) }
        }

        pub fn crba(&mut self, q: &[f64], m: &mut [f64]) {
            self.check(q, &[], m.len() / self.nv.max(1));
            // SAFETY: lengths checked against the model's nq and nv (m holds nv × nv).
            unsafe { pin_bench_crba(self.handle, q.as_ptr(), m.as_mut_ptr()) }
        }

        pub fn forward_kinematics(&mut self, q: &[f64], v: &[f64], a: &[f64]) {
            self.check(q, &[v, a], self.nv);
            // SAFETY: lengths checked against the model's nq and nv.
            unsafe { pin_bench_forward_kinematics(self.handle, q.as_ptr(), v.as_ptr(), a.as_ptr()) }
        }

        fn check(&self, q: &[f64], velocities: &[&[f64]], out: usize) {
            assert!(q.len() == self.nq && out == self.nv && velocities.iter().all(|v| v.len() == self.nv));
        }
    }

    impl Drop for Peer {
        fn drop(&mut self) {
            // SAFETY: the handle came from pin_bench_new and is freed once.
            unsafe { pin_bench_free(self.handle) }
        }
    }
}

#[cfg(not(mechanica_pinocchio))]
mod peer {
    //! No shim linked: there is no peer to build, and no method can be reached.
    use super::Value;

    pub enum Peer {}

    impl Peer {
        pub fn build(_robot: &Value) -> Option<Peer> {
            None
        }
        pub fn rnea(&mut self, _: &[f64], _: &[f64], _: &[f64], _: &mut [f64]) {
            match *self {}
        }
        pub fn aba(&mut self, _: &[f64], _: &[f64], _: &[f64], _: &mut [f64]) {
            match *self {}
        }
        pub fn crba(&mut self, _: &[f64], _: &mut [f64]) {
            match *self {}
        }
        pub fn forward_kinematics(&mut self, _: &[f64], _: &[f64], _: &[f64]) {
            match *self {}
        }
    }
}

use peer::Peer;

/// Pinocchio's rnea on the reference states (φ = 0, R_ref = the base rotation) reproduces the
/// reference file's τ to 1e-12: the shim's model is the reference's. Returns the deviation.
fn check_peer(robot: &Value, peer: &mut Peer) -> f64 {
    let free = is_free(robot);
    let mut worst = 0.0f64;
    for state in robot["states"].as_array().expect("states") {
        let (q, v, a, expected) = (
            numbers(state, "q"),
            numbers(state, "v"),
            numbers(state, "a"),
            numbers(state, "rnea"),
        );
        let r = if free {
            matrix3(state, "base_rotation")
        } else {
            Matrix3::identity()
        };
        // With φ = 0 the rotation is R_ref = r: rotate the translational parts into the body.
        let frame = |x: &[f64]| -> Vec<f64> {
            let mut out = x.to_vec();
            if free {
                let body = r.transpose() * Vector3::new(x[0], x[1], x[2]);
                out[..3].copy_from_slice(body.as_slice());
            }
            out
        };
        let (pin_v, mut pin_a) = (frame(&v), frame(&a));
        let mut pin_q = q.clone();
        if free {
            let w = Vector3::new(v[3], v[4], v[5]);
            let vb = Vector3::new(pin_v[0], pin_v[1], pin_v[2]);
            let ab = Vector3::new(pin_a[0], pin_a[1], pin_a[2]) - w.cross(&vb);
            pin_a[..3].copy_from_slice(ab.as_slice());
            let quaternion = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
            pin_q = q[0..3].to_vec();
            pin_q.extend_from_slice(quaternion.coords.as_slice());
            pin_q.extend_from_slice(&q[6..]);
        }
        let mut tau = vec![0.0; v.len()];
        peer.rnea(&pin_q, &pin_v, &pin_a, &mut tau);
        if free {
            let world = r * Vector3::new(tau[0], tau[1], tau[2]);
            tau[..3].copy_from_slice(world.as_slice());
        }
        let scale = expected.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let deviation = tau.iter().zip(&expected).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale;
        worst = worst.max(deviation);
    }
    worst
}

struct Bench {
    name: String,
    dynamics: Dynamics,
    workspace: Workspace,
    samples: Vec<Sample>,
    peer: Option<Peer>,
    out: Vec<f64>,
    matrix: Vec<f64>,
}

/// The four operations, as (label, mechanica's call, Pinocchio's call) on sample `i`.
type Call = fn(&mut Bench, usize);

fn operations() -> [(&'static str, Call, Call); 4] {
    [
        (
            "rnea",
            |b, i| {
                let s = &b.samples[i];
                b.dynamics
                    .rnea_into(&s.q, &s.q_dot, &s.q_ddot, &mut b.out)
                    .expect("rnea");
            },
            |b, i| {
                let s = &b.samples[i];
                b.peer
                    .as_mut()
                    .expect("peer")
                    .rnea(&s.pin_q, &s.pin_v, &s.pin_a, &mut b.out);
            },
        ),
        (
            "aba",
            |b, i| {
                let s = &b.samples[i];
                b.dynamics.aba_into(&s.q, &s.q_dot, &s.tau, &mut b.out).expect("aba");
            },
            |b, i| {
                let s = &b.samples[i];
                b.peer
                    .as_mut()
                    .expect("peer")
                    .aba(&s.pin_q, &s.pin_v, &s.pin_tau, &mut b.out);
            },
        ),
        (
            "crba",
            |b, i| {
                b.dynamics
                    .mass_matrix_into(&b.samples[i].q, &mut b.matrix)
                    .expect("mass matrix");
            },
            |b, i| {
                b.peer.as_mut().expect("peer").crba(&b.samples[i].pin_q, &mut b.matrix);
            },
        ),
        (
            "forward_kinematics",
            |b, i| {
                let s = &b.samples[i];
                let tree = b.dynamics.tree();
                tree.update_positions(&mut b.workspace, &s.q).expect("positions");
                tree.update_velocities(&mut b.workspace, &s.q_dot).expect("velocities");
                tree.update_accelerations(&mut b.workspace, &s.q_ddot)
                    .expect("accelerations");
            },
            |b, i| {
                let s = &b.samples[i];
                b.peer
                    .as_mut()
                    .expect("peer")
                    .forward_kinematics(&s.pin_q, &s.pin_v, &s.pin_a);
            },
        ),
    ]
}

fn setup() -> Vec<Bench> {
    let document = reference();
    let mut benches = Vec::new();
    for (index, robot) in document["models"].as_array().expect("models").iter().enumerate() {
        let name = robot["name"].as_str().expect("name").to_string();
        let dynamics = mechanica_model(robot);
        let mut peer = Peer::build(robot);
        match peer.as_mut() {
            Some(p) => {
                let deviation = check_peer(robot, p);
                assert!(
                    deviation <= 1e-12,
                    "{name}: the Pinocchio shim deviates from the reference by {deviation:e}"
                );
                println!("{name}: Pinocchio shim reproduces the reference rnea to {deviation:.1e}");
            }
            None => println!(
                "{name}: no Pinocchio shim (set MECHANICA_PINOCCHIO_SHIM when building, see \
                 tools/pinocchio_dynamics_bench.sh): Pinocchio series skipped"
            ),
        }
        let nv = dynamics.dof();
        benches.push(Bench {
            name,
            workspace: dynamics.tree().workspace(),
            dynamics,
            samples: samples(robot, SEED + index as u64),
            peer,
            out: vec![0.0; nv],
            matrix: vec![0.0; nv * nv],
        });
    }
    benches
}

fn criterion_groups(c: &mut Criterion, benches: &mut [Bench]) {
    for bench in benches.iter_mut() {
        let mut group = c.benchmark_group(format!("dynamics_{}", bench.name));
        for (label, ours, theirs) in operations() {
            let mut i = 0;
            group.bench_function(format!("{label}/mechanica"), |b| {
                b.iter(|| {
                    i = (i + 1) % STATES;
                    ours(bench, i)
                })
            });
            if bench.peer.is_some() {
                group.bench_function(format!("{label}/pinocchio"), |b| {
                    b.iter(|| {
                        i = (i + 1) % STATES;
                        theirs(bench, i)
                    })
                });
            }
        }
        group.finish();
    }
}

/// ns per call of one pass of `call` over all samples.
fn pass_ns(bench: &mut Bench, call: Call) -> f64 {
    let start = Instant::now();
    for i in 0..STATES {
        call(bench, i);
    }
    start.elapsed().as_secs_f64() * 1e9 / STATES as f64
}

fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    x[x.len() / 2]
}

/// Interleaved passes, median ns per call of each side and the ratio mechanica / Pinocchio.
fn summary(benches: &mut [Bench]) {
    let mut csv = String::from("robot,nv,operation,mechanica_ns,pinocchio_ns,ratio\n");
    println!("\n# interleaved summary: median of {ROUNDS} rounds, one pass over {STATES} states per side and round");
    println!("# robot nv operation mechanica_ns pinocchio_ns ratio(mechanica/pinocchio)");
    for bench in benches.iter_mut() {
        let nv = bench.dynamics.dof();
        for (label, ours, theirs) in operations() {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for _ in 0..ROUNDS {
                a.push(pass_ns(bench, ours));
                if bench.peer.is_some() {
                    b.push(pass_ns(bench, theirs));
                }
            }
            let ours_ns = median(a);
            let (theirs_ns, ratio) = if b.is_empty() {
                (f64::NAN, f64::NAN)
            } else {
                let t = median(b);
                (t, ours_ns / t)
            };
            println!("{} {nv} {label} {ours_ns:.0} {theirs_ns:.0} {ratio:.2}", bench.name);
            csv += &format!("{},{nv},{label},{ours_ns:.1},{theirs_ns:.1},{ratio:.3}\n", bench.name);
        }
    }
    match mechanica_benches::reports_dir().and_then(|d| std::fs::write(d.join("dynamics.csv"), csv)) {
        Ok(()) => println!("# written to target/reports/dynamics.csv"),
        Err(e) => println!("# target/reports/dynamics.csv not written: {e}"),
    }
}

fn main() {
    let mut benches = setup();
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    criterion_groups(&mut c, &mut benches);
    c.final_summary();
    summary(&mut benches);
}
