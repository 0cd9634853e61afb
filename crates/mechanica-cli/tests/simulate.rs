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

/// A point mass on a prismatic joint along z dropped from h₀ on a `[[contact]]` floor: the
/// reported impacts against the closed form t_{k+1} = t_k + 2 e^k v₁/g, v_k = e^{k−1} v₁ and
/// losses ½ m v_k² (1 − e²), for a family of masses, heights and restitutions, and the text
/// report names the contact.
#[test]
fn bouncing_mass_on_a_contact_matches_the_closed_form() {
    for (case, (m, h0, e)) in [
        (0.3, 0.7, 0.5),
        (12.0, 2.5, 0.8),
        (1e-3, 0.05, 0.35),
        (450.0, 9.0, 0.65),
    ]
    .into_iter()
    .enumerate()
    {
        let v1 = (2.0 * G * h0).sqrt();
        let mut times = vec![v1 / G];
        for k in 1..3 {
            times.push(times[k - 1] + 2.0 * f64::powi(e, k as i32) * v1 / G);
        }
        let t_end = times[2] + f64::powi(e, 3) * v1 / G;
        let scene = format!(
            r#"title = "bouncing mass"
gravity = [0.0, 0.0, -{G:?}]
[[body]]
name = "ball"
primitive = {{ shape = "point", mass = {m:?} }}
[[joint]]
name = "drop"
type = "prismatic"
parent = "ground"
child = "ball"
axis = [0.0, 0.0, 1.0]
q0 = [{h0:?}]
[[contact]]
name = "floor"
body = "ball"
normal = [0.0, 0.0, 2.0]
restitution = {e:?}
law = "newton"
[analyses]
simulate = {{ t_end = {t_end:?}, tolerance = 1e-11, atol = 1e-13, interval = {t_end:?} }}
"#
        );
        let report = run_json(&format!("bounce-{case}"), &scene);
        let record = step(&report, "simulate");
        let impacts = record["impacts"].as_array().expect("impacts");
        assert_eq!(impacts.len(), 3, "case {case}");
        for (k, impact) in impacts.iter().enumerate() {
            let v = f64::powi(e, k as i32) * v1;
            let lost = 0.5 * m * v * v * (1.0 - e * e);
            let at = format!("case {case} impact {k}");
            let get = |key: &str| impact[key].as_f64().unwrap_or_else(|| panic!("{at}: {key}"));
            assert!((get("t") - times[k]).abs() <= 1e-8 * times[k], "{at}: t {}", get("t"));
            assert!(
                (get("energy_lost") - lost).abs() <= 1e-7 * lost,
                "{at}: lost {}",
                get("energy_lost")
            );
            assert!((get("approach_speed") - v).abs() <= 1e-7 * v, "{at}");
            assert_eq!(impact["contacts"][0], "floor", "{at}");
            assert_eq!(impact["modes"][0], "frictionless", "{at}");
        }
        let q_end = numbers(&record["q_end"]);
        let apex = f64::powi(f64::powi(e, 3) * v1, 2) / (2.0 * G);
        assert!(
            (q_end[0] - apex).abs() <= 1e-7 * h0,
            "case {case}: {} vs {apex}",
            q_end[0]
        );
    }
    let (ok, out, err) = mechanica(&["run", "../../examples/scenes/striking_double_pendulum.toml"]);
    assert!(ok, "{err}");
    assert!(out.contains("tip on wall") && out.contains("dissipated"), "{out}");
}

/// Contacts with a bad normal, restitution, law or body are refused with the field named.
#[test]
fn bad_contacts_are_located() {
    let base = pendulum(1.0, 0.5, "{ t_end = 1.0 }");
    for (field, table) in [
        ("contact[0].normal", "body = \"bob\"\nnormal = [0.0, 0.0, 0.0]"),
        (
            "contact[0].restitution",
            "body = \"bob\"\nnormal = [0.0, 0.0, 1.0]\nrestitution = 1.5",
        ),
        (
            "contact[0].law",
            "body = \"bob\"\nnormal = [0.0, 0.0, 1.0]\nlaw = \"hooke\"",
        ),
        ("contact[0].body", "body = \"nobody\"\nnormal = [0.0, 0.0, 1.0]"),
    ] {
        let scene = format!("{base}\n[[contact]]\n{table}\n");
        let (ok, _, err) = run("bad-contact", &scene);
        assert!(!ok && err.contains(field), "{field}: {err}");
    }
}
