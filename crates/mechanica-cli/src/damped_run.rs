//! The damped-modes step of a scene's dynamics analysis: the modes of
//! A δ̈ + (C + G) δ̇ + B δ = 0 about q0 (FM 4.62–4.66, §8e, §8g), each with its kind, natural
//! frequency ω_n, damped frequency ω_d, damping ratio ζ and eigenvalues s with their bounds.

use crate::dynamics_run::records::{DampedEigenvalue, DampedKind, DampedModeRecord, DampedModesRecord, DampedVerdict};
use crate::report::Step;
use mechanica::dynamics::{DampedModes, Dynamics};
use mechanica::modal::{QuadraticModeKind, QuadraticOptions};

/// The step's title.
const ANALYSIS: &str = "dynamics: damped modes det(s²A + s(C + G) + B) = 0 at q0";

/// The damped modes at `q0` as a step. A scene the damped modes do not model (a
/// velocity-dependent potential, a prescribed base motion) gets the reason in the record
/// instead of failing the whole dynamics analysis.
pub fn step(dynamics: &mut Dynamics, q0: &[f64]) -> Step {
    let start = std::time::Instant::now();
    let record = match dynamics.damped_modes(q0, &QuadraticOptions::default()) {
        Ok(result) => record(&result),
        Err(e) => DampedModesRecord {
            not_computed: Some(e.to_string()),
            gradient_norm: None,
            modes: Vec::new(),
            stability: None,
            growing_modes: 0,
            undecided_modes: 0,
        },
    };
    Step::new(ANALYSIS, start.elapsed().as_secs_f64(), record)
}

fn record(result: &DampedModes) -> DampedModesRecord {
    let eigenvalues = &result.solution.eigenvalues;
    let modes = result
        .solution
        .modes
        .iter()
        .map(|mode| DampedModeRecord {
            kind: kind_of(mode.kind),
            natural_frequency: mode.natural_frequency,
            damped_frequency: mode.damped_frequency,
            damping_ratio: mode.damping_ratio,
            eigenvalues: mode
                .eigenvalues
                .iter()
                .filter_map(|&i| eigenvalues.get(i))
                .map(|e| DampedEigenvalue {
                    s: e.s.map(|s| [s.re, s.im]),
                    bound: e.error_bound,
                    backward_error: e.backward_error,
                })
                .collect(),
        })
        .collect();
    let count = |kind: QuadraticModeKind| result.solution.modes.iter().filter(|m| m.kind == kind).count();
    let growing = count(QuadraticModeKind::Unstable);
    DampedModesRecord {
        not_computed: None,
        gradient_norm: Some(result.gradient_norm),
        modes,
        stability: Some(if growing > 0 {
            DampedVerdict::Unstable
        } else {
            DampedVerdict::NoGrowth
        }),
        growing_modes: growing,
        undecided_modes: count(QuadraticModeKind::Undecided),
    }
}

fn kind_of(kind: QuadraticModeKind) -> DampedKind {
    match kind {
        QuadraticModeKind::Underdamped => DampedKind::Underdamped,
        QuadraticModeKind::Overdamped => DampedKind::Overdamped,
        QuadraticModeKind::Critical => DampedKind::Critical,
        QuadraticModeKind::Rigid => DampedKind::Rigid,
        QuadraticModeKind::Unstable => DampedKind::Unstable,
        QuadraticModeKind::Neutral => DampedKind::Neutral,
        QuadraticModeKind::Relaxation => DampedKind::Relaxation,
        QuadraticModeKind::Infinite => DampedKind::Infinite,
        _ => DampedKind::Undecided,
    }
}
