//! The scene's `simulate` analysis: the motion from (q0, qd0) integrated in time, with the
//! global error estimate and the energy monitor of `mechanica-motion`.
//!
//! ```toml
//! [analyses]
//! simulate = { t_end = 5.0, method = "dopri5", tolerance = 1e-8, interval = 0.05 }
//! # method: "dopri5" (default; rtol = tolerance, default 1e-8; atol = tolerance × atol_scale),
//! #         "rk4", "verlet", "midpoint" or "rattle" (these need `step`, s). With
//! #         [[constraint]] tables the motion keeps the constraints: "rattle" by multipliers
//! #         (M.17), the others by projection after each step (M.19); the drift is reported
//! # q_dot = [...]           the initial velocities (default: the joints' qd0)
//! # tau = [...]             constant applied generalized forces (default 0)
//! # estimate_error = true   run the companion that estimates the global error (default true)
//! # csv = "motion.csv"      write t, q, q̇, energy and the estimates (relative to the scene)
//! # json = "motion.json"    the same as JSON
//! # max_steps = 10000000    the most steps of each run (default 10⁷)
//! ```

use super::{SceneError, Spanned, Validator};
use serde::Deserialize;

/// The integration methods a scene may name.
pub const SIMULATE_METHODS: [&str; 5] = ["dopri5", "rk4", "verlet", "midpoint", "rattle"];

/// The default limit of steps of a scene's simulation (each of the main and companion runs).
pub const DEFAULT_SIMULATE_STEPS: usize = 10_000_000;

/// The `simulate` analysis as written in the scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulateSpec {
    /// The end time, s (> 0).
    pub t_end: Spanned<f64>,
    /// One of [`SIMULATE_METHODS`] (default "dopri5").
    pub method: Option<Spanned<String>>,
    /// The relative tolerance of "dopri5" (default 1e-8, at least 1e-14, below 1).
    pub tolerance: Option<Spanned<f64>>,
    /// The absolute tolerance of "dopri5" (default: the relative one), in the units of q and q̇.
    pub atol: Option<Spanned<f64>>,
    /// The step of the fixed-step methods, s (required for them).
    pub step: Option<Spanned<f64>>,
    /// The output interval, s (default t_end / 100).
    pub interval: Option<Spanned<f64>>,
    /// The initial velocities (default: the joints' qd0).
    pub q_dot: Option<Spanned<Vec<f64>>>,
    /// Constant applied generalized forces τ (default 0).
    pub tau: Option<Spanned<Vec<f64>>>,
    /// Run the companion that estimates the global error (default true).
    pub estimate_error: Option<bool>,
    /// A CSV file for the trajectory, relative to the scene file.
    pub csv: Option<String>,
    /// A JSON file for the trajectory, relative to the scene file.
    pub json: Option<String>,
    /// The most steps of each run (default [`DEFAULT_SIMULATE_STEPS`]).
    pub max_steps: Option<Spanned<usize>>,
}

impl SimulateSpec {
    /// The most steps of each run: `max_steps`, or [`DEFAULT_SIMULATE_STEPS`].
    pub fn step_limit(&self) -> usize {
        self.max_steps.as_ref().map_or(DEFAULT_SIMULATE_STEPS, |m| *m.get_ref())
    }

    /// The method's name.
    pub fn method_name(&self) -> &str {
        self.method.as_ref().map_or("dopri5", |m| m.get_ref().as_str())
    }

    /// The output interval.
    pub fn interval(&self) -> f64 {
        self.interval
            .as_ref()
            .map_or(*self.t_end.get_ref() / 100.0, |i| *i.get_ref())
    }
}

impl Validator<'_> {
    /// Ok when the simulation is well defined: positive finite times, a known method with
    /// its parameters, τ of the scene's length, a bounded number of samples and steps.
    /// Constraints are kept by the integration (RATTLE, or projection after each step).
    pub(super) fn check_simulate(&self, spec: &SimulateSpec, dof: usize) -> Result<(), SceneError> {
        let at = |field: &str| format!("analyses.simulate.{field}");
        let positive = |value: &Spanned<f64>, field: &str| {
            let v = *value.get_ref();
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(self.error(
                    Some(value.span()),
                    at(field),
                    format!("must be finite and > 0, got {v}"),
                ))
            }
        };
        positive(&spec.t_end, "t_end")?;
        self.check_simulate_method(spec, &at)?;
        if let Some(interval) = &spec.interval {
            positive(interval, "interval")?;
        }
        for (values, field) in [(&spec.q_dot, "q_dot"), (&spec.tau, "tau")] {
            let Some(values) = values else { continue };
            self.check_length(values, dof, at(field), "the scene has")?;
            if let Some(bad) = values.get_ref().iter().find(|v| !v.is_finite()) {
                return Err(self.error(Some(values.span()), at(field), format!("{bad} is not a finite number")));
            }
        }
        self.check_simulate_size(spec, dof, &at)
    }

    /// Ok when the method is known and its tolerance or step is given and in range.
    fn check_simulate_method(&self, spec: &SimulateSpec, at: &dyn Fn(&str) -> String) -> Result<(), SceneError> {
        let name = spec.method_name();
        if !SIMULATE_METHODS.contains(&name) {
            let span = spec.method.as_ref().map(|m| m.span());
            return Err(self.error(
                span,
                at("method"),
                format!("\"{name}\" is not one of {SIMULATE_METHODS:?}"),
            ));
        }
        let adaptive = name == "dopri5";
        let (given, missing) = if adaptive {
            (&spec.step, "step")
        } else {
            (&spec.tolerance, "tolerance")
        };
        if let Some(value) = given {
            let message = format!("\"{name}\" takes no `{missing}`");
            return Err(self.error(Some(value.span()), at(missing), message));
        }
        if !adaptive && spec.step.is_none() {
            let span = spec.method.as_ref().map(|m| m.span());
            return Err(self.error(span, at("step"), format!("\"{name}\" needs a `step` (s)")));
        }
        for (value, field, low, high) in [
            (&spec.tolerance, "tolerance", 1e-14, 1.0),
            (&spec.atol, "atol", f64::MIN_POSITIVE, f64::MAX),
            (&spec.step, "step", f64::MIN_POSITIVE, f64::MAX),
        ] {
            if let Some(value) = value
                && !(low..high).contains(value.get_ref())
            {
                let message = format!("must lie in [{low:e}, {high:e}), got {}", value.get_ref());
                return Err(self.error(Some(value.span()), at(field), message));
            }
        }
        Ok(())
    }

    /// Ok when the samples fit the response limit and a fixed step needs at most `max_steps`.
    fn check_simulate_size(
        &self,
        spec: &SimulateSpec,
        dof: usize,
        at: &dyn Fn(&str) -> String,
    ) -> Result<(), SceneError> {
        let t_end = *spec.t_end.get_ref();
        let samples = (t_end / spec.interval()).ceil() + 1.0;
        let values = samples * (2 * dof + 4) as f64;
        if values > self.limits.max_response_values as f64 {
            let message = format!(
                "{samples} samples × {} values exceed the limit of {} values (--max-response-values)",
                2 * dof + 4,
                self.limits.max_response_values
            );
            return Err(self.error(Some(spec.t_end.span()), at("interval"), message));
        }
        let max_steps = spec.step_limit();
        if let Some(step) = &spec.step
            && t_end / step.get_ref() > max_steps as f64
        {
            let message = format!(
                "t_end / step = {:e} steps exceed max_steps = {max_steps} (raise it to run longer)",
                t_end / step.get_ref()
            );
            return Err(self.error(Some(step.span()), at("step"), message));
        }
        Ok(())
    }
}
