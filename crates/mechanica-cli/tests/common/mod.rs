//! Helpers shared by the CLI integration tests: run the binary, read the steps of a JSON report.

use std::process::Command;

/// Runs `mechanica` with `args`: (success, stdout, stderr).
pub fn mechanica(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mechanica"))
        .args(args)
        .output()
        .expect("run mechanica");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The first step of the JSON report whose `analysis` is `analysis`.
#[allow(dead_code)]
pub fn step<'a>(json: &'a serde_json::Value, analysis: &str) -> &'a serde_json::Value {
    json["steps"]
        .as_array()
        .expect("steps")
        .iter()
        .find(|s| s["analysis"] == analysis)
        .unwrap_or_else(|| panic!("no {analysis} step in {json}"))
}

/// A JSON number, or an array of numbers (nested arrays flattened), as floats.
#[allow(dead_code)]
pub fn numbers(value: &serde_json::Value) -> Vec<f64> {
    match value {
        serde_json::Value::Array(items) => items.iter().flat_map(numbers).collect(),
        other => vec![other.as_f64().unwrap_or_else(|| panic!("not a number: {other}"))],
    }
}

/// The numbers of field `key` of the first `analysis` step.
#[allow(dead_code)]
pub fn values(json: &serde_json::Value, analysis: &str, key: &str) -> Vec<f64> {
    numbers(&step(json, analysis)[key])
}

/// ω² of every mode of the first `modes` step (an infinite mode reads +∞).
#[allow(dead_code)]
pub fn omega_sq(json: &serde_json::Value) -> Vec<f64> {
    step(json, "modes")["modes"]
        .as_array()
        .expect("modes")
        .iter()
        .map(|m| m["omega_sq"].as_f64().unwrap_or(f64::INFINITY))
        .collect()
}
