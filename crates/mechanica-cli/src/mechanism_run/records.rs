//! The records of a scene's mechanism analyses: the mechanism, equilibria, modes and
//! stability, the free response and impacts.

use crate::mode_record::{ModeRecord, write_modes};
use crate::report::text::{Precision, Text, bound, name_of, number};
use serde::Serialize;

/// The mechanism built from a scene.
#[derive(Debug, Clone, Serialize)]
pub struct MechanismRecord {
    /// Number of potentials (springs, constant forces; gravity and the rotating frame are
    /// part of the mechanism).
    pub potentials: usize,
}

impl MechanismRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.count("potentials", self.potentials);
    }
}

/// The verdict on an equilibrium (mechanica::mechanism::Stability).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Every mode oscillates (B positive definite relative to A).
    Stable,
    /// Some ω² < 0 beyond its bound.
    Unstable,
    /// No unstable mode, but zero modes within their bounds.
    Marginal,
    /// No proven unstable mode, but modes whose sign is not decided.
    Undecided,
}

/// The stability of an equilibrium from its modes.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityRecord {
    /// The verdict.
    pub verdict: Verdict,
    /// Number of unstable directions.
    pub unstable_directions: usize,
    /// Largest growth rate, 1/s, when unstable.
    pub max_growth_rate: Option<f64>,
    /// Number of zero modes.
    pub zero_modes: usize,
    /// Number of modes whose sign is not decided.
    pub undecided_modes: usize,
}

impl StabilityRecord {
    /// The verdict in words.
    pub fn sentence(&self) -> String {
        match self.verdict {
            Verdict::Stable => "stable: every mode oscillates (B positive definite relative to A)".into(),
            Verdict::Unstable => format!(
                "unstable: {} unstable direction(s), fastest growth rate {} 1/s",
                self.unstable_directions,
                number(self.max_growth_rate.unwrap_or(0.0), 7)
            ),
            Verdict::Marginal => format!(
                "marginal: {} zero mode(s) within their error bounds, none unstable",
                self.zero_modes
            ),
            Verdict::Undecided => format!(
                "undecided: {} mode(s) whose interval contains zero, far wider than the data's resolution; none proven unstable",
                self.undecided_modes
            ),
        }
    }
}

/// A further equilibrium found from the scene's extra starts.
#[derive(Debug, Clone, Serialize)]
pub struct FoundEquilibrium {
    /// Its coordinates.
    pub q: Vec<f64>,
    /// Its stability, when its modes could be computed.
    pub stability: Option<StabilityRecord>,
    /// Why its stability is unknown, otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability_error: Option<String>,
}

/// The searches from the scene's further starts.
#[derive(Debug, Clone, Serialize)]
pub struct MultiStartRecord {
    /// Number of starts (q0 and the scene's `starts`).
    pub starts: usize,
    /// Searches that did not converge.
    pub failed: usize,
    /// The distinct equilibria (apart by more than 1e-8 in some coordinate).
    pub equilibria: Vec<FoundEquilibrium>,
}

/// An equilibrium search: Newton on grad U* (8.74).
#[derive(Debug, Clone, Serialize)]
pub struct EquilibriumRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q at the equilibrium, rad | m.
    pub q: Vec<f64>,
    /// |grad U*| there, J.
    pub gradient_norm: f64,
    /// The convergence tolerance on |grad U*|, J.
    pub tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Size of the last Newton step (an estimate of the error of q).
    pub last_step: f64,
    /// U* at the equilibrium, J.
    pub potential: f64,
    /// Coordinates resting on a joint limit there (held fixed for the modes).
    pub locked: Vec<String>,
    /// Spherical and free joints were re-centred: their rotation vectors read 0 there.
    pub recentred: bool,
    /// The searches from further starts, when the scene gives some.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multi_start: Option<MultiStartRecord>,
}

impl EquilibriumRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let q_precision = Precision::Absolute(self.last_step);
        out.named("q at equilibrium", &self.coordinates, &self.q, "rad | m", q_precision);
        out.line(
            "|grad U*| at equilibrium",
            &format!(
                "{} J   (tolerance {}, {} Newton iterations)",
                bound(self.gradient_norm),
                bound(self.tolerance),
                self.iterations
            ),
        );
        out.value("U* at equilibrium", self.potential, "J", Precision::Exact);
        if !self.locked.is_empty() {
            out.line("resting on joint limits (locked)", &self.locked.join(", "));
        }
        if self.recentred {
            out.note("spherical/free joints were re-centred on the equilibrium: their rotation vectors read 0 in the new chart; bodies did not move");
        }
        if let Some(multi) = &self.multi_start {
            out.note(&format!(
                "{} distinct equilibria from {} starts ({} did not converge)",
                multi.equilibria.len(),
                multi.starts,
                multi.failed
            ));
            for (i, eq) in multi.equilibria.iter().enumerate() {
                out.named(
                    &format!("equilibrium {i}"),
                    &self.coordinates,
                    &eq.q,
                    "rad | m",
                    Precision::Exact,
                );
                match (&eq.stability, &eq.stability_error) {
                    (Some(s), _) => out.note(&format!("equilibrium {i}: {}", s.sentence())),
                    (None, Some(e)) => out.note(&format!("equilibrium {i}: stability unknown: {e}")),
                    (None, None) => {}
                }
            }
        }
    }
}

/// How far the computed modes can be trusted (mechanica::modal::AccuracyReport).
#[derive(Debug, Clone, Serialize)]
pub struct ModalAccuracy {
    /// Largest error bound of ω² over the finite modes, rad²/s².
    pub max_bound: f64,
    /// Largest backward error, when measured.
    pub max_backward_error: Option<f64>,
    /// A-orthogonality error of the shapes, when measured.
    pub orthogonality_error: Option<f64>,
    /// The Sturm count check.
    pub sturm_check: SturmStatus,
}

/// The outcome of a Sturm (inertia) check of a spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SturmStatus {
    /// The count of modes below the shift agrees with the computed spectrum.
    Consistent,
    /// It does not: a mode was missed or misplaced.
    Inconsistent,
    /// Not run (no finite mode).
    NotRun,
}

/// The gyroscopic problem of a rotating frame, det(s²A + sG + B) = 0.
#[derive(Debug, Clone, Serialize)]
pub struct GyroscopicRecord {
    /// Eigenvalues s as [Re s, Im s], 1/s.
    pub eigenvalues: Vec<[f64; 2]>,
    /// Backward error of each eigenvalue.
    pub backward_errors: Vec<f64>,
    /// Largest Re s, 1/s.
    pub max_real_part: f64,
    /// Bound below which |Re s| is indistinguishable from 0, 1/s.
    pub real_part_bound: f64,
    /// No Re s exceeds its bound (possibly gyroscopically stabilised).
    pub stable: bool,
}

/// The modes and stability of a mechanism at its equilibrium (8.84–8.92).
#[derive(Debug, Clone, Serialize)]
pub struct ModesRecord {
    /// The coordinates' names (the rows of every shape).
    pub coordinates: Vec<String>,
    /// Coordinates held fixed (resting on a joint limit); their rows of the shapes are 0.
    pub locked: Vec<String>,
    /// Coordinates left out because they move no mass and feel no force (their rows of A, B
    /// and G are zero); their rows of the shapes are 0.
    pub idle: Vec<String>,
    /// The stability verdict.
    pub stability: StabilityRecord,
    /// The modes, ω² ascending.
    pub modes: Vec<ModeRecord>,
    /// The accuracy of the solution.
    pub accuracy: ModalAccuracy,
    /// |grad U*| at the configuration; large means it is not an equilibrium.
    pub gradient_norm: f64,
    /// Total mass, kg (the bound of each effective-mass sum).
    pub total_mass: f64,
    /// The gyroscopic problem, in a rotating frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gyroscopic: Option<GyroscopicRecord>,
}

impl ModesRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        write_modes(out, &self.modes, &self.coordinates, 6);
        let a = &self.accuracy;
        out.line(
            "accuracy",
            &format!(
                "max error bound {}; max backward error {}; A-orthogonality error {}; Sturm check {}",
                bound(a.max_bound),
                bound(a.max_backward_error.unwrap_or(0.0)),
                bound(a.orthogonality_error.unwrap_or(0.0)),
                name_of(&a.sturm_check)
            ),
        );
        out.note(&self.stability.sentence());
        if let Some(g) = &self.gyroscopic {
            out.note(&format!(
                "rotating frame: gyroscopic problem det(s²A + sG + B) = 0 solved; max Re s = {} (bound {}) → {}",
                bound(g.max_real_part),
                bound(g.real_part_bound),
                if g.stable {
                    "stable (possibly gyroscopically stabilised)"
                } else {
                    "unstable"
                }
            ));
        }
        if !self.locked.is_empty() {
            out.note(&format!(
                "coordinates {} rest on joint limits at the equilibrium and are held fixed for the modes",
                self.locked.join(", ")
            ));
        }
        if !self.idle.is_empty() {
            out.note(&format!(
                "coordinates {} move no mass and feel no force (massless links without springs): left out of the modes",
                self.idle.join(", ")
            ));
        }
    }
}

/// The free response δ(t) by modal superposition (8.91).
#[derive(Debug, Clone, Serialize)]
pub struct ResponseRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The span T, s.
    pub duration: f64,
    /// Samples over [0, T].
    pub samples: usize,
    /// δ(T), rad | m.
    pub end: Vec<f64>,
    /// Error bound of δ(T).
    pub end_bound: f64,
    /// Residual of the fit of δ(0).
    pub displacement_fit_residual: f64,
    /// Residual of the fit of δ̇(0).
    pub velocity_fit_residual: f64,
}

impl ResponseRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let precision = Precision::Absolute(self.end_bound);
        out.named(
            "δ(T) at the end of the span",
            &self.coordinates,
            &self.end,
            "rad | m",
            precision,
        );
        out.line(
            "initial-state fit residual (δ, δ̇)",
            &format!(
                "{}, {}",
                bound(self.displacement_fit_residual),
                bound(self.velocity_fit_residual)
            ),
        );
    }
}

/// How a contact behaved during an impact (mechanica::impulse::ContactMode).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactModeName {
    /// No impulse: separating or grazing.
    NoImpact,
    /// Smooth contact: no tangential impulse.
    Frictionless,
    /// Stuck from the start.
    Stick,
    /// Slipped throughout.
    Slip,
    /// Slipped, then stuck.
    SlipThenStick,
    /// Slipped, halted and slipped again in a new direction.
    Reversed,
}

/// One restitution law's outcome of an impact.
#[derive(Debug, Clone, Serialize)]
pub struct ImpactLawRecord {
    /// "newton", "poisson" or "stronge".
    pub law: String,
    /// Impulse on the body (world), N·s.
    pub impulse: [f64; 3],
    /// Error of the impulse-parameterised integration, N·s.
    pub integration_error: f64,
    /// How the contact behaved.
    pub contact_mode: ContactModeName,
    /// q̇ after the impact, rad/s | m/s.
    pub q_dot_after: Vec<f64>,
    /// Kinetic energy before, J.
    pub energy_before: f64,
    /// ΔT (7.107), J; > 0 means energy was gained (Kane's paradox).
    pub energy_change: f64,
}

/// An impact of a body point on the ground at (q0, qd0) (7.115–7.117).
#[derive(Debug, Clone, Serialize)]
pub struct ImpactRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The body that strikes.
    pub body: String,
    /// The chosen law first, then the others when the scene compares laws.
    pub laws: Vec<ImpactLawRecord>,
}

impl ImpactRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        for law in &self.laws {
            let name = &law.law;
            out.values(
                &format!("{name}: impulse on the body (world)"),
                &law.impulse,
                "N·s",
                Precision::Absolute(law.integration_error),
            );
            out.named(
                &format!("{name}: q̇ after"),
                &self.coordinates,
                &law.q_dot_after,
                "rad/s | m/s",
                Precision::Exact,
            );
            out.values(
                &format!("{name}: T before, ΔT (7.107)"),
                &[law.energy_before, law.energy_change],
                "J",
                Precision::Exact,
            );
            out.line(&format!("{name}: contact"), &name_of(&law.contact_mode));
        }
    }
}

/// One law of Kane's double pendulum striking a rough floor.
#[derive(Debug, Clone, Serialize)]
pub struct ShowcaseLaw {
    /// The restitution law.
    pub law: String,
    /// Kinetic energy before, J.
    pub energy_before: f64,
    /// ΔT, J; > 0 means energy was gained (Kane's paradox).
    pub energy_change: f64,
}

/// Kane's double pendulum on a rough floor, e = f = 0.5, under every law.
#[derive(Debug, Clone, Serialize)]
pub struct ShowcaseRecord {
    /// One entry per law.
    pub laws: Vec<ShowcaseLaw>,
}

impl ShowcaseRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        for law in &self.laws {
            let verdict = if law.energy_change > 0.0 {
                "energy GAINED (Kane's paradox)"
            } else {
                "energy lost"
            };
            let values = [law.energy_before, law.energy_change];
            let shown: Vec<String> = values.iter().map(|&v| number(v, 10)).collect();
            out.line(
                &format!("{}: T before, ΔT", law.law),
                &format!("[{}] J   ({verdict})", shown.join(", ")),
            );
        }
    }
}
