//! The damped-modes step of a scene's dynamics analysis: the modes of
//! A δ̈ + (C + G) δ̇ + B δ = 0 about q0 (FM 4.62–4.66, §8e, §8g), each with its kind, natural
//! frequency ω_n, damped frequency ω_d, damping ratio ζ and eigenvalues s with their bounds.

use crate::report::{Quantity, Step};
use crate::scene_run::quantity;
use mechanica::dynamics::{DampedModes, Dynamics};
use mechanica::modal::{QuadraticEigenvalue, QuadraticMode, QuadraticModeKind, QuadraticOptions};

/// The step's title.
const ANALYSIS: &str = "dynamics: damped modes det(s²A + s(C + G) + B) = 0 at q0";

/// The damped modes at `q0` as a step. A scene the damped modes do not model (a
/// velocity-dependent potential, a prescribed base motion) gets the reason as a note instead
/// of failing the whole dynamics analysis.
pub fn step(dynamics: &mut Dynamics, q0: &[f64]) -> Step {
    let start = std::time::Instant::now();
    let (quantities, notes) = match dynamics.damped_modes(q0, &QuadraticOptions::default()) {
        Ok(result) => (quantities(&result), verdicts(&result)),
        Err(e) => (Vec::new(), vec![format!("damped modes not computed: {e}")]),
    };
    Step {
        analysis: ANALYSIS.into(),
        seconds: start.elapsed().as_secs_f64(),
        quantities,
        notes,
    }
}

fn quantities(result: &DampedModes) -> Vec<Quantity> {
    let mut out = vec![quantity(
        "‖grad U*(q0)‖ (the linearization is exact only at 0, an equilibrium)",
        vec![result.gradient_norm],
        "N·m | N",
        None,
    )];
    let eigenvalues = &result.solution.eigenvalues;
    for (k, mode) in result.solution.modes.iter().enumerate() {
        let label = format!("damped mode {} ({})", k + 1, kind_name(mode.kind));
        out.push(frequencies(&label, mode));
        let members: Vec<&QuadraticEigenvalue> = mode.eigenvalues.iter().filter_map(|&i| eigenvalues.get(i)).collect();
        out.push(roots(&label, &members));
    }
    out
}

/// ω_n, ω_d and ζ of a mode, those that are defined.
fn frequencies(label: &str, mode: &QuadraticMode) -> Quantity {
    let (mut names, mut values, mut units) = (Vec::new(), Vec::new(), Vec::new());
    if let Some(omega_n) = mode.natural_frequency {
        names.push("ω_n");
        values.push(omega_n);
        units.push("rad/s");
    }
    names.push("ω_d");
    values.push(mode.damped_frequency);
    units.push("rad/s");
    if let Some(zeta) = mode.damping_ratio {
        names.push("ζ");
        values.push(zeta);
        units.push("1");
    }
    quantity(
        &format!("{label}: {}", names.join(", ")),
        values,
        &units.join(" | "),
        None,
    )
}

/// The eigenvalues of a mode as (Re s, Im s) pairs, with their bounds; an infinite eigenvalue
/// is stated in the accuracy text and has no values.
fn roots(label: &str, members: &[&QuadraticEigenvalue]) -> Quantity {
    let mut values = Vec::new();
    let mut bounds = Vec::new();
    for e in members {
        match e.s {
            Some(s) => {
                values.extend([s.re, s.im]);
                bounds.push(format!("|Δs| ≤ {:.1e} (η = {:.1e})", e.error_bound, e.backward_error));
            }
            None => bounds.push(format!("s = ∞ (|1/s| ≤ {:.1e})", e.error_bound)),
        }
    }
    quantity(
        &format!("{label}: s = (Re s, Im s) per eigenvalue"),
        values,
        "1/s | rad/s",
        Some(bounds.join("; ")),
    )
}

fn kind_name(kind: QuadraticModeKind) -> &'static str {
    match kind {
        QuadraticModeKind::Underdamped => "underdamped",
        QuadraticModeKind::Overdamped => "overdamped",
        QuadraticModeKind::Critical => "critical",
        QuadraticModeKind::Rigid => "rigid",
        QuadraticModeKind::Unstable => "unstable",
        QuadraticModeKind::Neutral => "neutral",
        QuadraticModeKind::Relaxation => "relaxation",
        QuadraticModeKind::Infinite => "infinite",
        _ => "undecided",
    }
}

/// A stability verdict from the kinds of the modes.
fn verdicts(result: &DampedModes) -> Vec<String> {
    let count = |kind: QuadraticModeKind| result.solution.modes.iter().filter(|m| m.kind == kind).count();
    let (unstable, undecided) = (count(QuadraticModeKind::Unstable), count(QuadraticModeKind::Undecided));
    let mut notes = vec![if unstable > 0 {
        format!("{unstable} growing mode(s): q0 is unstable")
    } else {
        "no mode grows beyond its bound".to_string()
    }];
    if undecided > 0 {
        notes.push(format!("{undecided} mode(s) whose kind the accuracy does not decide"));
    }
    notes
}
