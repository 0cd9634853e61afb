//! One mode of det(λA + B) = 0 (8.89, λ = −ω²) as the report states it, shared by the modes
//! of a scene's mechanism and of a Matrix Market pencil, and its lines of the text report.

use crate::report::text::{Precision, Text, bound, name_of, number};
use mechanica::modal::{Mode, ModeGroup, ModeKind};
use serde::Serialize;

/// What a mode is physically (mechanica::modal::ModeKind).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeKindName {
    /// ω² > 0 beyond its bound.
    Oscillatory,
    /// ω² within the data's resolution of 0: a rigid-body mode.
    Zero,
    /// ω² < 0 beyond its bound: growth e^{γt}.
    Unstable,
    /// A massless direction: ω² = +∞.
    Infinite,
    /// ω² ± bound contains 0 and the bound is far above the data's resolution.
    Undecided,
}

impl ModeKindName {
    /// The class of `kind`.
    pub fn of(kind: ModeKind) -> ModeKindName {
        match kind {
            ModeKind::Oscillatory { .. } => ModeKindName::Oscillatory,
            ModeKind::Zero => ModeKindName::Zero,
            ModeKind::Unstable { .. } => ModeKindName::Unstable,
            ModeKind::Infinite => ModeKindName::Infinite,
            ModeKind::Undecided => ModeKindName::Undecided,
        }
    }

    /// The name the JSON report uses.
    pub fn as_str(self) -> &'static str {
        match self {
            ModeKindName::Oscillatory => "oscillatory",
            ModeKindName::Zero => "zero",
            ModeKindName::Unstable => "unstable",
            ModeKindName::Infinite => "infinite",
            ModeKindName::Undecided => "undecided",
        }
    }
}

/// A body's motion in a mode, per unit modal amplitude (world components).
#[derive(Debug, Clone, Serialize)]
pub struct BodyMotion {
    /// The body's name.
    pub body: String,
    /// Displacement of its centre of mass, m.
    pub translation: [f64; 3],
    /// Small rotation vector, rad.
    pub rotation: [f64; 3],
}

/// One mode.
#[derive(Debug, Clone, Serialize)]
pub struct ModeRecord {
    /// ω² = −λ, rad²/s²; null for an infinite mode (ω² = +∞).
    pub omega_sq: Option<f64>,
    /// Bound on |ω²_computed − ω²_exact|, rad²/s².
    pub bound: f64,
    /// Backward error η of the pair, when measured.
    pub backward_error: Option<f64>,
    /// The classification.
    pub kind: ModeKindName,
    /// ω, rad/s: √ω² for an oscillatory mode, 0 for a zero mode, null otherwise.
    pub omega: Option<f64>,
    /// f = ω/2π, Hz, where ω is given.
    pub frequency_hz: Option<f64>,
    /// γ = √(−ω²), 1/s, of an unstable mode; null otherwise.
    pub growth_rate: Option<f64>,
    /// Index of the mode's group of equal frequencies (within their bounds).
    pub group: usize,
    /// Number of modes in the group.
    pub multiplicity: usize,
    /// The A-normalised shape, one entry per coordinate, when computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<Vec<f64>>,
    /// Effective modal masses for unit base translations along x, y, z, kg (mechanisms).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effective_mass: Option<[f64; 3]>,
    /// Every body's motion per unit amplitude (mechanisms).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bodies: Option<Vec<BodyMotion>>,
}

impl ModeRecord {
    /// The record of `mode` of a solution with `groups`, with its `shape` if computed.
    pub fn new(mode: &Mode, groups: &[ModeGroup], shape: Option<Vec<f64>>) -> ModeRecord {
        let (kind, omega, growth_rate) = match mode.kind {
            ModeKind::Oscillatory { omega } => (ModeKindName::Oscillatory, Some(omega), None),
            ModeKind::Zero => (ModeKindName::Zero, Some(0.0), None),
            ModeKind::Unstable { growth_rate } => (ModeKindName::Unstable, None, Some(growth_rate)),
            ModeKind::Infinite => (ModeKindName::Infinite, None, None),
            ModeKind::Undecided => (ModeKindName::Undecided, None, None),
        };
        ModeRecord {
            omega_sq: (kind != ModeKindName::Infinite).then_some(mode.omega_sq),
            bound: mode.error_bound,
            backward_error: mode.backward_error,
            kind,
            omega,
            frequency_hz: omega.map(|w| w / std::f64::consts::TAU),
            growth_rate,
            group: mode.group,
            multiplicity: groups.get(mode.group).map_or(1, |g| g.multiplicity),
            shape,
            effective_mass: None,
            bodies: None,
        }
    }

    /// The mode's line: kind, ω² with its bound, frequency or growth rate, multiplicity.
    pub fn summary(&self) -> String {
        let mut text = name_of(&self.kind);
        if let Some(w2) = self.omega_sq {
            let digits = Precision::Absolute(self.bound).digits(w2);
            text.push_str(&format!(
                ", ω² = {} ± {} rad²/s²",
                number(w2, digits),
                bound(self.bound)
            ));
        }
        if let (Some(f), Some(w2)) = (self.frequency_hz, self.omega_sq) {
            let relative = if w2 == 0.0 { 0.0 } else { 0.5 * self.bound / w2.abs() };
            text.push_str(&format!(
                ", f = {} Hz",
                number(f, Precision::Relative(relative).digits(f))
            ));
        }
        if let (Some(gamma), Some(w2)) = (self.growth_rate, self.omega_sq) {
            let relative = 0.5 * self.bound / w2.abs();
            let digits = Precision::Relative(relative).digits(gamma);
            text.push_str(&format!(", γ = {} 1/s", number(gamma, digits)));
        }
        if self.multiplicity > 1 {
            text.push_str(&format!(", multiplicity {} (group {})", self.multiplicity, self.group));
        }
        text
    }
}

/// The modes' lines of the text report: every mode's summary, the shapes of the first
/// `shown` modes named by `coordinates`, their effective masses and body motions.
pub fn write_modes(out: &mut Text, modes: &[ModeRecord], coordinates: &[String], shown: usize) {
    for (k, mode) in modes.iter().enumerate() {
        out.line(&format!("mode {}", k + 1), &mode.summary());
    }
    for (k, mode) in modes.iter().enumerate().take(shown) {
        if let Some(shape) = &mode.shape {
            out.named(
                &format!("mode {} shape (A-normalised)", k + 1),
                coordinates,
                shape,
                "",
                Precision::Exact,
            );
        }
        if let Some(mass) = &mode.effective_mass {
            out.values(
                &format!("mode {} effective mass (x, y, z)", k + 1),
                mass,
                "kg",
                Precision::Exact,
            );
        }
    }
    for (k, mode) in modes.iter().enumerate().take(shown.min(3)) {
        for body in mode.bodies.iter().flatten() {
            let values: Vec<f64> = body.translation.iter().chain(&body.rotation).copied().collect();
            out.values(
                &format!("mode {} {}: translation, rotation", k + 1, body.body),
                &values,
                "m | rad",
                Precision::Exact,
            );
        }
    }
    if modes.len() > shown && modes.iter().any(|m| m.shape.is_some()) {
        out.note(&format!(
            "shapes of the first {shown} modes shown; the JSON report has all"
        ));
    }
}
