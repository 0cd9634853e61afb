//! `run --matrices` reports A(q), U*(q), ∂U*/∂q and ∂²U*/∂q∂q at the start state, checked against
//! closed forms at random states of random mechanisms: a double pendulum of two uniform rods (a
//! scene file) and a cart with a hanging pendulum (a URDF, prismatic and revolute joints).

mod common;
use common::{mechanica, numbers, step};
use std::path::PathBuf;

const G: f64 = 9.81;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-matrices-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A deterministic stream of numbers in [0, 1) (xorshift64*).
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn between(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.next()
    }
}

/// The `state_matrices` step of `run path --q q --matrices --json`.
fn matrices_at(path: &str, q: &[f64]) -> serde_json::Value {
    let q: Vec<String> = q.iter().map(|v| format!("{v:?}")).collect();
    let q = q.join(",");
    let (ok, out, err) = mechanica(&["run", path, "--q", &q, "--matrices", "--json"]);
    assert!(ok, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
    step(&report, "state_matrices").clone()
}

/// Every entry of the reported `key` (a matrix or a vector) within `tol` × scale of `expected`.
fn assert_close(record: &serde_json::Value, key: &str, expected: &[f64], scale: f64, tol: f64) {
    let got = numbers(&record[key]);
    assert_eq!(got.len(), expected.len(), "{key}: {record}");
    for (k, (g, e)) in got.iter().zip(expected).enumerate() {
        assert!((g - e).abs() <= tol * scale, "{key}[{k}]: {g} vs {e} (scale {scale})");
    }
}

fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |a: f64, b| a.max(b.abs()))
}

/// A double pendulum of uniform rods (lengths l1, l2, masses m1, m2) hinged about y under
/// gravity −g z, at angles θ1 (upper, from the vertical) and θ2 (lower, relative): with
/// centres c = l/2 and moments J = m l²/12 about them,
/// A11 = J1 + m1 c1² + J2 + m2 (l1² + c2² + 2 l1 c2 cos θ2), A12 = J2 + m2 (c2² + l1 c2 cos θ2),
/// A22 = J2 + m2 c2², U = −g [m1 c1 cos θ1 + m2 (l1 cos θ1 + c2 cos(θ1 + θ2))].
#[test]
fn double_pendulum_matrices_match_the_closed_form_at_random_states() {
    let dir = scratch("pendulum");
    let mut random = Stream(0x9e37_79b9_7f4a_7c15);
    for case in 0..6 {
        let (l1, l2) = (random.between(0.2, 3.0), random.between(0.2, 3.0));
        let (m1, m2) = (random.between(0.1, 10.0), random.between(0.1, 10.0));
        let scene = dir.join(format!("pendulum{case}.toml"));
        std::fs::write(
            &scene,
            format!(
                r#"title = "double pendulum"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "upper"
primitive = {{ shape = "rod", length = {l1:?}, mass = {m1:?} }}
offset = [0.0, 0.0, {:?}]

[[body]]
name = "lower"
primitive = {{ shape = "rod", length = {l2:?}, mass = {m2:?} }}
offset = [0.0, 0.0, {:?}]

[[joint]]
name = "shoulder"
type = "revolute"
parent = "ground"
child = "upper"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, 0.0]

[[joint]]
name = "elbow"
type = "revolute"
parent = "upper"
child = "lower"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, {:?}]

[analyses]
mass_properties = true
"#,
                -l1 / 2.0,
                -l2 / 2.0,
                -l1
            ),
        )
        .expect("scene");
        let (t1, t2) = (random.between(-3.1, 3.1), random.between(-3.1, 3.1));
        let record = matrices_at(scene.to_str().expect("utf-8"), &[t1, t2]);
        assert_eq!(record["coordinates"], serde_json::json!(["shoulder", "elbow"]));
        assert_eq!(numbers(&record["q"]), vec![t1, t2]);
        assert_eq!(record["recentred"], false);
        let (c1, c2) = (l1 / 2.0, l2 / 2.0);
        let (j1, j2) = (m1 * l1 * l1 / 12.0, m2 * l2 * l2 / 12.0);
        let a11 = j1 + m1 * c1 * c1 + j2 + m2 * (l1 * l1 + c2 * c2 + 2.0 * l1 * c2 * t2.cos());
        let a12 = j2 + m2 * (c2 * c2 + l1 * c2 * t2.cos());
        let a22 = j2 + m2 * c2 * c2;
        let a = [a11, a12, a12, a22];
        assert_close(&record, "mass_matrix", &a, largest(&a), 1e-13);
        let s = t1 + t2;
        let u = -G * (m1 * c1 * t1.cos() + m2 * (l1 * t1.cos() + c2 * s.cos()));
        let scale = G * (m1 * c1 + m2 * (l1 + c2));
        assert_close(&record, "potential", &[u], scale, 1e-14);
        let gradient = [
            G * (m1 * c1 * t1.sin() + m2 * (l1 * t1.sin() + c2 * s.sin())),
            G * m2 * c2 * s.sin(),
        ];
        assert_close(&record, "gradient", &gradient, scale, 1e-14);
        let h12 = G * m2 * c2 * s.cos();
        let hessian = [
            G * (m1 * c1 * t1.cos() + m2 * (l1 * t1.cos() + c2 * s.cos())),
            h12,
            h12,
            h12,
        ];
        assert_close(&record, "hessian", &hessian, scale, 1e-14);
    }
}

/// A cart of mass M on a prismatic joint along x carrying a pendulum (mass m, centre of mass c
/// below the hinge, moment J about it along y) on a hinge about y, read from a URDF file: at
/// (s, θ), A = [[M + m, −m c cos θ], [−m c cos θ, J + m c²]], U = −m g c cos θ,
/// ∂U/∂q = (0, m g c sin θ), ∂²U/∂q² = diag(0, m g c cos θ).
#[test]
fn urdf_cart_pendulum_matrices_match_the_closed_form_at_random_states() {
    let dir = scratch("cart");
    let mut random = Stream(0x2545_f491_4f6c_dd1d);
    for case in 0..4 {
        let (cart, m) = (random.between(0.5, 20.0), random.between(0.1, 5.0));
        let (c, j) = (random.between(0.1, 2.0), random.between(0.01, 1.0));
        let urdf = dir.join(format!("cart{case}.urdf"));
        std::fs::write(
            &urdf,
            format!(
                r#"<?xml version="1.0"?>
<robot name="cart_pendulum">
  <link name="rail"/>
  <link name="cart">
    <inertial><origin xyz="0 0 0"/><mass value="{cart:?}"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <link name="pole">
    <inertial><origin xyz="0 0 {:?}"/><mass value="{m:?}"/>
      <inertia ixx="{j:?}" ixy="0" ixz="0" iyy="{j:?}" iyz="0" izz="{:?}"/></inertial>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="rail"/><child link="cart"/><axis xyz="1 0 0"/>
    <limit lower="-10" upper="10" effort="1" velocity="1"/>
  </joint>
  <joint name="hinge" type="continuous">
    <parent link="cart"/><child link="pole"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"#,
                -c,
                j / 10.0
            ),
        )
        .expect("urdf");
        let (s, theta) = (random.between(-5.0, 5.0), random.between(-3.1, 3.1));
        let record = matrices_at(urdf.to_str().expect("utf-8"), &[s, theta]);
        assert_eq!(record["coordinates"], serde_json::json!(["slide", "hinge"]));
        let j_hinge = j + m * c * c;
        let a = [cart + m, -m * c * theta.cos(), -m * c * theta.cos(), j_hinge];
        assert_close(&record, "mass_matrix", &a, largest(&a), 1e-13);
        let scale = m * G * c;
        assert_close(&record, "potential", &[-scale * theta.cos()], scale, 1e-14);
        assert_close(&record, "gradient", &[0.0, scale * theta.sin()], scale, 1e-14);
        let hessian = [0.0, 0.0, 0.0, scale * theta.cos()];
        assert_close(&record, "hessian", &hessian, scale, 1e-14);
    }
}

/// The text report prints every entry of the matrices, row by row, labelled by coordinate;
/// without a file `--matrices` is refused, and without `--q` it evaluates at q0.
#[test]
fn the_text_report_prints_whole_matrices_and_q0_is_the_default_state() {
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/double_pendulum.toml");
    let scene = scene.to_str().expect("utf-8");
    let (ok, out, err) = mechanica(&["run", scene, "--matrices"]);
    assert!(ok, "{err}");
    // At q0 = 0, unit rods of unit mass: A11 = 1/12 + 1/4 + 1/12 + (1 + 1/4 + 1) = 8/3,
    // A12 = 1/12 + 1/4 + 1/2 = 5/6, A22 = 1/3; B = g [[2, 1/2], [1/2, 1/2]].
    let lines: Vec<String> = out
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect();
    for line in [
        "shoulder [2.666666667, 0.8333333333]",
        "elbow [0.8333333333, 0.3333333333]",
        "shoulder [19.62, 4.905]",
        "elbow [4.905, 4.905]",
    ] {
        assert!(lines.iter().any(|l| l == line), "no line {line:?} in\n{out}");
    }
    let (ok, json, err) = mechanica(&["run", scene, "--matrices", "--json"]);
    assert!(ok, "{err}");
    let report: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    assert_eq!(numbers(&step(&report, "state_matrices")["q"]), vec![0.0, 0.0]);
    let (ok, _, err) = mechanica(&["run", "--matrices"]);
    assert!(!ok && err.contains("--matrices needs a scene"), "{err}");
}

/// A point mass m at distance l from a spherical joint, at a random rotation vector φ: the
/// state is re-centred (the record says so), and whatever the frame of the local rotation
/// vector, A has the invariants of m (l² 1 − p pᵀ) (trace 2 m l², determinant 0), U = m g z
/// with z the height of exp(φ) (0, 0, −l) (Rodrigues), and the Hessian of U = a·x about φ = 0 has
/// trace Σ_k a·(e_k × (e_k × x)) = −2 a·x = −2U.
#[test]
fn a_spherical_joint_is_recentred_and_keeps_the_invariants() {
    let dir = scratch("spherical");
    let mut random = Stream(0x5851_f42d_4c95_7f2d);
    for case in 0..4 {
        let (m, l) = (random.between(0.2, 5.0), random.between(0.2, 2.0));
        let scene = dir.join(format!("ball{case}.toml"));
        std::fs::write(
            &scene,
            format!(
                r#"title = "spherical pendulum"
gravity = [0.0, 0.0, -9.81]
[[body]]
name = "bob"
primitive = {{ shape = "point", mass = {m:?} }}
offset = [0.0, 0.0, {:?}]
[[joint]]
name = "ball"
type = "spherical"
parent = "ground"
child = "bob"
"#,
                -l
            ),
        )
        .expect("scene");
        let phi = [
            random.between(-1.5, 1.5),
            random.between(-1.5, 1.5),
            random.between(-1.5, 1.5),
        ];
        let record = matrices_at(scene.to_str().expect("utf-8"), &phi);
        assert_eq!(record["recentred"], true);
        assert_eq!(
            record["coordinates"],
            serde_json::json!(["ball[0]", "ball[1]", "ball[2]"])
        );
        let a = numbers(&record["mass_matrix"]);
        let scale = m * l * l;
        let trace = a[0] + a[4] + a[8];
        assert!(
            (trace - 2.0 * scale).abs() <= 1e-13 * scale,
            "trace {trace} vs {}",
            2.0 * scale
        );
        let det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
            + a[2] * (a[3] * a[7] - a[4] * a[6]);
        assert!(det.abs() <= 1e-12 * scale.powi(3), "det {det}");
        // exp(φ) p with p = (0, 0, −l): z = −l [cos θ + (1 − cos θ) n_z²].
        let theta = (phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]).sqrt();
        let nz = phi[2] / theta;
        let z = -l * (theta.cos() + (1.0 - theta.cos()) * nz * nz);
        let u = m * G * z;
        let potential = record["potential"].as_f64().expect("U*");
        assert!((potential - u).abs() <= 1e-13 * m * G * l, "U {potential} vs {u}");
        let h = numbers(&record["hessian"]);
        let h_trace = h[0] + h[4] + h[8];
        assert!(
            (h_trace + 2.0 * u).abs() <= 1e-13 * m * G * l,
            "tr B {h_trace} vs {}",
            -2.0 * u
        );
    }
}
