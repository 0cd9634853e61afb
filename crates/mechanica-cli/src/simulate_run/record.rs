//! The record of a simulation: the final state with its estimated global error, the costs and
//! the monitor of the conserved quantity.

use crate::mechanism_run::records::ContactModeName;
use crate::report::text::{Precision, Text, bound, number};
use serde::Serialize;

/// The integrator (mechanica::motion::Method).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodName {
    /// Classical Runge–Kutta, fixed step.
    Rk4,
    /// Störmer–Verlet, fixed step.
    Verlet,
    /// The implicit midpoint rule, fixed step.
    Midpoint,
    /// Dormand–Prince 5(4), adaptive.
    DormandPrince,
    /// RATTLE (Störmer–Verlet with constraint multipliers), fixed step.
    Rattle,
}

/// The conserved quantity monitored (mechanica::motion::Invariant).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InvariantName {
    /// T + U.
    Energy,
    /// T₂ − T₀ + U in a rotating frame.
    JacobiIntegral,
}

/// The drift of the conserved quantity over the run (M.1)–(M.2).
#[derive(Debug, Clone, Serialize)]
pub struct MonitorRecord {
    /// Which quantity.
    pub invariant: InvariantName,
    /// Its initial value, J.
    pub initial: f64,
    /// Largest |H(t) − H(0)| over the samples, relative to `scale`.
    pub max_drift: f64,
    /// |H(t_end) − H(0)| relative to `scale`.
    pub last_drift: f64,
    /// The energy scale, J.
    pub scale: f64,
}

/// The drift of the scene's holonomic constraints over the run (M.20).
#[derive(Debug, Clone, Serialize)]
pub struct ConstraintRecord {
    /// max ‖f(q)‖₂ over the steps and samples (m, or mixed units).
    pub max_position_drift: f64,
    /// max ‖J(q) q̇‖₂ over the steps and samples.
    pub max_velocity_drift: f64,
}

/// One impact during the motion (theory (M.23)).
#[derive(Debug, Clone, Serialize)]
pub struct ImpactEventRecord {
    /// The time of the impact, s.
    pub t: f64,
    /// The contacts that took part, by name.
    pub contacts: Vec<String>,
    /// Their impulses, world, N·s (in the order of `contacts`).
    pub impulses: Vec<[f64; 3]>,
    /// Their modes at the end of the impact.
    pub modes: Vec<ContactModeName>,
    /// The smallest gap at the impact, m (≤ 0: the penetration left by locating the event).
    pub gap: f64,
    /// The largest approach speed, m/s.
    pub approach_speed: f64,
    /// The kinetic energy just before the impact, J.
    pub kinetic_energy_before: f64,
    /// H just before the impact, J.
    pub energy_before: f64,
    /// H just after the impact, J.
    pub energy_after: f64,
    /// energy_before − energy_after, J.
    pub energy_lost: f64,
    /// H just before this impact minus H just after the previous one (or at t = 0), J: the
    /// integrator's drift over the free motion before it.
    pub segment_drift: f64,
    /// The impact's own error: the process's impulse error (N·s) or the simultaneous model's
    /// residual (m/s).
    pub impulse_error: f64,
    /// q̇ just before, rad/s | m/s.
    pub q_dot_before: Vec<f64>,
    /// q̇ just after, rad/s | m/s.
    pub q_dot_after: Vec<f64>,
}

/// A simulation from (q0, qd0) to t_end.
#[derive(Debug, Clone, Serialize)]
pub struct SimulateRecord {
    /// The integrator.
    pub method: MethodName,
    /// Its fixed step, s (fixed-step methods).
    pub step: Option<f64>,
    /// Relative and absolute tolerances (adaptive method).
    pub rtol: Option<f64>,
    /// Absolute tolerance (adaptive method).
    pub atol: Option<f64>,
    /// End time, s.
    pub t_end: f64,
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q(t_end), rad | m.
    pub q_end: Vec<f64>,
    /// q̇(t_end), rad/s | m/s.
    pub q_dot_end: Vec<f64>,
    /// Estimated global error of q(t_end), ∞-norm, with the companion run.
    pub error_q_end: Option<f64>,
    /// Estimated global error of q̇(t_end).
    pub error_q_dot_end: Option<f64>,
    /// Largest estimated error of q over the samples.
    pub max_error_q: Option<f64>,
    /// Largest estimated error of q̇ over the samples.
    pub max_error_q_dot: Option<f64>,
    /// Steps of the main run.
    pub steps: usize,
    /// Steps of the companion run (0 without it).
    pub companion_steps: usize,
    /// The conserved quantity's drift.
    pub monitor: MonitorRecord,
    /// The constraint drift, for a scene with constraints.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraints: Option<ConstraintRecord>,
    /// The impacts, in time order, for a scene with contacts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub impacts: Option<Vec<ImpactEventRecord>>,
    /// Trajectory files written (CSV, JSON).
    pub files: Vec<String>,
}

impl SimulateRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let names = &self.coordinates;
        let precision = |e: Option<f64>| e.map_or(Precision::Exact, Precision::Absolute);
        out.named("q(t_end)", names, &self.q_end, "rad | m", precision(self.error_q_end));
        out.named(
            "q̇(t_end)",
            names,
            &self.q_dot_end,
            "rad/s | m/s",
            precision(self.error_q_dot_end),
        );
        if let (Some(q), Some(q_dot)) = (self.max_error_q, self.max_error_q_dot) {
            out.line(
                "largest estimated error over the samples",
                &format!("q {}, q̇ {}", bound(q), bound(q_dot)),
            );
        }
        out.line(
            "steps: main run, companion run",
            &format!("{}, {}", self.steps, self.companion_steps),
        );
        let m = &self.monitor;
        let what = match m.invariant {
            InvariantName::Energy => "energy T + U",
            InvariantName::JacobiIntegral => "Jacobi integral T₂ − T₀ + U",
        };
        out.note(&format!(
            "{what}: initial {} J; drift max {}, final {} of the energy scale {} J \
             (conserved only without dampers and velocity-dependent forces)",
            number(m.initial, crate::report::text::MAX_DIGITS),
            bound(m.max_drift),
            bound(m.last_drift),
            number(m.scale, 4)
        ));
        if let Some(c) = &self.constraints {
            out.line(
                "constraint drift: max ‖f(q)‖₂, max ‖J q̇‖₂",
                &format!("{}, {}", bound(c.max_position_drift), bound(c.max_velocity_drift)),
            );
        }
        if let Some(impacts) = &self.impacts {
            write_impacts(out, impacts);
        }
        for file in &self.files {
            out.note(&format!("trajectory written to {file}"));
        }
    }
}

/// The impacts, one line each, and the energy books over the run.
fn write_impacts(out: &mut Text, impacts: &[ImpactEventRecord]) {
    out.line("impacts (M.23)", &impacts.len().to_string());
    for (k, i) in impacts.iter().enumerate() {
        let share = if i.kinetic_energy_before > 0.0 {
            format!(
                " ({} % of T⁻)",
                number(100.0 * i.energy_lost / i.kinetic_energy_before, 3)
            )
        } else {
            String::new()
        };
        out.line(
            &format!("impact {k}: t = {} s, {}", number(i.t, 10), i.contacts.join(", ")),
            &format!(
                "approach {} m/s, energy lost {} J{share}, drift before it {} J",
                number(i.approach_speed, 4),
                number(i.energy_lost, 4),
                bound(i.segment_drift)
            ),
        );
    }
    let lost: f64 = impacts.iter().map(|i| i.energy_lost).sum();
    let drift: f64 = impacts.iter().map(|i| i.segment_drift.abs()).sum();
    out.note(&format!(
        "the impacts dissipated {} J in all; the integrator's drift between them adds up to at most {} J",
        number(lost, 4),
        bound(drift)
    ));
}
