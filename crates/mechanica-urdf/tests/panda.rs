//! The Panda arm of examples/cpp/panda_modes/panda.urdf (written by tools/panda_urdf.py from
//! the Pinocchio model in tools/dynamics_pinocchio_reference.json) read back: its mass matrix
//! A(q) at the reference states equals Pinocchio's crba, max |A − A_pin| ≤ 1e-12 max |A_pin|,
//! which checks the rpy placements, the inertial frames and the body order of the reader. The
//! URDF's decimals (15 places) perturb A by about 1e-15 relative, well inside the bound.

use mechanica_mechanism::Mechanism;
use mechanica_urdf::{UrdfOptions, read_file, read_str};
use serde_json::Value;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// Pinocchio's Panda states: q and the row-major crba.
fn panda_states() -> Vec<(Vec<f64>, Vec<f64>)> {
    let text =
        std::fs::read_to_string(root().join("tools/dynamics_pinocchio_reference.json")).expect("the reference file");
    let document: Value = serde_json::from_str(&text).expect("JSON");
    let numbers = |v: &Value| -> Vec<f64> { v.as_array().expect("array").iter().filter_map(Value::as_f64).collect() };
    let panda = document["models"]
        .as_array()
        .expect("models")
        .iter()
        .find(|m| m["name"] == "panda")
        .expect("the panda model");
    panda["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(|s| (numbers(&s["q"]), numbers(&s["crba"])))
        .collect()
}

#[test]
fn the_panda_mass_matrix_matches_pinocchio_crba() {
    let robot = read_file(
        &root().join("examples/cpp/panda_modes/panda.urdf"),
        UrdfOptions::default(),
    )
    .expect("panda");
    let urdf = robot.tree().expect("a tree");
    assert_eq!(urdf.tree.dof(), 9);
    assert_eq!(urdf.coordinate_names[0], "panda_joint1");
    assert_eq!(urdf.link_names[0], "panda_link0");
    assert_eq!(urdf.limits[3], Some([-3.0718, -0.0698]));
    let mut mechanism = Mechanism::new(urdf.tree, urdf.masses).expect("mechanism");
    let states = panda_states();
    assert!(!states.is_empty());
    for (q, crba) in states {
        let a = mechanism.mass_matrix(&q).expect("A(q)");
        let scale = crba.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let mut worst = 0.0_f64;
        for i in 0..9 {
            for j in 0..9 {
                worst = worst.max((a[(i, j)] - crba[9 * i + j]).abs());
            }
        }
        assert!(
            worst <= 1e-12 * scale,
            "max |A − A_pin| = {worst:e}, max |A_pin| = {scale}"
        );
    }
}

#[test]
fn broken_descriptions_name_the_joint_or_link_and_the_field() {
    let good = r#"<robot name="r"><link name="a"/><link name="b"/>
        <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint></robot>"#;
    let here = Path::new(".");
    let tree = read_str(good, here, UrdfOptions::default())
        .expect("good")
        .tree()
        .expect("tree");
    assert_eq!(tree.joint_names, ["", "j"]);
    let cases = [
        (
            good.replace(r#"<parent link="a"/>"#, r#"<parent link="x"/>"#),
            "joint \"j\": parent link \"x\"",
        ),
        (
            good.replace(r#"<link name="b"/>"#, r#"<link name="b"/><link name="b"/>"#),
            "link \"b\": two links",
        ),
        (
            good.replace(
                r#"<axis xyz="0 0 1"/>"#,
                r#"<origin xyz="0 inf 0"/><axis xyz="0 0 1"/>"#,
            ),
            "joint \"j\": origin",
        ),
    ];
    for (text, expected) in cases {
        let error = read_str(&text, here, UrdfOptions::default())
            .and_then(|r| r.tree())
            .expect_err("broken");
        assert!(error.to_string().contains(expected), "{error} (expected {expected})");
    }
}
