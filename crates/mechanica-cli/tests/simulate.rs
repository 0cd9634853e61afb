//! The `simulate` analysis of `mechanica run`: a pendulum over one exact period for every
//! method (the period from the complete elliptic integral K, computed here by the
//! arithmetic-geometric mean), the honesty of the reported error estimates over a family of
//! amplitudes and lengths, the trajectory files, and located errors for bad options.

use std::path::PathBuf;
mod common;
use common::{mechanica, numbers, step, values};

const G: f64 = 9.81;

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mechanica-simulate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn run(name: &str, text: &str) -> (bool, String, String) {
    let path = scratch().join(format!("{name}.toml"));
    std::fs::write(&path, text).expect("write scene");
    mechanica(&["run", path.to_str().expect("path"), "--json"])
}

fn run_json(name: &str, text: &str) -> serde_json::Value {
    let (ok, out, err) = run(name, text);
    assert!(ok, "{err}");
    serde_json::from_str(&out).expect("JSON report")
}

/// K(k) = π / (2 AGM(1, √(1 − k²))).
fn complete_elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (next_a, next_b) = (0.5 * (a + b), (a * b).sqrt());
        a = next_a;
        b = next_b;
    }
    std::f64::consts::PI / (2.0 * a)
}

/// A point mass on a massless rod of length l, hinged about y, released at rest from θ0.
fn pendulum(l: f64, theta0: f64, simulate: &str) -> String {
    format!(
        r#"title = "pendulum"
gravity = [0.0, 0.0, -{G:?}]
[[body]]
name = "bob"
primitive = {{ shape = "point", mass = 1.0 }}
offset = [0.0, 0.0, -{l:?}]
[[joint]]
name = "hinge"
type = "revolute"
parent = "ground"
child = "bob"
axis = [0.0, 1.0, 0.0]
q0 = [{theta0:?}]
[analyses]
simulate = {simulate}
"#
    )
}

/// The period T = 4 K(sin(θ0/2)) √(l/g).
fn period(l: f64, theta0: f64) -> f64 {
    4.0 * complete_elliptic_k((0.5 * theta0).sin()) * (l / G).sqrt()
}

/// Every method brings the pendulum back to θ0 at rest after one period, within its own
/// error estimate, over a family of amplitudes and lengths; the estimates are honest in at
/// least 90% of the cases and never off by more than 10×.
#[test]
fn a_pendulum_returns_after_one_period_within_the_estimate() {
    let mut honest = 0;
    let mut total = 0;
    for (case, (l, theta0)) in [(0.3, 0.2), (1.7, 1.1), (0.9, 2.5), (2.5, 0.6), (0.5, 2.9)]
        .into_iter()
        .enumerate()
    {
        let t = period(l, theta0);
        let h = t / 400.0;
        for method in [
            "method = \"dopri5\", tolerance = 1e-10".to_string(),
            format!("method = \"rk4\", step = {h:?}"),
            format!("method = \"verlet\", step = {:?}", h / 4.0),
            format!("method = \"midpoint\", step = {:?}", h / 4.0),
        ] {
            let spec = format!("{{ t_end = {t:?}, interval = {:?}, {method} }}", t / 4.0);
            let json = run_json(&format!("period{case}"), &pendulum(l, theta0, &spec));
            let q = values(&json, "simulate", "q_end")[0];
            let q_dot = values(&json, "simulate", "q_dot_end")[0];
            let report = json.to_string();
            let estimate = estimate_of(&report, "error_q_end");
            let rate_estimate = estimate_of(&report, "error_q_dot_end");
            let error = (q - theta0).abs();
            let rate_error = q_dot.abs();
            assert!(
                error <= 1e-4 && rate_error <= 1e-3,
                "case {case} {method}: θ(T) − θ0 = {error:e}, θ̇(T) = {q_dot:e}"
            );
            for (e, bound) in [(error, estimate), (rate_error, rate_estimate)] {
                total += 1;
                if e <= bound {
                    honest += 1;
                }
                assert!(
                    e <= 10.0 * bound + 1e-15,
                    "case {case} {method}: error {e:e} vs estimate {bound:e}"
                );
            }
        }
    }
    assert!(honest * 10 >= total * 9, "{honest} of {total} estimates hold");
}

/// The simulation's estimated global error of `key` (`error_q_end` or `error_q_dot_end`).
fn estimate_of(report: &str, key: &str) -> f64 {
    let json: serde_json::Value = serde_json::from_str(report).expect("json");
    values(&json, "simulate", key)[0]
}

/// Störmer–Verlet keeps the energy of an undamped pendulum within a bounded band over many
/// periods, and the report's drift is that band (relative to the energy scale).
#[test]
fn verlet_keeps_the_energy_drift_bounded() {
    let (l, theta0) = (1.0, 1.0);
    let t = 50.0 * period(l, theta0);
    let spec = format!(
        "{{ t_end = {t:?}, method = \"verlet\", step = 0.01, interval = {:?}, estimate_error = false }}",
        t / 50.0
    );
    let (ok, out, err) = run("verlet", &pendulum(l, theta0, &spec));
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("json");
    let monitor = &step(&json, "simulate")["monitor"];
    assert_eq!(monitor["invariant"], "energy");
    let drift = numbers(&monitor["max_drift"])[0];
    // Verlet's energy error is O((ω h)²) and does not grow: here (ω h)² ≈ 1e-3.
    assert!(drift > 0.0 && drift < 5e-3, "drift {drift}");
}

/// The CSV and JSON trajectories hold every sample, and their last row is the reported state.
#[test]
fn trajectory_files_hold_every_sample() {
    let spec = "{ t_end = 1.0, interval = 0.1, tolerance = 1e-9, csv = \"pendulum.csv\", json = \"pendulum.json\" }";
    let json = run_json("files", &pendulum(0.8, 0.7, spec));
    let q_end = values(&json, "simulate", "q_end")[0];
    let csv = std::fs::read_to_string(scratch().join("pendulum.csv")).expect("csv written");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,q:hinge,q_dot:hinge,energy,error_q,error_q_dot"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len(), 11);
    assert_eq!(rows[10][0], 1.0);
    assert_eq!(rows[10][1], q_end);
    assert_eq!(rows[0][1], 0.7);
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scratch().join("pendulum.json")).expect("json written"))
            .expect("JSON");
    assert_eq!(file["t"].as_array().expect("t").len(), 11);
    assert_eq!(file["q"][10][0].as_f64(), Some(q_end));
    assert_eq!(file["coordinates"][0].as_str(), Some("hinge"));
}

/// Bad options are refused with the field named.
#[test]
fn bad_simulation_options_are_refused_with_the_field_named() {
    let cases = [
        ("{ t_end = -1.0 }", "analyses.simulate.t_end"),
        ("{ t_end = 1.0, method = \"euler\" }", "analyses.simulate.method"),
        ("{ t_end = 1.0, method = \"rk4\" }", "analyses.simulate.step"),
        ("{ t_end = 1.0, tolerance = 0.0 }", "analyses.simulate.tolerance"),
        (
            "{ t_end = 1.0, tolerance = 1e-8, step = 0.1 }",
            "analyses.simulate.step",
        ),
        (
            "{ t_end = 1.0, method = \"rk4\", step = 1e-12 }",
            "analyses.simulate.step",
        ),
        ("{ t_end = 1.0, interval = 1e-9 }", "analyses.simulate.interval"),
        ("{ t_end = 1.0, tau = [1.0, 2.0] }", "analyses.simulate.tau"),
        ("{ t_end = 1.0, q_dot = [nan] }", "analyses.simulate.q_dot"),
    ];
    for (spec, field) in cases {
        let (ok, _, err) = run("bad", &pendulum(1.0, 0.5, spec));
        assert!(!ok && err.contains(field), "{spec}: {err}");
    }
}
