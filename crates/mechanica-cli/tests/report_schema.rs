//! The JSON report of every command validates against docs/report.schema.json (JSON Schema
//! draft 2020-12), and the schema is strict: a report with a wrong type, a missing required
//! key, an unknown key or an unknown enum value fails.

use std::path::{Path, PathBuf};
mod common;
use common::mechanica;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn validator() -> jsonschema::Validator {
    let text = std::fs::read_to_string(repo().join("docs/report.schema.json")).expect("schema file");
    let schema: serde_json::Value = serde_json::from_str(&text).expect("schema is JSON");
    jsonschema::meta::validate(&schema).expect("a valid draft 2020-12 schema");
    jsonschema::validator_for(&schema).expect("schema compiles")
}

/// The JSON report of `mechanica args… --json`.
fn report(args: &[&str]) -> serde_json::Value {
    let mut args = args.to_vec();
    args.push("--json");
    let (ok, out, err) = mechanica(&args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(&out).expect("JSON report")
}

/// Every schema violation of `instance`, as text (empty when valid).
fn violations(validator: &jsonschema::Validator, instance: &serde_json::Value) -> Vec<String> {
    validator
        .iter_errors(instance)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-schema-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A symmetric Matrix Market file of order n from (row, col, value) entries, lower triangle.
fn write_matrix(path: &Path, n: usize, entries: &[(usize, usize, f64)]) {
    let mut text = format!(
        "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
        entries.len()
    );
    for (r, c, v) in entries {
        text.push_str(&format!("{} {} {v:?}\n", r + 1, c + 1));
    }
    std::fs::write(path, text).expect("write matrix");
}

/// The reports of every command on the repository's examples and fixtures, by name.
fn every_report() -> Vec<(String, serde_json::Value)> {
    let root = repo();
    let path = |p: &str| root.join(p).to_str().expect("utf-8 path").to_string();
    let mut reports = Vec::new();
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(root.join("examples/scenes"))
        .expect("examples")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5, "{scenes:?}");
    for scene in scenes {
        let name = scene.display().to_string();
        reports.push((name, report(&["run", scene.to_str().expect("utf-8")])));
    }
    reports.push(("default scene".into(), report(&[])));
    let pendulum = path("examples/scenes/double_pendulum.toml");
    reports.push((
        format!("{pendulum} --q --matrices"),
        report(&["run", &pendulum, "--q", "0.3,-1.2", "--matrices"]),
    ));
    let panda = path("examples/cpp/panda_modes/panda.urdf");
    reports.push((panda.clone(), report(&["run", &panda])));
    reports.push(("URDF with massless links".into(), urdf_with_warnings()));
    let mesh = path("crates/mechanica-mass/tests/data/robot-meshes/allegro_link_0.0.stl");
    reports.push((format!("mass {mesh}"), report(&["mass", &mesh])));
    reports.push((format!("mass --shell {mesh}"), report(&["mass", &mesh, "--shell"])));
    reports.extend(pencil_reports());
    reports.push(("version".into(), report(&["version"])));
    reports
}

/// A URDF pendulum with a tool link whose mesh is missing, run with `--allow-missing-mesh`: the
/// report carries a warning.
fn urdf_with_warnings() -> serde_json::Value {
    let urdf = scratch("warnings").join("tool.urdf");
    std::fs::write(
        &urdf,
        r#"<?xml version="1.0"?>
<robot name="tooled">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="0 0 -0.5"/><mass value="1"/>
      <inertia ixx="0.08" ixy="0" ixz="0" iyy="0.08" iyz="0" izz="1e-6"/></inertial>
  </link>
  <link name="tool"><collision><geometry><mesh filename="missing.stl"/></geometry></collision></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <joint name="mount" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0 0 -1"/></joint>
</robot>
"#,
    )
    .expect("urdf");
    let json = report(&["run", urdf.to_str().expect("utf-8"), "--allow-missing-mesh"]);
    let warnings = common::step(&json, "build")["warnings"]
        .as_array()
        .expect("warnings")
        .len();
    assert_eq!(warnings, 1, "{json}");
    json
}

/// `modes` on a dense pencil with shapes, with values only, and on a sparse one (the grid
/// Laplacian above the dense limit, by Lanczos).
fn pencil_reports() -> Vec<(String, serde_json::Value)> {
    let dir = scratch("pencils");
    let (a, b) = (dir.join("a.mtx"), dir.join("b.mtx"));
    write_matrix(&a, 3, &[(0, 0, 2.0), (1, 1, 1.0), (2, 2, 0.0)]);
    write_matrix(
        &b,
        3,
        &[(0, 0, 2.0), (1, 0, -1.0), (1, 1, 2.0), (2, 1, -1.0), (2, 2, 2.0)],
    );
    let (a, b) = (a.to_str().expect("utf-8"), b.to_str().expect("utf-8"));
    let side = 25;
    let mut grid = Vec::new();
    for j in 0..side {
        for i in 0..side {
            let r = i + side * j;
            grid.push((r, r, 4.0));
            if i > 0 {
                grid.push((r, r - 1, -1.0));
            }
            if j > 0 {
                grid.push((r, r - side, -1.0));
            }
        }
    }
    let identity: Vec<_> = (0..side * side).map(|i| (i, i, 1.0)).collect();
    let (ga, gb) = (dir.join("grid_a.mtx"), dir.join("grid_b.mtx"));
    write_matrix(&ga, side * side, &identity);
    write_matrix(&gb, side * side, &grid);
    let (ga, gb) = (ga.to_str().expect("utf-8"), gb.to_str().expect("utf-8"));
    vec![
        (
            "modes --shapes".into(),
            report(&["modes", "--mass", a, "--stiffness", b, "--shapes"]),
        ),
        (
            "modes --values-only".into(),
            report(&["modes", "--mass", a, "--stiffness", b, "--values-only"]),
        ),
        (
            "modes sparse".into(),
            report(&["modes", "--mass", ga, "--stiffness", gb, "--lowest", "4"]),
        ),
    ]
}

#[test]
fn every_command_s_report_validates_against_the_schema() {
    let validator = validator();
    let mut analyses = std::collections::BTreeSet::new();
    for (name, report) in every_report() {
        let problems = violations(&validator, &report);
        assert!(problems.is_empty(), "{name}:\n{}", problems.join("\n"));
        for step in report["steps"].as_array().expect("steps") {
            analyses.insert(step["analysis"].as_str().expect("analysis").to_string());
        }
    }
    // The fixtures reach every kind of step but the plots' (written only with --plot).
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo().join("docs/report.schema.json")).expect("schema"))
            .expect("JSON");
    let declared = schema["$defs"]["step"]["properties"]["analysis"]["enum"]
        .as_array()
        .expect("analysis enum");
    let missing: Vec<&str> = declared
        .iter()
        .filter_map(|a| a.as_str())
        .filter(|a| *a != "plots" && !analyses.contains(*a))
        .collect();
    assert!(missing.is_empty(), "no fixture reaches {missing:?}");
}

#[test]
fn the_plots_step_validates_too() {
    let dir = scratch("plots");
    let chain = repo().join("examples/scenes/spring_pendulum_chain.toml");
    let json = report(&[
        "run",
        chain.to_str().expect("utf-8"),
        "--plot",
        dir.to_str().expect("utf-8"),
    ]);
    let plots = common::step(&json, "plots");
    assert!(plots["files"].as_array().is_some_and(|f| !f.is_empty()), "{plots}");
    assert_eq!(violations(&validator(), &json), Vec::<String>::new());
}

/// The index of the first `analysis` step of a report.
fn step_index(report: &serde_json::Value, analysis: &str) -> usize {
    let steps = report["steps"].as_array().expect("steps");
    steps
        .iter()
        .position(|s| s["analysis"] == analysis)
        .unwrap_or_else(|| panic!("no {analysis} step"))
}

/// The index of the modes step of a report.
fn modes_step(report: &serde_json::Value) -> usize {
    step_index(report, "modes")
}

/// One way to break a report, with what it breaks.
type Mutation = (&'static str, fn(&mut serde_json::Value));

#[test]
fn a_mutated_report_fails_validation() {
    let validator = validator();
    let chain = repo().join("examples/scenes/spring_pendulum_chain.toml");
    let original = report(&["run", chain.to_str().expect("utf-8"), "--matrices"]);
    assert!(violations(&validator, &original).is_empty());
    let mutations: [Mutation; 11] = [
        ("schema version 1", |r| r["schema_version"] = 1.into()),
        ("a string for ω²", |r| {
            let k = modes_step(r);
            r["steps"][k]["modes"][0]["omega_sq"] = "30.4".into();
        }),
        ("a mode without its kind", |r| {
            let k = modes_step(r);
            r["steps"][k]["modes"][0].as_object_mut().expect("mode").remove("kind");
        }),
        ("an unknown mode kind", |r| {
            let k = modes_step(r);
            r["steps"][k]["modes"][0]["kind"] = "wobbly".into();
        }),
        ("an unknown key in a step", |r| {
            r["steps"][0]["quantities"] = serde_json::json!([])
        }),
        ("a step without its time", |r| {
            r["steps"][0].as_object_mut().expect("step").remove("seconds");
        }),
        ("an unknown analysis", |r| {
            r["steps"][0]["analysis"] = "astrology".into()
        }),
        ("a mass matrix flattened to one row", |r| {
            let k = step_index(r, "state_matrices");
            r["steps"][k]["mass_matrix"] = serde_json::json!([1.0, 0.0, 0.0, 1.0]);
        }),
        ("matrices without the Hessian", |r| {
            let k = step_index(r, "state_matrices");
            r["steps"][k].as_object_mut().expect("step").remove("hessian");
        }),
        ("a count that is not an integer", |r| r["steps"][0]["dof"] = 2.5.into()),
        ("a stability verdict in words", |r| {
            let k = modes_step(r);
            r["steps"][k]["stability"]["verdict"] = "stable: every mode oscillates".into();
        }),
    ];
    for (what, mutate) in mutations {
        let mut broken = original.clone();
        mutate(&mut broken);
        assert_ne!(broken, original, "{what}: the mutation changed nothing");
        assert!(!violations(&validator, &broken).is_empty(), "{what}: accepted");
    }
}
