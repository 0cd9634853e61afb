//! The records of a constrained scene's dynamics steps: the projection onto the constraints,
//! the forward dynamics with multipliers, and the constrained equilibrium.

use crate::report::text::{Precision, Text, bound};
use serde::Serialize;

/// q0 and q̇ projected onto f(q) = 0 and J q̇ = 0 (least kinetic metric).
#[derive(Debug, Clone, Serialize)]
pub struct ProjectionRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q on the constraints, rad | m.
    pub q: Vec<f64>,
    /// ‖q − q0‖₂.
    pub moved: f64,
    /// ‖f(q)‖₂ left.
    pub constraint_residual: f64,
    /// Gauss–Newton iterations.
    pub iterations: usize,
    /// Tolerance on ‖f‖₂.
    pub tolerance: f64,
    /// q̇ with J q̇ = 0, rad/s | m/s.
    pub q_dot: Vec<f64>,
    /// ‖J q̇‖₂ before the projection.
    pub velocity_removed: f64,
    /// ‖J q̇‖₂ after.
    pub velocity_residual: f64,
}

impl ProjectionRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let names = &self.coordinates;
        out.named(
            "q on the constraints",
            names,
            &self.q,
            "rad | m",
            Precision::Absolute(self.constraint_residual),
        );
        out.line(
            "‖q − q0‖₂, ‖f(q)‖₂",
            &format!(
                "{}, {}   ({} Gauss–Newton iteration(s); tolerance {})",
                bound(self.moved),
                bound(self.constraint_residual),
                self.iterations,
                bound(self.tolerance)
            ),
        );
        out.named("q̇ with J q̇ = 0", names, &self.q_dot, "rad/s | m/s", Precision::Exact);
        out.line(
            "‖J q̇‖₂ before, after",
            &format!("{}, {}", bound(self.velocity_removed), bound(self.velocity_residual)),
        );
    }
}

/// The reaction of one constraint.
#[derive(Debug, Clone, Serialize)]
pub struct ConstraintReactionRecord {
    /// The constraint's name (`constraint[i]` when the scene gives none).
    pub constraint: String,
    /// Force on its first point (world), N, for a constraint between points.
    pub force: Option<[f64; 3]>,
    /// Generalized force −Jᵢᵀλᵢ, N·m | N.
    pub generalized_force: Vec<f64>,
}

/// Forward dynamics and multipliers from [A Jᵀ; J 0] (FM 4.61).
#[derive(Debug, Clone, Serialize)]
pub struct ConstrainedForwardRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q̈, rad/s² | m/s².
    pub q_ddot: Vec<f64>,
    /// λ, one per constraint equation, N | N·m.
    pub multipliers: Vec<f64>,
    /// Backward error of the KKT solve.
    pub backward_error: f64,
    /// κ(A).
    pub mass_condition: f64,
    /// κ(J A⁻¹ Jᵀ).
    pub schur_condition: f64,
    /// ‖f(q)‖₂.
    pub position_drift: f64,
    /// ‖J q̇‖₂.
    pub velocity_drift: f64,
    /// One reaction per constraint.
    pub reactions: Vec<ConstraintReactionRecord>,
}

impl ConstrainedForwardRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let relative = self.backward_error * self.mass_condition.max(self.schur_condition);
        let names = &self.coordinates;
        let precision = Precision::Relative(relative);
        out.named(
            "q̈ (constrained forward dynamics)",
            names,
            &self.q_ddot,
            "rad/s² | m/s²",
            precision,
        );
        out.values(
            "λ (one per constraint equation)",
            &self.multipliers,
            "N | N·m",
            precision,
        );
        out.line(
            "accuracy",
            &format!(
                "backward error {}; κ(A) = {}, κ(J A⁻¹ Jᵀ) = {}",
                bound(self.backward_error),
                bound(self.mass_condition),
                bound(self.schur_condition)
            ),
        );
        out.line(
            "drift ‖f(q)‖₂, ‖J q̇‖₂",
            &format!("{}, {}", bound(self.position_drift), bound(self.velocity_drift)),
        );
        write_reactions(out, &self.reactions, names);
    }
}

fn write_reactions(out: &mut Text, reactions: &[ConstraintReactionRecord], names: &[String]) {
    for r in reactions {
        if let Some(force) = &r.force {
            let label = format!("reaction of \"{}\": force on its first point", r.constraint);
            out.values(&label, force, "N", Precision::Exact);
        }
        let label = format!("reaction of \"{}\": −Jᵀλ", r.constraint);
        out.named(&label, names, &r.generalized_force, "N·m | N", Precision::Exact);
    }
}

/// The constrained equilibrium ∇U + Jᵀλ = 0, f(q) = 0 (FM 4.83–4.86).
#[derive(Debug, Clone, Serialize)]
pub struct ConstrainedEquilibriumRecord {
    /// The coordinates' names.
    pub coordinates: Vec<String>,
    /// q at the equilibrium, rad | m.
    pub q: Vec<f64>,
    /// U there, J.
    pub potential: f64,
    /// λ there.
    pub multipliers: Vec<f64>,
    /// ‖∇U + Jᵀλ‖₂.
    pub stationarity: f64,
    /// Its tolerance.
    pub stationarity_tolerance: f64,
    /// ‖f‖₂.
    pub constraint_norm: f64,
    /// Its tolerance.
    pub constraint_tolerance: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// One reaction per constraint.
    pub reactions: Vec<ConstraintReactionRecord>,
}

impl ConstrainedEquilibriumRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let names = &self.coordinates;
        out.named(
            "q at the constrained equilibrium",
            names,
            &self.q,
            "rad | m",
            Precision::Exact,
        );
        out.line(
            "accuracy",
            &format!(
                "‖∇U + Jᵀλ‖₂ = {} ≤ {}, ‖f‖₂ = {} ≤ {}; {} Newton iteration(s)",
                bound(self.stationarity),
                bound(self.stationarity_tolerance),
                bound(self.constraint_norm),
                bound(self.constraint_tolerance),
                self.iterations
            ),
        );
        out.value("U at the equilibrium", self.potential, "J", Precision::Exact);
        out.values("λ at the equilibrium", &self.multipliers, "N | N·m", Precision::Exact);
        write_reactions(out, &self.reactions, names);
    }
}
