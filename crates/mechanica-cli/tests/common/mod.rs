//! Helpers shared by the CLI integration tests: run the binary, read quantities of a JSON report.

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

/// The values of the first quantity whose name starts with `name` (null reads as NaN).
pub fn values(json: &serde_json::Value, name: &str) -> Vec<f64> {
    for step in json["steps"].as_array().expect("steps") {
        for q in step["quantities"].as_array().expect("quantities") {
            if q["name"].as_str().is_some_and(|n| n.starts_with(name)) {
                return q["values"]
                    .as_array()
                    .expect("values")
                    .iter()
                    .map(|v| v.as_f64().unwrap_or(f64::NAN))
                    .collect();
            }
        }
    }
    panic!("no quantity {name} in {json}");
}
