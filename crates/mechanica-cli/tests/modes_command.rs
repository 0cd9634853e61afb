//! `mechanica modes`: Matrix Market pencils through the CLI, against closed-form spectra, on
//! the dense and the sparse path, and a malformed file.

use std::path::{Path, PathBuf};
mod common;
use common::{mechanica, numbers, step};

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-modes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Writes the lower triangle of a symmetric matrix given as (row, col, value), 0-based.
fn write_symmetric(path: &PathBuf, n: usize, entries: &[(usize, usize, f64)]) {
    let mut text = format!(
        "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
        entries.len()
    );
    for (i, j, v) in entries {
        text.push_str(&format!("{} {} {v:e}\n", i + 1, j + 1));
    }
    std::fs::write(path, text).expect("write mtx");
}

/// Writes the pencil `{name}_a.mtx` (mass A) and `{name}_b.mtx` (stiffness B) into `dir`.
fn write_pencil(
    dir: &Path,
    name: &str,
    n: usize,
    mass: &[(usize, usize, f64)],
    stiffness: &[(usize, usize, f64)],
) -> (PathBuf, PathBuf) {
    let (a, b) = (dir.join(format!("{name}_a.mtx")), dir.join(format!("{name}_b.mtx")));
    write_symmetric(&a, n, mass);
    write_symmetric(&b, n, stiffness);
    (a, b)
}

fn run_json(args: &[&str]) -> serde_json::Value {
    let (ok, out, err) = mechanica(args);
    assert!(ok, "{err}");
    serde_json::from_str(&out).expect("json")
}

/// Free–free unit chain of n masses: ω²_k = 4 sin²(kπ/(2n)), k = 0..n−1 (one rigid-body mode).
#[test]
fn free_chain_dense_all_modes_match_the_closed_form() {
    let n = 12;
    let mut kb = Vec::new();
    for i in 0..n {
        kb.push((i, i, if i == 0 || i == n - 1 { 1.0 } else { 2.0 }));
        if i > 0 {
            kb.push((i, i - 1, -1.0));
        }
    }
    let mass: Vec<_> = (0..n).map(|i| (i, i, 1.0)).collect();
    let (a, b) = write_pencil(&scratch(), "free", n, &mass, &kb);
    let json = run_json(&[
        "--json",
        "modes",
        "--mass",
        a.to_str().expect("utf-8 path"),
        "--stiffness",
        b.to_str().expect("utf-8 path"),
    ]);
    let modes = step(&json, "pencil_modes")["modes"].as_array().expect("modes");
    let omega_sq: Vec<f64> = modes.iter().map(|m| numbers(&m["omega_sq"])[0]).collect();
    let bounds: Vec<f64> = modes.iter().map(|m| numbers(&m["bound"])[0]).collect();
    assert_eq!(omega_sq.len(), n);
    for k in 0..n {
        let exact = 4.0 * (k as f64 * std::f64::consts::PI / (2.0 * n as f64)).sin().powi(2);
        assert!(
            (omega_sq[k] - exact).abs() <= bounds[k].max(1e-15),
            "mode {k}: {} vs {exact}",
            omega_sq[k]
        );
    }
    assert_eq!(modes[0]["kind"], "zero", "the rigid-body mode is classified zero");
    assert!(modes[1..].iter().all(|m| m["kind"] == "oscillatory"));
    let check = step(&json, "sturm_check");
    assert_eq!(check["status"], "consistent");
    assert_eq!(check["count_below"], check["computed_below"], "the Sturm count agrees");
    // Every stage has a wall time.
    for analysis in ["pencil_read", "pencil_factor", "pencil_modes", "sturm_check"] {
        assert!(
            step(&json, analysis)["seconds"].as_f64().is_some_and(|t| t >= 0.0),
            "{analysis}"
        );
    }
}

/// A 25×25 grid Laplacian (n = 625 > the dense limit) with --lowest 4 goes through the sparse
/// solver: ω²_pq = 4 sin²(pπ/52) + 4 sin²(qπ/52), the second and third equal.
#[test]
fn grid_lowest_modes_use_the_sparse_solver() {
    let side = 25;
    let n = side * side;
    let mut kb = Vec::new();
    for j in 0..side {
        for i in 0..side {
            let r = i + side * j;
            kb.push((r, r, 4.0));
            if i > 0 {
                kb.push((r, r - 1, -1.0));
            }
            if j > 0 {
                kb.push((r, r - side, -1.0));
            }
        }
    }
    let mass: Vec<_> = (0..n).map(|i| (i, i, 1.0)).collect();
    let (a, b) = write_pencil(&scratch(), "grid", n, &mass, &kb);
    let json = run_json(&[
        "--json",
        "modes",
        "--mass",
        a.to_str().expect("utf-8 path"),
        "--stiffness",
        b.to_str().expect("utf-8 path"),
        "--lowest",
        "4",
    ]);
    assert_eq!(step(&json, "pencil_modes")["solver"], "sparse_lanczos");
    let s = |p: f64| 4.0 * (p * std::f64::consts::PI / 52.0).sin().powi(2);
    let exact = [s(1.0) + s(1.0), s(1.0) + s(2.0), s(1.0) + s(2.0), s(2.0) + s(2.0)];
    let modes = step(&json, "pencil_modes")["modes"].as_array().expect("modes");
    for k in 0..4 {
        let (omega_sq, bound) = (numbers(&modes[k]["omega_sq"])[0], numbers(&modes[k]["bound"])[0]);
        assert!((omega_sq - exact[k]).abs() <= bound, "mode {k}");
    }
    assert_eq!(modes[1]["multiplicity"], 2);
}

#[test]
fn a_malformed_file_is_reported_with_its_line() {
    let dir = scratch();
    let (a, b) = (dir.join("bad_a.mtx"), dir.join("bad_b.mtx"));
    std::fs::write(
        &a,
        "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n2 x 1.0\n",
    )
    .expect("write");
    write_symmetric(&b, 2, &[(0, 0, 1.0), (1, 1, 1.0)]);
    let (ok, _, err) = mechanica(&[
        "modes",
        "--mass",
        a.to_str().expect("utf-8 path"),
        "--stiffness",
        b.to_str().expect("utf-8 path"),
    ]);
    assert!(!ok);
    assert!(err.contains("bad_a.mtx") && err.contains("line 4"), "{err}");
}
