//! A simulated trajectory as CSV and JSON: per sample t, q, q̇, the conserved quantity H and
//! the estimated global errors of q and q̇ (empty in CSV, null in JSON, without the companion).

use mechanica::motion::Trajectory;
use serde_json::json;
use std::fmt::Write as _;

/// CSV with a header `t,q:<name>...,q_dot:<name>...,energy,error_q,error_q_dot`; numbers with
/// 17 significant digits, so that they read back exactly.
pub fn csv(trajectory: &Trajectory, names: &[String]) -> String {
    let mut out = String::from("t");
    for prefix in ["q", "q_dot"] {
        for name in names {
            let _ = write!(out, ",{prefix}:{name}");
        }
    }
    out.push_str(",energy,error_q,error_q_dot\n");
    for s in &trajectory.samples {
        let _ = write!(out, "{:.16e}", s.t);
        for v in s.q.iter().chain(&s.q_dot) {
            let _ = write!(out, ",{v:.16e}");
        }
        let _ = write!(out, ",{:.16e}", s.energy);
        match s.error {
            Some(e) => {
                let _ = writeln!(out, ",{:.16e},{:.16e}", e.q, e.q_dot);
            }
            None => out.push_str(",,\n"),
        }
    }
    out
}

/// JSON: `{"coordinates": [...], "t": [...], "q": [[...], ...], "q_dot": [...], "energy": [...],
/// "error_q": [...], "error_q_dot": [...], "steps": n, "companion_steps": n,
/// "energy_drift": {"max": .., "final": .., "scale": ..}}` (one row of q per sample).
pub fn json(trajectory: &Trajectory, names: &[String]) -> Result<String, String> {
    let samples = &trajectory.samples;
    let monitors = &trajectory.monitors;
    let value = json!({
        "coordinates": names,
        "t": samples.iter().map(|s| s.t).collect::<Vec<_>>(),
        "q": samples.iter().map(|s| s.q.clone()).collect::<Vec<_>>(),
        "q_dot": samples.iter().map(|s| s.q_dot.clone()).collect::<Vec<_>>(),
        "energy": samples.iter().map(|s| s.energy).collect::<Vec<_>>(),
        "error_q": samples.iter().map(|s| s.error.map(|e| e.q)).collect::<Vec<_>>(),
        "error_q_dot": samples.iter().map(|s| s.error.map(|e| e.q_dot)).collect::<Vec<_>>(),
        "steps": trajectory.steps,
        "companion_steps": trajectory.companion_steps,
        "energy_drift": {"max": monitors.max_drift, "final": monitors.last_drift, "scale": monitors.scale},
    });
    serde_json::to_string_pretty(&value).map_err(|e| format!("trajectory JSON: {e}"))
}
