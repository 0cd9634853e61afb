//! `mechanica mass`: runs the built binary on small mesh files written into a temporary
//! directory and checks the report against closed forms (a box: m = ρabc,
//! I_xx = m(b² + c²)/12, ...), the JSON encoding, and the error paths.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh directory under the system temp dir, unique to this test and process.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-mass-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// The 12 outward triangles of the box [x0, x0+a] × [y0, y0+b] × [z0, z0+c].
fn box_triangles(origin: [f64; 3], size: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let corner = |k: usize| {
        [
            origin[0] + if k & 1 != 0 { size[0] } else { 0.0 },
            origin[1] + if k & 2 != 0 { size[1] } else { 0.0 },
            origin[2] + if k & 4 != 0 { size[2] } else { 0.0 },
        ]
    };
    // Corner k has x bit 1, y bit 2, z bit 4; faces counter-clockwise seen from outside.
    let faces: [[usize; 3]; 12] = [
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
    ];
    faces
        .iter()
        .map(|f| [corner(f[0]), corner(f[1]), corner(f[2])])
        .collect()
}

/// An ASCII STL file of `triangles` (normals left zero; readers recompute them).
fn write_ascii_stl(path: &Path, triangles: &[[[f64; 3]; 3]]) {
    let mut text = String::from("solid test\n");
    for t in triangles {
        text.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in t {
            text.push_str(&format!("      vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        text.push_str("    endloop\n  endfacet\n");
    }
    text.push_str("endsolid test\n");
    std::fs::write(path, text).expect("write STL");
}

fn mechanica(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mechanica"))
        .args(args)
        .output()
        .expect("run the mechanica binary")
}

/// The step of the JSON report whose `analysis` is `analysis`.
fn step<'a>(report: &'a serde_json::Value, analysis: &str) -> &'a serde_json::Value {
    report["steps"]
        .as_array()
        .expect("steps")
        .iter()
        .find(|s| s["analysis"] == analysis)
        .unwrap_or_else(|| panic!("no {analysis} step in {report}"))
}

/// The numbers of field `key` of the `analysis` step (nested arrays flattened by rows).
fn values(report: &serde_json::Value, analysis: &str, key: &str) -> Vec<f64> {
    fn flatten(value: &serde_json::Value, out: &mut Vec<f64>) {
        match value {
            serde_json::Value::Array(items) => items.iter().for_each(|v| flatten(v, out)),
            other => out.push(other.as_f64().unwrap_or_else(|| panic!("not a number: {other}"))),
        }
    }
    let mut out = Vec::new();
    flatten(&step(report, analysis)[key], &mut out);
    out
}

/// Runs `mechanica --json mass ARGS` and parses its report.
fn json_report(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["--json", "mass"];
    all.extend_from_slice(args);
    let out = mechanica(&all);
    assert!(
        out.status.success(),
        "mechanica {all:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the --json output parses as JSON")
}

fn assert_close(got: f64, expected: f64, tol: f64, what: &str) {
    assert!(
        (got - expected).abs() <= tol,
        "{what}: got {got}, expected {expected} (tolerance {tol})"
    );
}

/// Rounding tolerance of a 12-triangle integral with exact (f32-representable) vertices: a few
/// dozen operations per term, each within ε relative to the scale of the result.
const TOL: f64 = 64.0 * f64::EPSILON;

/// The closed form of a solid box of mass m and sides a, b, c: central inertia
/// diag(m(b²+c²)/12, m(a²+c²)/12, m(a²+b²)/12).
fn box_inertia(m: f64, [a, b, c]: [f64; 3]) -> [f64; 3] {
    [
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ]
}

fn check_box_report(report: &serde_json::Value, mass: f64, origin: [f64; 3], size: [f64; 3], tol: f64) {
    let m = values(report, "mesh_mass_properties", "mass")[0];
    assert_close(m, mass, tol * mass, "mass");
    let volume = size[0] * size[1] * size[2];
    assert_close(
        values(report, "mesh_mass_properties", "measure")[0],
        volume,
        tol * volume,
        "volume",
    );
    let c = values(report, "mesh_mass_properties", "centre_of_mass");
    for k in 0..3 {
        let expected = origin[k] + 0.5 * size[k];
        assert_close(c[k], expected, tol * expected.abs().max(size[k]), "centre of mass");
    }
    let diag = box_inertia(mass, size);
    let scale = diag.iter().copied().fold(0.0, f64::max);
    let j = values(report, "mesh_mass_properties", "inertia");
    assert_eq!(j.len(), 9);
    for r in 0..3 {
        for col in 0..3 {
            let expected = if r == col { diag[r] } else { 0.0 };
            assert_close(j[3 * r + col], expected, tol * scale, "central inertia");
        }
    }
    let urdf = &step(report, "mesh_mass_properties")["inertia_urdf"];
    let six = ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"].map(|k| urdf[k].as_f64().expect("number"));
    let expected_six = [diag[0], 0.0, 0.0, diag[1], 0.0, diag[2]];
    for k in 0..6 {
        assert_close(six[k], expected_six[k], tol * scale, "URDF inertia");
    }
    // Sorted principal moments and axes along the coordinate axes (the boxes used have
    // distinct sides, hence distinct moments).
    let mut sorted = diag;
    sorted.sort_by(f64::total_cmp);
    let moments = values(report, "mesh_mass_properties", "principal_moments");
    for k in 0..3 {
        assert_close(moments[k], sorted[k], tol * scale, "principal moment");
    }
    let axes = values(report, "mesh_mass_properties", "principal_axes");
    assert_eq!(axes.len(), 9);
    for (k, &moment) in sorted.iter().enumerate() {
        let axis = diag
            .iter()
            .position(|&d| d == moment)
            .expect("moment of a coordinate axis");
        assert_close(axes[3 * k + axis].abs(), 1.0, 1e-12, "principal axis");
    }
}

#[test]
fn a_box_gives_the_closed_form_mass_centre_and_inertia() {
    let dir = temp_dir("box");
    let file = dir.join("box.stl");
    let (origin, size) = ([1.0, -2.0, 4.0], [1.0, 2.0, 0.5]);
    write_ascii_stl(&file, &box_triangles(origin, size));
    let path = file.to_str().expect("utf-8 path");

    // By density.
    let report = json_report(&[path, "--density", "500"]);
    check_box_report(&report, 500.0, origin, size, TOL);
    assert_eq!(values(&report, "mesh_mass_properties", "density"), vec![500.0]);
    assert_eq!(values(&report, "mesh_diagnostics", "boundary_edges"), vec![0.0]);
    assert_eq!(step(&report, "mesh_diagnostics")["flipped"], false);
    assert_eq!(values(&report, "mesh_diagnostics", "degenerate_triangles"), vec![0.0]);

    // By mass, and the default density of water.
    check_box_report(&json_report(&[path, "--mass", "3.5"]), 3.5, origin, size, TOL);
    check_box_report(&json_report(&[path]), 1000.0, origin, size, TOL);

    // Inertia about the file origin: Steiner from the centre, J_O = J_C + m(|c|² I − c cᵀ) (3.28).
    let report = json_report(&[path, "--mass", "2"]);
    let j_o = values(&report, "mesh_mass_properties", "inertia_about_origin");
    let c = [1.5, -1.0, 4.25];
    let diag = box_inertia(2.0, size);
    let c2: f64 = c.iter().map(|x| x * x).sum();
    for r in 0..3 {
        for col in 0..3 {
            let delta = if r == col { 1.0 } else { 0.0 };
            let expected = delta * diag[r] + 2.0 * (delta * c2 - c[r] * c[col]);
            assert_close(j_o[3 * r + col], expected, TOL * 2.0 * c2, "inertia about the origin");
        }
    }

    // The text report (no --json) succeeds and names the quantities.
    let out = mechanica(&["mass", path, "--mass", "2"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("principal moments") && text.contains("centre of mass"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn millimetre_files_scale_to_metres_and_obj_matches_stl() {
    let dir = temp_dir("scale");
    let (origin, size) = ([1.0, -2.0, 4.0], [1.0, 2.0, 0.5]);
    let mm: Vec<_> = box_triangles(origin, size)
        .iter()
        .map(|t| t.map(|v| v.map(|x| 1000.0 * x)))
        .collect();
    let file = dir.join("box_mm.stl");
    write_ascii_stl(&file, &mm);
    // 0.001 is inexact: each scaled coordinate carries one rounding (ε relative) on top of TOL.
    let report = json_report(&[file.to_str().expect("utf-8"), "--scale", "0.001", "--mass", "2"]);
    check_box_report(&report, 2.0, origin, size, TOL + 16.0 * f64::EPSILON);

    // The same box as an OBJ file with quad faces (triangulated by the reader).
    let mut obj = String::new();
    for k in 0..8 {
        let x = origin[0] + if k & 1 != 0 { size[0] } else { 0.0 };
        let y = origin[1] + if k & 2 != 0 { size[1] } else { 0.0 };
        let z = origin[2] + if k & 4 != 0 { size[2] } else { 0.0 };
        obj.push_str(&format!(
            "v {x} {y} {z}
"
        ));
    }
    // 1-based corner indices; counter-clockwise seen from outside.
    for face in ["1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6"] {
        obj.push_str(&format!(
            "f {face}
"
        ));
    }
    let file = dir.join("box.OBJ");
    std::fs::write(&file, obj).expect("write OBJ");
    check_box_report(
        &json_report(&[file.to_str().expect("utf-8"), "--mass", "2"]),
        2.0,
        origin,
        size,
        TOL,
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_inside_out_box_is_flipped_and_reported() {
    let dir = temp_dir("flipped");
    let file = dir.join("inside_out.stl");
    let (origin, size) = ([0.0, 0.0, 0.0], [2.0, 1.0, 0.5]);
    let reversed: Vec<_> = box_triangles(origin, size).iter().map(|t| [t[0], t[2], t[1]]).collect();
    write_ascii_stl(&file, &reversed);
    let report = json_report(&[file.to_str().expect("utf-8"), "--mass", "1"]);
    check_box_report(&report, 1.0, origin, size, TOL);
    assert_eq!(step(&report, "mesh_diagnostics")["flipped"], true);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_hairline_crack_is_welded_by_default_and_named_when_welding_is_off() {
    let dir = temp_dir("crack");
    let file = dir.join("crack.stl");
    // One copy of the corner at the origin written as (1e-20, 0, 0), as CAD exporters do where
    // patches meet: without welding, the four edges of that copy and of the origin are open.
    let (origin, size) = ([0.0; 3], [1.0, 2.0, 0.5]);
    let mut triangles = box_triangles(origin, size);
    assert_eq!(triangles[0][0], [0.0; 3]);
    triangles[0][0] = [1e-20, 0.0, 0.0];
    write_ascii_stl(&file, &triangles);
    let path = file.to_str().expect("utf-8");

    let report = json_report(&[path, "--density", "500"]);
    check_box_report(&report, 500.0, origin, size, TOL);
    assert_eq!(values(&report, "mesh_load", "vertices"), vec![8.0]);
    assert_eq!(step(&report, "mesh_load")["weld"]["vertices_welded"], 1);
    let weld = &step(&report, "mesh_load")["weld"];
    assert_eq!(weld["relative_tolerance"], 1e-8);
    let moved = weld["max_displacement"].as_f64().expect("number");
    assert!(moved > 0.0 && moved < 1e-19, "{moved}");

    let out = mechanica(&["mass", path, "--weld", "0"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("4 boundary edges") && err.contains("try --weld"), "{err}");
    let out = mechanica(&["mass", path, "--weld", "-1"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("weld tolerance must be finite and non-negative"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_open_mesh_is_rejected_with_its_boundary_edges_unless_shell() {
    let dir = temp_dir("open");
    let file = dir.join("open.stl");
    // A unit cube without its top face (the two z = 1 triangles): the 4 edges of the missing
    // square are used once.
    let mut triangles = box_triangles([0.0; 3], [1.0; 3]);
    triangles.drain(2..4);
    write_ascii_stl(&file, &triangles);
    let path = file.to_str().expect("utf-8");
    let out = mechanica(&["mass", path]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("4 boundary edges") && err.contains("--shell"), "{err}");
    assert!(!err.contains("--weld"), "{err}");
    assert!(out.stdout.is_empty());

    // As a shell: five unit squares with surface density 2 kg/m².
    let report = json_report(&[path, "--shell", "--density", "2"]);
    assert_close(
        values(&report, "mesh_mass_properties", "measure")[0],
        5.0,
        TOL * 5.0,
        "area",
    );
    assert_close(
        values(&report, "mesh_mass_properties", "mass")[0],
        10.0,
        TOL * 10.0,
        "mass",
    );
    assert_eq!(values(&report, "mesh_diagnostics", "boundary_edges"), vec![4.0]);
    // Centre: the bottom face at z = 0 and four walls centred at z = 1/2, each of mass 2.
    let c = values(&report, "mesh_mass_properties", "centre_of_mass");
    assert_close(c[2], 0.4, TOL, "shell centre z");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_closed_cube_shell_has_the_closed_form_five_eighteenths_m_a_squared() {
    // Each face of mass m/6: two faces ⟂ the axis give (m/6)a²/6 each, four faces ∥ give
    // (m/6)(a²/12 + a²/4) each, in total (5/18) m a².
    let dir = temp_dir("shell");
    let file = dir.join("cube.stl");
    let a = 2.0;
    write_ascii_stl(&file, &box_triangles([-1.0, -1.0, -1.0], [a; 3]));
    let report = json_report(&[file.to_str().expect("utf-8"), "--shell", "--mass", "3"]);
    let j = values(&report, "mesh_mass_properties", "inertia");
    let expected = 5.0 / 18.0 * 3.0 * a * a;
    for k in 0..3 {
        assert_close(j[4 * k], expected, TOL * expected, "shell moment");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_inputs_fail_with_a_message_naming_the_problem() {
    let dir = temp_dir("errors");
    let missing = dir.join("missing.stl");
    let out = mechanica(&["mass", missing.to_str().expect("utf-8")]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("missing.stl") && err.contains("cannot read"), "{err}");

    let unknown = dir.join("mesh.ply");
    std::fs::write(
        &unknown, "ply
",
    )
    .expect("write");
    let out = mechanica(&["mass", unknown.to_str().expect("utf-8")]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown mesh format"));

    let garbage = dir.join("garbage.obj");
    std::fs::write(
        &garbage,
        "v 0 0 0
f 1 2 3
",
    )
    .expect("write");
    let out = mechanica(&["mass", garbage.to_str().expect("utf-8")]);
    assert!(!out.status.success());

    let cube = dir.join("cube.stl");
    write_ascii_stl(&cube, &box_triangles([0.0; 3], [1.0; 3]));
    let path = cube.to_str().expect("utf-8");
    for (args, needle) in [
        (vec!["mass", path, "--density", "-5"], "density must be positive"),
        (vec!["mass", path, "--mass", "0"], "mass must be positive"),
        (vec!["mass", path, "--density", "nan"], "not finite"),
        (vec!["mass", path, "--scale", "0"], "--scale"),
    ] {
        let out = mechanica(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // --density and --mass exclude each other (a usage error from the argument parser).
    let out = mechanica(&["mass", path, "--density", "1", "--mass", "1"]);
    assert_eq!(out.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_surface_stored_twice_is_named_as_such() {
    let dir = temp_dir("twice");
    let file = dir.join("twice.stl");
    // Every triangle of a unit cube listed twice: no edge is open, each is used four times.
    let once = box_triangles([0.0; 3], [1.0; 3]);
    let twice: Vec<_> = once.iter().chain(&once).cloned().collect();
    write_ascii_stl(&file, &twice);
    let out = mechanica(&["mass", file.to_str().expect("utf-8")]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("0 boundary edges") && err.contains("more than two triangles") && err.contains("surface twice"),
        "{err}"
    );
    assert!(!err.contains("large open boundary"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
