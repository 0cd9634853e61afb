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

/// What a test reads of one panel: points, index tick labels, caption, zero line.
type ShapePanel = (Vec<(f64, f64)>, Vec<String>, String, f64);

/// Per panel of `svg`: the `cx`/`cy` of every `<circle class="shape-point">`, the text of every
/// index tick label, the caption, and the y of the zero line (the solid grid line).
fn shape_panels(svg: &str) -> Vec<ShapePanel> {
    let attribute = |line: &str, name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let start = line.find(&key).expect("attribute") + key.len();
        line[start..start + line[start..].find('"').expect("quoted")]
            .parse()
            .expect("a number")
    };
    let text = |line: &str| line[line.find('>').expect("tag") + 1..line.rfind("</").expect("end")].to_string();
    let mut panels = Vec::new();
    for line in svg.lines() {
        if line.starts_with("<g class=\"panel\"") {
            panels.push((Vec::new(), Vec::new(), String::new(), f64::NAN));
        }
        let Some((points, ticks, caption, zero)) = panels.last_mut() else {
            continue;
        };
        if line.contains("class=\"shape-point\"") {
            points.push((attribute(line, "cx"), attribute(line, "cy")));
        } else if line.contains("class=\"tick-label\"") && line.contains("text-anchor=\"middle\"") {
            ticks.push(text(line));
        } else if line.contains("class=\"caption\"") {
            *caption = text(line);
        } else if line.contains("class=\"grid\"") && !line.contains("dasharray") {
            *zero = attribute(line, "y1");
        }
    }
    panels
}

/// `modes --plot` on a lumped fixed chain of n equal masses: one panel per mode (six), the
/// displacement against the coordinate index on integer ticks 1 … n, and the k-th mode changes
/// sign k − 1 times along the chain (the oscillation theorem of a Jacobi matrix), its largest
/// |x_i| at the coordinate of the largest |sin(kπ i/(n + 1))|, which the caption names.
#[test]
fn lumped_chain_mode_shapes_are_drawn_against_the_coordinate_index() {
    let dir = scratch().join("plot");
    std::fs::create_dir_all(&dir).expect("dir");
    let n = 13;
    let mass: Vec<_> = (0..n).map(|i| (i, i, 2.5)).collect();
    let mut stiffness: Vec<_> = (0..n).map(|i| (i, i, 2.0 * 40.0)).collect();
    stiffness.extend((1..n).map(|i| (i, i - 1, -40.0)));
    let (a, b) = write_pencil(&dir, "chain", n, &mass, &stiffness);
    let plots = dir.join("plots");
    let args = [
        "modes",
        "--mass",
        a.to_str().expect("utf-8"),
        "--stiffness",
        b.to_str().expect("utf-8"),
        "--plot",
        plots.to_str().expect("utf-8"),
    ];
    let json = run_json(&[&args[..], &["--json"]].concat());
    let files = numbers_free_files(step(&json, "plots"));
    assert_eq!(files, vec![plots.join("mode_shapes.svg").display().to_string()]);
    let svg = std::fs::read_to_string(plots.join("mode_shapes.svg")).expect("svg");
    let panels = shape_panels(&svg);
    assert_eq!(panels.len(), 6);
    for (k, (points, ticks, caption, zero)) in panels.iter().enumerate() {
        let mode = k + 1;
        assert_eq!(points.len(), n, "mode {mode}");
        for tick in ticks {
            let i: usize = tick
                .parse()
                .unwrap_or_else(|_| panic!("tick {tick:?} is not an integer"));
            assert!((1..=n).contains(&i), "tick {i}");
        }
        assert!(ticks.first().map(String::as_str) == Some("1"), "{ticks:?}");
        // Points are drawn left to right, one per coordinate; y is screen-down.
        assert!(points.windows(2).all(|w| w[1].0 > w[0].0));
        assert!(zero.is_finite(), "mode {mode}: no zero line");
        let signs: Vec<bool> = points
            .iter()
            .filter(|p| (p.1 - zero).abs() > 0.02)
            .map(|p| p.1 < *zero)
            .collect();
        let changes = signs.windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(changes, mode - 1, "mode {mode}: {points:?}");
        let exact = |i: usize| {
            (mode as f64 * std::f64::consts::PI * i as f64 / (n + 1) as f64)
                .sin()
                .abs()
        };
        let peak = (1..=n)
            .max_by(|&i, &j| exact(i).total_cmp(&exact(j)))
            .expect("a coordinate");
        let ties = (1..=n)
            .filter(|&i| (exact(i) - exact(peak)).abs() < 1e-9)
            .collect::<Vec<_>>();
        assert!(
            ties.iter().any(|i| caption.contains(&format!("coordinate {i} "))),
            "mode {mode}: {caption} (peak at {ties:?})"
        );
    }
    let (ok, _, err) = mechanica(&[&args[..], &["--values-only"]].concat());
    assert!(!ok && err.contains("--values-only"), "{err}");
}

/// The file names of a `plots` step.
fn numbers_free_files(step: &serde_json::Value) -> Vec<String> {
    step["files"]
        .as_array()
        .expect("files")
        .iter()
        .map(|f| f.as_str().expect("a path").to_string())
        .collect()
}
