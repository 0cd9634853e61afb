//! `mechanica run` on URDF robots whose links take their mass from meshes: a usable mesh gives
//! the closed-form pendulum frequency, an unusable one (missing file, `package://` path, a
//! `.dae`, a misspelt name) is an error naming the link and the mesh unless
//! `--allow-missing-mesh` makes the link massless with a warning.

use std::path::PathBuf;
mod common;
use common::{mechanica, omega_sq, step, values};

const G: f64 = 9.81;

/// A fresh directory under the system temp dir, unique to this test and process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-urdf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// An OBJ cube of side `s` centred on the origin, faces counter-clockwise seen from outside.
fn cube_obj(s: f64) -> String {
    let h = 0.5 * s;
    let mut text = String::new();
    for k in 0..8 {
        let c = |bit: usize| if k & bit != 0 { h } else { -h };
        text.push_str(&format!("v {} {} {}\n", c(1), c(2), c(4)));
    }
    // Corner k (1-based k + 1 in OBJ) has x bit 1, y bit 2, z bit 4.
    for [a, b, c] in [
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ] {
        text.push_str(&format!("f {} {} {}\n", a + 1, b + 1, c + 1));
    }
    text
}

/// A rod pendulum (1 kg, 1 m, hinge about y) carrying, by a fixed joint at its tip, one tool
/// link per mesh file name in `meshes`, each without `<inertial>`.
fn pendulum_with_tools(meshes: &[&str]) -> String {
    let mut text = String::from(
        r#"<?xml version="1.0"?>
<robot name="tooled_pendulum">
  <link name="base"/>
  <link name="upper">
    <inertial>
      <origin xyz="0 0 -0.5" rpy="0 0 0"/>
      <mass value="1.0"/>
      <inertia ixx="0.08333333333333333" ixy="0" ixz="0" iyy="0.08333333333333333" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
  <joint name="hinge" type="continuous">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
"#,
    );
    for (i, mesh) in meshes.iter().enumerate() {
        text.push_str(&format!(
            r#"  <link name="tool{i}">
    <visual><geometry><box size="1 1 1"/></geometry></visual>
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <joint name="mount{i}" type="fixed">
    <parent link="upper"/><child link="tool{i}"/>
    <origin xyz="0 0 -1" rpy="0 0 0"/>
  </joint>
"#
        ));
    }
    text.push_str("</robot>\n");
    text
}

/// ω² of the rod pendulum alone: m g d / I_pivot with d = 1/2, I_pivot = 1/12 + 1/4.
fn rod_alone() -> f64 {
    G * 0.5 / (1.0 / 12.0 + 0.25)
}

fn lowest_omega_sq(out: &str) -> f64 {
    let json: serde_json::Value = serde_json::from_str(out).expect("JSON report");
    omega_sq(&json)[0]
}

#[test]
fn a_usable_mesh_gives_the_link_its_mass_at_water_density() {
    let dir = scratch("usable");
    std::fs::write(dir.join("cube.obj"), cube_obj(0.1)).expect("mesh");
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, pendulum_with_tools(&["cube.obj"])).expect("urdf");
    let (ok, out, err) = mechanica(&["run", urdf.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    assert!(out.contains("mass properties from mesh"), "{out}");
    // Cube of 0.1 m at 1000 kg/m³: 1 kg at 1 m below the hinge, central moment m s²/6.
    let (m_cube, i_cube) = (1.0, 0.01 / 6.0);
    let exact = G * (0.5 + m_cube) / (1.0 / 12.0 + 0.25 + i_cube + m_cube);
    let got = lowest_omega_sq(&out);
    assert!((got - exact).abs() <= 1e-10 * exact, "{got} vs {exact}");
    // The start of the analyses is printed, with the coordinate named after its URDF joint.
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
    let build = step(&json, "build");
    assert_eq!(build["coordinates"], serde_json::json!(["hinge"]));
    assert_eq!(values(&json, "build", "q0"), vec![0.0]);
}

#[test]
fn unusable_meshes_are_errors_naming_each_link_and_mesh() {
    let dir = scratch("unusable");
    std::fs::write(dir.join("cube.obj"), cube_obj(0.1)).expect("mesh");
    std::fs::write(dir.join("tool.dae"), "<COLLADA/>\n").expect("dae");
    let meshes = ["package://robot/meshes/tool.stl", "tool.dae", "cub.obj"];
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, pendulum_with_tools(&meshes)).expect("urdf");
    let (ok, out, err) = mechanica(&["run", urdf.to_str().expect("path")]);
    assert!(!ok, "must refuse:\n{out}");
    assert!(out.is_empty(), "nothing half-written: {out}");
    assert!(
        err.contains("--allow-missing-mesh") && err.contains("robot.urdf"),
        "{err}"
    );
    for (i, mesh) in meshes.iter().enumerate() {
        assert!(
            err.contains(&format!("link \"tool{i}\": mesh \"{mesh}\"")),
            "tool{i} / {mesh}: {err}"
        );
    }
    assert!(
        err.contains("not found") && err.contains("unknown mesh format"),
        "{err}"
    );
}

#[test]
fn allow_missing_mesh_makes_the_links_massless_with_a_warning_in_text_and_json() {
    let dir = scratch("allowed");
    let meshes = ["package://robot/meshes/tool.stl", "tool.dae"];
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, pendulum_with_tools(&meshes)).expect("urdf");
    let path = urdf.to_str().expect("path");
    let (ok, out, err) = mechanica(&["run", path, "--json", "--allow-missing-mesh"]);
    assert!(ok, "{err}");
    // Massless tools leave the rod's own frequency.
    let got = lowest_omega_sq(&out);
    assert!(
        (got - rod_alone()).abs() <= 1e-10 * rod_alone(),
        "{got} vs {}",
        rod_alone()
    );
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let notes: Vec<&str> = json["steps"]
        .as_array()
        .expect("steps")
        .iter()
        .flat_map(|s| s["warnings"].as_array().into_iter().flatten())
        .filter_map(|n| n.as_str())
        .collect();
    assert!(notes.iter().all(|n| n.starts_with("warning:")), "{notes:?}");
    assert_eq!(notes.len(), meshes.len(), "{notes:?}");
    for (i, mesh) in meshes.iter().enumerate() {
        assert!(
            notes
                .iter()
                .any(|n| n.contains(&format!("link \"tool{i}\"")) && n.contains(mesh)),
            "{notes:?}"
        );
    }
    let (ok, text, err) = mechanica(&["run", path, "--allow-missing-mesh"]);
    assert!(ok, "{err}");
    assert!(
        text.contains("warning: link \"tool0\"") && text.contains("massless"),
        "{text}"
    );
}

/// Two uniform rods (masses m₁, m₂, lengths l₁, l₂, hinges about y) hanging from a shoulder:
/// a double compound pendulum.
fn two_rods(m1: f64, l1: f64, m2: f64, l2: f64) -> String {
    let link = |name: &str, m: f64, l: f64| {
        let i = m * l * l / 12.0;
        format!(
            r#"  <link name="{name}">
    <inertial>
      <origin xyz="0 0 {:?}" rpy="0 0 0"/>
      <mass value="{m:?}"/>
      <inertia ixx="{i:?}" ixy="0" ixz="0" iyy="{i:?}" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
"#,
            -0.5 * l
        )
    };
    format!(
        r#"<?xml version="1.0"?>
<robot name="two_rods">
  <link name="base"/>
{}{}  <joint name="shoulder" type="continuous">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="continuous">
    <parent link="upper"/><child link="lower"/>
    <origin xyz="0 0 {:?}" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"#,
        link("upper", m1, l1),
        link("lower", m2, l2),
        -l1
    )
}

/// What a script reads from the JSON report (examples/read_report.py does the same): the
/// first mode's frequency, and the name of the coordinate that moves most in it. Reference:
/// in absolute angles φ the pendulum has M = [[m₁l₁²/3 + m₂l₁², m₂l₁l₂/2], [m₂l₁l₂/2, m₂l₂²/3]]
/// and K = g diag(m₁l₁/2 + m₂l₁, m₂l₂/2); the joint angles are θ₁ = φ₁, θ₂ = φ₂ − φ₁.
#[test]
fn a_script_finds_the_first_frequency_and_the_coordinate_that_moves_most() {
    let dir = scratch("script");
    let cases = [
        (1.0, 1.0, 1.0, 1.0),
        (2.0, 0.5, 0.1, 1.5),
        (0.3, 1.2, 4.0, 0.2),
        (1.0, 0.8, 0.5, 2.0),
    ];
    let mut movers = std::collections::BTreeSet::new();
    for (case, (m1, l1, m2, l2)) in cases.into_iter().enumerate() {
        let urdf = dir.join(format!("rods{case}.urdf"));
        std::fs::write(&urdf, two_rods(m1, l1, m2, l2)).expect("urdf");
        let (ok, out, err) = mechanica(&["run", urdf.to_str().expect("path"), "--json"]);
        assert!(ok, "{err}");
        let report: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
        let modes = step(&report, "modes");
        let first = &modes["modes"][0];
        assert_eq!(first["kind"], "oscillatory");
        let frequency = first["frequency_hz"].as_f64().expect("frequency");
        let shape: Vec<f64> = first["shape"]
            .as_array()
            .expect("shape")
            .iter()
            .filter_map(|v| v.as_f64())
            .collect();
        let largest = (0..shape.len())
            .max_by(|&a, &b| shape[a].abs().total_cmp(&shape[b].abs()))
            .expect("entries");
        let mover = modes["coordinates"][largest].as_str().expect("name");
        // The closed form.
        let (a11, a12, a22) = (
            m1 * l1 * l1 / 3.0 + m2 * l1 * l1,
            0.5 * m2 * l1 * l2,
            m2 * l2 * l2 / 3.0,
        );
        let (k1, k2) = (G * (0.5 * m1 * l1 + m2 * l1), G * 0.5 * m2 * l2);
        let (a, b, c) = (a11 * a22 - a12 * a12, -(k1 * a22 + k2 * a11), k1 * k2);
        let w2 = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        let exact = w2.sqrt() / std::f64::consts::TAU;
        assert!(
            (frequency - exact).abs() <= 1e-10 * exact,
            "case {case}: {frequency} vs {exact}"
        );
        let phi = [a12 * w2, k1 - a11 * w2];
        let theta = [phi[0], phi[1] - phi[0]];
        let expected = if theta[0].abs() > theta[1].abs() {
            "shoulder"
        } else {
            "elbow"
        };
        assert_eq!(mover, expected, "case {case}: θ ∝ {theta:?}, shape {shape:?}");
        movers.insert(expected);
    }
    assert_eq!(movers.len(), 2, "the cases exercise both answers: {movers:?}");
}

/// `--q` evaluates at a given configuration without an equilibrium search: a uniform rod of
/// mass m and length l hinged at its end, linearised at θ, has ω² = 3g cos θ / (2l) (U = −mg(l/2)
/// cos θ, A = ml²/3), oscillatory below π/2 and unstable beyond; the report's q0 is the given q,
/// and a wrong count of values is refused naming the coordinates.
#[test]
fn the_modes_at_a_given_configuration_match_the_linearised_rod() {
    let dir = scratch("state");
    let (m, l) = (0.7, 1.3);
    let i = m * l * l / 12.0;
    let urdf = dir.join("rod.urdf");
    std::fs::write(
        &urdf,
        format!(
            r#"<?xml version="1.0"?>
<robot name="rod">
  <link name="base"/>
  <link name="rod">
    <inertial>
      <origin xyz="0 0 {:?}" rpy="0 0 0"/>
      <mass value="{m:?}"/>
      <inertia ixx="{i:?}" ixy="0" ixz="0" iyy="{i:?}" iyz="0" izz="1e-6"/>
    </inertial>
  </link>
  <joint name="hinge" type="continuous">
    <parent link="base"/><child link="rod"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
</robot>
"#,
            -0.5 * l
        ),
    )
    .expect("urdf");
    let path = urdf.to_str().expect("path");
    for theta in [0.3, -1.1, 2.0, -2.9] {
        let q = format!("{theta:?}");
        let (ok, out, err) = mechanica(&["run", path, "--q", &q, "--json"]);
        assert!(ok, "{err}");
        let report: serde_json::Value = serde_json::from_str(&out).expect("JSON report");
        assert_eq!(values(&report, "build", "q0"), vec![theta]);
        assert!(
            report["steps"]
                .as_array()
                .expect("steps")
                .iter()
                .all(|s| s["analysis"] != "equilibrium"),
            "no equilibrium search with --q"
        );
        let want = 1.5 * G * f64::cos(theta) / l;
        let got = omega_sq(&report)[0];
        assert!(
            (got - want).abs() <= 1e-10 * want.abs(),
            "θ = {theta}: ω² {got} vs {want}"
        );
        let kind = &step(&report, "modes")["modes"][0]["kind"];
        assert_eq!(kind, if want > 0.0 { "oscillatory" } else { "unstable" }, "θ = {theta}");
    }
    let (ok, _, err) = mechanica(&["run", path, "--q", "0.1,0.2"]);
    assert!(
        !ok && err.contains("--q has 2 values") && err.contains("hinge"),
        "{err}"
    );
    let (ok, _, err) = mechanica(&["run", "--q", "0.1"]);
    assert!(!ok && err.contains("--q needs a scene"), "{err}");
}

/// A link named `ground` (the scene's name for the world) is renamed with a note, and a
/// massless link on a joint without springs (a finger with neither `<inertial>` nor mesh) is
/// left out of the modes and named as such: the double rod's frequencies are unchanged.
#[test]
fn a_ground_link_and_a_massless_finger_do_not_stop_the_run() {
    let dir = scratch("ground");
    let plain = dir.join("plain.urdf");
    std::fs::write(&plain, two_rods(1.0, 0.8, 0.5, 0.6)).expect("urdf");
    let (ok, out, err) = mechanica(&["run", plain.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    let reference = omega_sq(&serde_json::from_str(&out).expect("JSON"));
    let finger = r#"  <link name="finger"/>
  <joint name="finger_joint" type="revolute">
    <parent link="lower"/><child link="finger"/>
    <origin xyz="0 0 -0.6" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"#;
    let text = two_rods(1.0, 0.8, 0.5, 0.6)
        .replace(r#""base""#, r#""ground""#)
        .replace("</robot>", finger);
    let quirky = dir.join("quirky.urdf");
    std::fs::write(&quirky, text).expect("urdf");
    let (ok, out, err) = mechanica(&["run", quirky.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    assert!(
        out.contains(r#"link \"ground\" is called \"ground (URDF link)\""#),
        "{out}"
    );
    let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(step(&json, "modes")["idle"], serde_json::json!(["finger_joint"]));
    let got = omega_sq(&json);
    assert_eq!(got.len(), reference.len());
    for (g, r) in got.iter().zip(&reference) {
        assert!((g - r).abs() <= 1e-12 * r, "{g} vs {r}");
    }
}

/// A robot without coordinates (one link, or links joined by fixed joints) runs, and takes an
/// empty `--q` as its configuration; a `--q` with a value that is not a number names it.
#[test]
fn a_robot_without_coordinates_takes_an_empty_q() {
    let dir = scratch("rigid");
    let urdf = dir.join("rigid.urdf");
    let text = r#"<robot name="rigid">
  <link name="body"><inertial><mass value="1.5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
</robot>"#;
    std::fs::write(&urdf, text).expect("urdf");
    let path = urdf.to_str().expect("path");
    for args in [vec!["run", path, "--json"], vec!["run", path, "--json", "--q", ""]] {
        let (ok, out, err) = mechanica(&args);
        assert!(ok, "{args:?}: {err}");
        let json: serde_json::Value = serde_json::from_str(&out).expect("JSON");
        assert_eq!(step(&json, "build")["dof"], serde_json::json!(0), "{args:?}");
    }
    let (ok, _, err) = mechanica(&["run", path, "--q", "0.5,zero"]);
    assert!(!ok && err.contains("\"zero\" is not a number"), "{err}");
}

/// A tool link that declares a zero mass with a rotational inertia (as robot files write for
/// feet and rotors) keeps that tensor and ignores its mesh: the pendulum's ω² is
/// m g d / (I_pivot + I_tool,yy), as Pinocchio builds it. A zero-mass tensor no body could have
/// is refused, naming the link.
#[test]
fn a_declared_zero_mass_keeps_its_tensor_and_ignores_the_mesh() {
    let dir = scratch("zero-mass");
    std::fs::write(dir.join("cube.obj"), cube_obj(0.1)).expect("mesh");
    let tool_iyy = 0.02;
    let declared = |iyy: f64| {
        pendulum_with_tools(&["cube.obj"]).replace(
            r#"<link name="tool0">"#,
            &format!(
                r#"<link name="tool0"><inertial><mass value="0"/>
                <inertia ixx="{iyy}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{iyy}"/></inertial>"#
            ),
        )
    };
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, declared(tool_iyy)).expect("urdf");
    let (ok, out, err) = mechanica(&["run", urdf.to_str().expect("path"), "--json"]);
    assert!(ok, "{err}");
    assert!(!out.contains("mass properties from mesh"), "{out}");
    let exact = G * 0.5 / (1.0 / 12.0 + 0.25 + tool_iyy);
    let got = lowest_omega_sq(&out);
    assert!((got - exact).abs() <= 1e-10 * exact, "{got} vs {exact}");
    std::fs::write(&urdf, declared(-tool_iyy)).expect("urdf");
    let (ok, _, err) = mechanica(&["run", urdf.to_str().expect("path")]);
    assert!(!ok && err.contains("tool0") && err.contains("semidefinite"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
