//! The report: a titled list of computations, each with its results, accuracy and run time.

use serde::Serialize;
use std::fmt::Write as _;

/// One computed quantity: a name, its value(s) with unit, and how accurate it is.
#[derive(Debug, Clone, Serialize)]
pub struct Quantity {
    /// What was computed.
    pub name: String,
    /// The values, in SI units.
    pub values: Vec<f64>,
    /// The unit of the values.
    pub unit: String,
    /// The accuracy statement (a residual or an error bound), if the quantity is approximate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
}

/// One step of a scene: what it computed and how long it took.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// The analysis performed.
    pub analysis: String,
    /// Wall-clock time of the step, in seconds.
    pub seconds: f64,
    /// What it produced.
    pub quantities: Vec<Quantity>,
    /// Verdicts and remarks (e.g. "stable"), in words.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// A whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The scene's title.
    pub title: String,
    /// The mechanica version that produced the report.
    pub version: String,
    /// The steps, in the order they ran.
    pub steps: Vec<Step>,
}

impl Report {
    /// The human-readable report.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "mechanica {} — {}", self.version, self.title);
        for step in &self.steps {
            let _ = writeln!(out, "\n## {} ({:.1} µs)", step.analysis, step.seconds * 1e6);
            for q in &step.quantities {
                let values: Vec<String> = q.values.iter().map(|v| format!("{v:.9e}")).collect();
                let _ = write!(out, "  {:<44} [{}] {}", q.name, values.join(", "), q.unit);
                if let Some(acc) = &q.accuracy {
                    let _ = write!(out, "   ({acc})");
                }
                let _ = writeln!(out);
            }
            for note in &step.notes {
                let _ = writeln!(out, "  → {note}");
            }
        }
        out
    }
}

/// A computed value that is not a finite number: the inputs' scale overflowed double
/// precision somewhere. A run stops with this error (and a non-zero exit) instead of
/// reporting the value.
#[derive(Debug, Clone, PartialEq)]
pub struct NonFiniteResult {
    /// The step that computed it.
    pub analysis: String,
    /// The quantity.
    pub quantity: String,
    /// The value (±∞ or NaN).
    pub value: f64,
}

impl std::fmt::Display for NonFiniteResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} is {}, not a finite number (the inputs overflow double precision: check the scale of masses, lengths and loads)",
            self.analysis, self.quantity, self.value
        )
    }
}

impl std::error::Error for NonFiniteResult {}

/// Ok when every value of `step` is finite, except +∞ in the quantities for which
/// `may_be_infinite(name)` holds (e.g. ω of a massless direction).
pub fn check_finite(step: &Step, may_be_infinite: impl Fn(&str) -> bool) -> Result<(), NonFiniteResult> {
    for q in &step.quantities {
        let allowed = |v: f64| v.is_finite() || (v == f64::INFINITY && may_be_infinite(&q.name));
        if let Some(&value) = q.values.iter().find(|&&v| !allowed(v)) {
            return Err(NonFiniteResult {
                analysis: step.analysis.clone(),
                quantity: q.name.clone(),
                value,
            });
        }
    }
    Ok(())
}

/// Times `body` and wraps its quantities into a step.
pub fn timed_step<E>(analysis: &str, body: impl FnOnce() -> Result<Vec<Quantity>, E>) -> Result<Step, E> {
    let start = std::time::Instant::now();
    let quantities = body()?;
    Ok(Step {
        analysis: analysis.to_string(),
        seconds: start.elapsed().as_secs_f64(),
        quantities,
        notes: Vec::new(),
    })
}

/// The `version` command's report.
pub fn version_report() -> Result<Report, String> {
    use mechanica::ffi::{mech_abi_version, mech_features};
    Ok(Report {
        title: "version".into(),
        version: mechanica::version().into(),
        steps: vec![Step {
            analysis: "library".into(),
            seconds: 0.0,
            notes: Vec::new(),
            quantities: vec![
                Quantity {
                    name: "C ABI version".into(),
                    values: vec![f64::from(mech_abi_version())],
                    unit: "".into(),
                    accuracy: None,
                },
                Quantity {
                    name: "feature bits".into(),
                    values: vec![f64::from(mech_features())],
                    unit: "".into(),
                    accuracy: None,
                },
            ],
        }],
    })
}
