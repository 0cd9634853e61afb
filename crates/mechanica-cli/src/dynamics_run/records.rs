//! The records of a scene's dynamics steps: forward and inverse dynamics at q0 with the joint
//! reactions, and the damped modes about q0.

use crate::report::text::{Precision, Text, bound, name_of, number};
use serde::Serialize;

/// How q̈ was computed (mechanica::dynamics::ForwardMethod).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ForwardMethodName {
    /// The articulated-body recursion, confirmed by the inverse dynamics.
    ArticulatedBody,
    /// The mass matrix and its Cholesky factor.
    MassMatrix,
}

/// Forward dynamics q̈ = A⁻¹ (τ + Σ Q − c − g) at q0 (7.60).
#[derive(Debug, Clone, Serialize)]
pub struct ForwardRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q̈, rad/s² | m/s².
    pub q_ddot: Vec<f64>,
    /// The method.
    pub method: ForwardMethodName,
    /// Backward error of q̈.
    pub backward_error: f64,
    /// κ∞(A), when estimated.
    pub condition: Option<f64>,
    /// Estimated ∞-norm error of q̈ (‖A⁻¹‖∞ times the residual and its rounding), when the
    /// mass matrix was formed and is not singular to working precision (then absent beside a
    /// condition number: no digit of q̈ is assured).
    pub error_estimate: Option<f64>,
    /// τ − RNEA(q, q̇, q̈), N·m | N.
    pub residual: Vec<f64>,
    /// Dissipation function D of the dampers, W.
    pub dissipation: f64,
}

impl ForwardRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        // The estimate is of the ∞-norm error (absolute); the articulated route has none, and
        // its backward error says nothing of q̈'s digits when A is ill-conditioned.
        let (precision, accuracy) = match (self.error_estimate, self.condition) {
            (Some(e), _) => (Precision::Absolute(e), format!("estimated error of q̈ {}", bound(e))),
            (None, Some(_)) => (
                Precision::Relative(f64::INFINITY),
                "A is singular to working precision: no digit of q̈ is assured".to_string(),
            ),
            (None, None) => (Precision::Exact, "forward error not estimated".to_string()),
        };
        out.named(
            "q̈ (forward dynamics)",
            &self.coordinates,
            &self.q_ddot,
            "rad/s² | m/s²",
            precision,
        );
        out.line(
            "method",
            &format!(
                "{}; backward error {}{}; {accuracy}",
                name_of(&self.method),
                bound(self.backward_error),
                self.condition
                    .map_or(String::new(), |c| format!("; κ∞(A) = {}", bound(c))),
            ),
        );
        out.values(
            "residual τ − RNEA(q, q̇, q̈)",
            &self.residual,
            "N·m | N",
            Precision::Exact,
        );
        out.value(
            "dissipation function D of the dampers",
            self.dissipation,
            "W",
            Precision::Exact,
        );
    }
}

/// A generalized force of one load.
#[derive(Debug, Clone, Serialize)]
pub struct LoadRecord {
    /// The load's name.
    pub name: String,
    /// Q, N·m | N per coordinate.
    pub force: Vec<f64>,
}

/// The reaction at one joint: force and moment about the joint origin that the parent exerts
/// on the body.
#[derive(Debug, Clone, Serialize)]
pub struct JointReaction {
    /// The joint's name.
    pub joint: String,
    /// Force, N.
    pub force: [f64; 3],
    /// Moment about the joint origin, N·m.
    pub moment: [f64; 3],
}

/// Inverse dynamics τ = A q̈ + c + g − Σ Q and the joint reactions (RNEA).
#[derive(Debug, Clone, Serialize)]
pub struct InverseRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// The q̈ used, rad/s² | m/s².
    pub q_ddot: Vec<f64>,
    /// τ, N·m | N.
    pub tau: Vec<f64>,
    /// Largest rounding-error estimate of τ.
    pub rounding_estimate: f64,
    /// c(q, q̇): velocity-product terms.
    pub velocity_product: Vec<f64>,
    /// g(q): gravity terms.
    pub gravity: Vec<f64>,
    /// The generalized forces of the loads.
    pub loads: Vec<LoadRecord>,
    /// "world", "body" or "joint": the frame of the reactions.
    pub frame: String,
    /// One reaction per joint.
    pub reactions: Vec<JointReaction>,
}

impl InverseRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let names = &self.coordinates;
        let exact = Precision::Exact;
        out.named("q̈ of the inverse dynamics", names, &self.q_ddot, "rad/s² | m/s²", exact);
        let rounding = Precision::Absolute(self.rounding_estimate);
        out.named("τ (inverse dynamics)", names, &self.tau, "N·m | N", rounding);
        out.named(
            "c(q, q̇): velocity-product terms",
            names,
            &self.velocity_product,
            "N·m | N",
            exact,
        );
        out.named("g(q): gravity terms", names, &self.gravity, "N·m | N", exact);
        for load in &self.loads {
            out.named(&format!("Q of {}", load.name), names, &load.force, "N·m | N", exact);
        }
        for r in &self.reactions {
            let values: Vec<f64> = r.force.iter().chain(&r.moment).copied().collect();
            let label = format!("reaction at \"{}\" ({} frame)", r.joint, self.frame);
            out.values(&label, &values, "N | N·m", exact);
        }
    }
}

/// What a damped mode is (mechanica::modal::QuadraticModeKind).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DampedKind {
    /// A complex pair with Re s < 0.
    Underdamped,
    /// Two real negative roots.
    Overdamped,
    /// A double real root.
    Critical,
    /// s = 0 twice.
    Rigid,
    /// Re s > 0 beyond its bound.
    Unstable,
    /// Re s = 0 within its bound, Im s ≠ 0.
    Neutral,
    /// A single real root (a massless, damped direction).
    Relaxation,
    /// s = ∞.
    Infinite,
    /// The accuracy does not decide.
    Undecided,
}

/// One eigenvalue s of a damped mode.
#[derive(Debug, Clone, Serialize)]
pub struct DampedEigenvalue {
    /// [Re s, Im s], 1/s | rad/s; null for s = ∞.
    pub s: Option<[f64; 2]>,
    /// Bound on |Δs| (on |1/s| for s = ∞).
    pub bound: f64,
    /// Backward error η.
    pub backward_error: f64,
}

/// One damped mode.
#[derive(Debug, Clone, Serialize)]
pub struct DampedModeRecord {
    /// The classification.
    pub kind: DampedKind,
    /// ω_n, rad/s, when defined.
    pub natural_frequency: Option<f64>,
    /// ω_d, rad/s.
    pub damped_frequency: f64,
    /// ζ, when defined.
    pub damping_ratio: Option<f64>,
    /// Its eigenvalues.
    pub eigenvalues: Vec<DampedEigenvalue>,
}

/// The verdict on q0 from the damped modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DampedVerdict {
    /// Some mode grows beyond its bound: q0 is unstable.
    Unstable,
    /// No mode grows beyond its bound.
    NoGrowth,
}

/// The damped modes det(s²A + s(C + G) + B) = 0 at q0.
#[derive(Debug, Clone, Serialize)]
pub struct DampedModesRecord {
    /// Why the damped modes were not computed (the scene has what they do not model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_computed: Option<String>,
    /// ‖grad U*(q0)‖: the linearization is exact only at 0, an equilibrium.
    pub gradient_norm: Option<f64>,
    /// The modes.
    pub modes: Vec<DampedModeRecord>,
    /// The verdict, when computed.
    pub stability: Option<DampedVerdict>,
    /// Number of growing modes.
    pub growing_modes: usize,
    /// Number of modes whose kind the accuracy does not decide.
    pub undecided_modes: usize,
}

impl DampedModesRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        if let Some(reason) = &self.not_computed {
            out.note(&format!("damped modes not computed: {reason}"));
            return;
        }
        if let Some(g) = self.gradient_norm {
            out.line("‖grad U*(q0)‖", &format!("{} N·m | N", bound(g)));
        }
        for (k, mode) in self.modes.iter().enumerate() {
            out.line(
                &format!("damped mode {} ({})", k + 1, kind_text(mode.kind)),
                &frequencies(mode),
            );
            let roots: Vec<String> = mode.eigenvalues.iter().map(root).collect();
            out.line("  s = Re s ± i Im s", &roots.join("; "));
        }
        match self.stability {
            Some(DampedVerdict::Unstable) => {
                out.note(&format!("{} growing mode(s): q0 is unstable", self.growing_modes))
            }
            Some(DampedVerdict::NoGrowth) => out.note("no mode grows beyond its bound"),
            None => {}
        }
        if self.undecided_modes > 0 {
            out.note(&format!(
                "{} mode(s) whose kind the accuracy does not decide",
                self.undecided_modes
            ));
        }
    }
}

fn kind_text(kind: DampedKind) -> String {
    name_of(&kind)
}

/// ω_n, ω_d and ζ, those that are defined (rounded to the smallest bound of the mode's roots).
fn frequencies(mode: &DampedModeRecord) -> String {
    let tightest = mode.eigenvalues.iter().map(|e| e.bound).fold(f64::INFINITY, f64::min);
    let precision = Precision::Absolute(if tightest.is_finite() { tightest } else { 0.0 });
    let show = |v: f64| number(v, precision.digits(v));
    let mut parts = Vec::new();
    if let Some(w) = mode.natural_frequency {
        parts.push(format!("ω_n = {} rad/s", show(w)));
    }
    parts.push(format!("ω_d = {} rad/s", show(mode.damped_frequency)));
    if let (Some(zeta), Some(omega_n)) = (mode.damping_ratio, mode.natural_frequency) {
        // ζ = −Re s / ω_n: its error is about the roots' bound over ω_n.
        let zeta_precision = Precision::Absolute(if tightest.is_finite() { tightest / omega_n } else { 0.0 });
        parts.push(format!("ζ = {}", number(zeta, zeta_precision.digits(zeta))));
    }
    parts.join(", ")
}

fn root(e: &DampedEigenvalue) -> String {
    match e.s {
        Some([re, im]) => {
            let precision = Precision::Absolute(e.bound);
            format!(
                "{} + {}i (|Δs| ≤ {}, η = {})",
                number(re, precision.digits(re)),
                number(im, precision.digits(im)),
                bound(e.bound),
                bound(e.backward_error)
            )
        }
        None => format!("s = ∞ (|1/s| ≤ {})", bound(e.bound)),
    }
}
