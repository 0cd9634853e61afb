//! The `mechanica run` command on scene files and URDF robots: closed-form results through the
//! whole pipeline, and located errors for bad input.

use std::path::{Path, PathBuf};
mod common;
use common::{mechanica, omega_sq, values};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-scenes-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes")
}

#[test]
fn rotating_hoop_scene_finds_the_relative_equilibrium_and_its_frequency() {
    let path = examples().join("rotating_hoop.toml");
    let (ok, out, err) = mechanica(&["run", path.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
    let (g, r, rate) = (9.81_f64, 0.5_f64, 6.0_f64);
    let theta = (g / (rate * rate * r)).acos();
    let q = values(&json, "equilibrium", "q");
    assert!((q[0].abs() - theta).abs() < 1e-10, "θ = {q:?} vs ±{theta}");
    let w2 = omega_sq(&json);
    let exact = rate * rate * theta.sin().powi(2);
    assert!((w2[0] - exact).abs() < 1e-10 * exact, "{w2:?} vs {exact}");
}

#[test]
fn chain_scene_reports_stable_modes_response_and_plots() {
    let path = examples().join("spring_pendulum_chain.toml");
    let plots = scratch("plots");
    let (ok, out, err) = mechanica(&[
        "run",
        path.to_str().expect("path"),
        "--plot",
        plots.to_str().expect("dir"),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("stable: every mode oscillates"), "{out}");
    assert!(out.contains("free response"), "{out}");
    for file in ["spectrum.svg", "mode_shapes.svg", "response.svg"] {
        let text = std::fs::read_to_string(plots.join(file)).expect("svg written");
        assert!(text.starts_with("<svg"), "{file}");
    }
}

#[test]
fn double_pendulum_of_point_masses_through_a_scene_file() {
    let dir = scratch("double");
    let scene = dir.join("double.toml");
    std::fs::write(
        &scene,
        r#"title = "double pendulum of point masses"
gravity = [0.0, 0.0, -9.81]
[[body]]
name = "a"
primitive = { shape = "point", mass = 2.0 }
offset = [0.0, 0.0, -0.5]
[[body]]
name = "b"
primitive = { shape = "point", mass = 2.0 }
offset = [0.0, 0.0, -0.5]
[[joint]]
name = "j1"
type = "revolute"
parent = "ground"
child = "a"
axis = [0.0, 1.0, 0.0]
q0 = [0.4]
[[joint]]
name = "j2"
type = "revolute"
parent = "a"
child = "b"
axis = [0.0, 1.0, 0.0]
origin = [0.0, 0.0, -0.5]
q0 = [-0.3]
[analyses]
equilibrium = {}
modes = {}
"#,
    )
    .expect("write scene");
    let (ok, out, err) = mechanica(&["run", scene.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let w2 = omega_sq(&json);
    let s = 2f64.sqrt();
    for (got, exact) in w2.iter().zip([(2.0 - s) * 9.81 / 0.5, (2.0 + s) * 9.81 / 0.5]) {
        assert!((got - exact).abs() < 1e-12 * exact, "{got} vs {exact}");
    }
}

#[test]
fn bad_scenes_give_located_errors() {
    let dir = scratch("bad");
    let base = std::fs::read_to_string(examples().join("double_pendulum.toml")).expect("example");
    let cases = [
        ("unknown_field", base.replace("origin = [0.0, 0.0, -1.0]", "orgin = [0.0, 0.0, -1.0]"), "orgin"),
        ("missing_body", base.replace("parent = \"upper\"", "parent = \"uper\""), "joint[1].parent"),
        ("cycle", base.replace("parent = \"ground\"", "parent = \"lower\""), "cycle"),
        (
            "missing_mesh",
            base.replace(
                "primitive = { shape = \"rod\", length = 1.0, mass = 1.0 }\noffset = [0.0, 0.0, -0.5]\n\n[[body]]\nname = \"lower\"",
                "mesh = { file = \"no_such_mesh.stl\", density = 1000.0 }\n\n[[body]]\nname = \"lower\"",
            ),
            "no_such_mesh.stl",
        ),
        (
            "bad_spring",
            format!("{base}\n[[spring]]\na = \"nobody\"\nb = \"ground\"\nstiffness = 1.0\n"),
            "spring[0].a",
        ),
    ];
    for (name, text, expected) in cases {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, &text).expect("write");
        let (ok, out, err) = mechanica(&["run", path.to_str().expect("path")]);
        assert!(!ok, "{name} should fail:\n{out}");
        assert!(err.contains(expected), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name}: the error names the file: {err}"
        );
        assert!(out.is_empty(), "{name}: nothing half-written: {out}");
    }
}

#[test]
fn a_search_that_cannot_converge_reports_the_best_point() {
    let dir = scratch("diverge");
    let path = dir.join("push.toml");
    std::fs::write(
        &path,
        r#"title = "a pushed slider"
[[body]]
name = "slider"
primitive = { shape = "point", mass = 1.0 }
[[joint]]
name = "rail"
type = "prismatic"
parent = "ground"
child = "slider"
axis = [1.0, 0.0, 0.0]
[[force]]
body = "slider"
force = [1.0, 0.0, 0.0]
[analyses]
equilibrium = { max_iterations = 5 }
"#,
    )
    .expect("write");
    let (ok, _, err) = mechanica(&["run", path.to_str().expect("path")]);
    assert!(!ok);
    assert!(
        err.contains("did not converge") && err.contains("best |grad U*|") && err.contains("at q ="),
        "{err}"
    );
}

const URDF: &str = r#"<?xml version="1.0"?>
<robot name="two_link">
  <link name="base"/>
  <link name="upper">
    <inertial>
      <origin xyz="0 0 -0.5" rpy="0 0 0"/>
      <mass value="1.0"/>
      <inertia ixx="IXX" ixy="0" ixz="0" iyy="0.0833" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
  <link name="lower">
    <inertial>
      <origin xyz="0 0 -0.5" rpy="0 0 0"/>
      <mass value="1.0"/>
      <inertia ixx="0.0833" ixy="0" ixz="0" iyy="0.0833" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
  <joint name="shoulder" type="continuous">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="lower"/>
    <origin xyz="0 0 -1" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="1"/>
  </joint>
</robot>
"#;

#[test]
fn a_urdf_robot_runs_and_invalid_inertias_are_reported_per_link() {
    let dir = scratch("urdf");
    let good = dir.join("good.urdf");
    std::fs::write(&good, URDF.replace("IXX", "0.0833")).expect("write");
    let (ok, out, err) = mechanica(&["run", good.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    // Two rods hanging: a double compound pendulum, two oscillatory modes.
    let w2 = omega_sq(&json);
    assert_eq!(w2.len(), 2);
    assert!(w2.iter().all(|w| *w > 0.0), "{w2:?}");
    let bad = dir.join("bad.urdf");
    std::fs::write(&bad, URDF.replace("IXX", "1.0")).expect("write");
    let (ok, _, err) = mechanica(&["run", bad.to_str().expect("path")]);
    assert!(!ok);
    assert!(
        err.contains("link \"upper\"") && err.contains("--repair-inertia"),
        "{err}"
    );
    let (ok, out, err) = mechanica(&["run", bad.to_str().expect("path"), "--repair-inertia"]);
    assert!(ok, "{err}");
    assert!(out.contains("inertia repaired"), "{out}");
    // A dangling reference is named by field; a URDF-built scene has no TOML positions to show.
    let dangling = dir.join("dangling.urdf");
    let text = URDF
        .replace("IXX", "0.0833")
        .replace(r#"<parent link="upper"/>"#, r#"<parent link="nowhere"/>"#);
    std::fs::write(&dangling, text).expect("write");
    let (ok, _, err) = mechanica(&["run", dangling.to_str().expect("path")]);
    assert!(!ok);
    assert!(
        err.contains("joint[2].parent") && err.contains("no body named \"nowhere\"") && !err.contains(":1:1"),
        "{err}"
    );
}

#[test]
fn a_response_over_the_value_limit_is_refused_at_once_and_the_limit_can_be_raised() {
    let dir = scratch("limit");
    let chain = std::fs::read_to_string(examples().join("spring_pendulum_chain.toml")).expect("example");
    let huge = dir.join("huge.toml");
    std::fs::write(&huge, chain.replace("samples = 400", "samples = 10000000000")).expect("write");
    let (ok, out, err) = mechanica(&["run", huge.to_str().expect("path")]);
    assert!(!ok && out.is_empty(), "{out}");
    let line = chain.lines().position(|l| l.starts_with("response =")).map(|i| i + 1);
    assert!(
        err.contains(&format!("huge.toml:{}:", line.expect("response line")))
            && err.contains("field analyses.response.samples")
            && err.contains("--max-response-values"),
        "{err}"
    );
    // The example stores 400 × (3 + 1) values: refused under a limit of 1599, run under 1600.
    let example = examples().join("spring_pendulum_chain.toml");
    let example = example.to_str().expect("path");
    let (ok, _, err) = mechanica(&["run", example, "--max-response-values", "1599"]);
    assert!(!ok && err.contains("1600 values"), "{err}");
    let (ok, out, err) = mechanica(&["run", example, "--max-response-values", "1600"]);
    assert!(ok && out.contains("free response"), "{err}");
}

#[test]
fn results_that_overflow_are_refused_with_a_non_zero_exit() {
    let dir = scratch("overflow");
    let base = std::fs::read_to_string(examples().join("double_pendulum.toml")).expect("example");
    let heavy = "primitive = { shape = \"rod\", length = 1.0, mass = 1e308 }";
    for (name, text) in [
        (
            "heavy_upper",
            base.replacen("primitive = { shape = \"rod\", length = 1.0, mass = 1.0 }", heavy, 1),
        ),
        (
            "heavy_both",
            base.replace("primitive = { shape = \"rod\", length = 1.0, mass = 1.0 }", heavy),
        ),
        (
            "heavy_with_modes",
            base.replacen("primitive = { shape = \"rod\", length = 1.0, mass = 1.0 }", heavy, 1)
                .replace("mass_properties = true", "equilibrium = {}\nmodes = {}"),
        ),
    ] {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).expect("write");
        for json in [false, true] {
            let mut args = vec!["run", path.to_str().expect("path")];
            if json {
                args.push("--json");
            }
            let (ok, out, err) = mechanica(&args);
            assert!(!ok, "{name}: must fail:\n{out}");
            assert!(out.is_empty(), "{name}: nothing half-written: {out}");
            // Every refusal names the offending value, or the quantity that overflows.
            assert!(
                err.contains("inf") || err.contains("NaN") || err.contains("overflows"),
                "{name}: {err}"
            );
        }
    }
}
