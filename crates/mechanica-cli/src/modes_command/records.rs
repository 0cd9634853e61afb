//! The records of `mechanica modes`: the pencil read, its factorization, the modes with their
//! accuracy, the refinement and the Sturm check.

use crate::mechanism_run::records::SturmStatus;
use crate::mode_record::{ModeRecord, write_modes};
use crate::report::text::{Text, bound, name_of, number};
use serde::Serialize;

/// Two Matrix Market files read.
#[derive(Debug, Clone, Serialize)]
pub struct PencilReadRecord {
    /// The order n.
    pub order: usize,
    /// Stored entries of A.
    pub mass_entries: usize,
    /// Stored entries of B.
    pub stiffness_entries: usize,
}

impl PencilReadRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.count("order n", self.order);
        out.line(
            "stored entries of A, B",
            &format!("{}, {}", self.mass_entries, self.stiffness_entries),
        );
    }
}

/// The factorization: Cholesky of A and C = L⁻¹BL⁻ᵀ (dense), or of B − σA (sparse).
#[derive(Debug, Clone, Serialize)]
pub struct PencilFactorRecord {
    /// The shift σ, rad²/s² (sparse).
    pub shift: Option<f64>,
    /// Stored entries of the sparse factor.
    pub factor_entries: Option<usize>,
}

impl PencilFactorRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        if let Some(shift) = self.shift {
            out.line("shift σ", &format!("{} rad²/s²", number(shift, 10)));
        }
        if let Some(n) = self.factor_entries {
            out.count("stored entries of the factor", n);
        }
    }
}

/// Which solver computed the modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverName {
    /// The dense symmetric-definite solver.
    Dense,
    /// Sparse shift-invert block Lanczos.
    SparseLanczos,
}

/// The modes of the pencil.
#[derive(Debug, Clone, Serialize)]
pub struct PencilModesRecord {
    /// The solver.
    pub solver: SolverName,
    /// The modes, ω² ascending (with their shapes under `--shapes`).
    pub modes: Vec<ModeRecord>,
    /// Largest error bound of ω², rad²/s².
    pub max_bound: f64,
    /// Largest backward error and the A-orthogonality error (sparse; the dense solver reports
    /// them in its accuracy step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_backward_error: Option<f64>,
    /// A-orthogonality error of the shapes (sparse).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orthogonality_error: Option<f64>,
}

impl PencilModesRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let coordinates: Vec<String> = Vec::new();
        write_modes(out, &self.modes, &coordinates, 6);
        out.line("max error bound of ω²", &bound(self.max_bound));
        if let (Some(eta), Some(orthogonality)) = (self.max_backward_error, self.orthogonality_error) {
            out.line(
                "max backward error, A-orthogonality error",
                &format!("{}, {}", bound(eta), bound(orthogonality)),
            );
        }
    }
}

/// Residuals of the accuracy report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ResidualsName {
    /// Exact residual norms.
    Exact,
    /// Sketched (probabilistic upper bounds).
    Sketched,
}

/// The accuracy report of a dense solve.
#[derive(Debug, Clone, Serialize)]
pub struct PencilAccuracyRecord {
    /// How the residuals were measured.
    pub residuals: ResidualsName,
    /// Largest backward error, when pairs were formed (not with `--values-only`).
    pub max_backward_error: Option<f64>,
    /// A-orthogonality error, when pairs were formed.
    pub orthogonality_error: Option<f64>,
}

impl PencilAccuracyRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        if let (Some(eta), Some(orthogonality)) = (self.max_backward_error, self.orthogonality_error) {
            out.line(
                "max backward error, A-orthogonality error",
                &format!(
                    "{}, {}   ({} residuals)",
                    bound(eta),
                    bound(orthogonality),
                    name_of(&self.residuals)
                ),
            );
        }
    }
}

/// The refinement of poorly bounded modes.
#[derive(Debug, Clone, Serialize)]
pub struct PencilRefineRecord {
    /// Modes refined (dense); null when the solver does not count them.
    pub refined_modes: Option<usize>,
}

impl PencilRefineRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        if let Some(n) = self.refined_modes {
            out.count("refined modes", n);
        }
    }
}

/// The Sturm check: the inertia of B − τA counts the modes below τ.
#[derive(Debug, Clone, Serialize)]
pub struct SturmRecord {
    /// The outcome.
    pub status: SturmStatus,
    /// The shift τ, rad²/s², when run.
    pub shift: Option<f64>,
    /// Modes below τ by the inertia count.
    pub count_below: Option<usize>,
    /// Computed modes below τ.
    pub computed_below: Option<usize>,
}

impl SturmRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let status = name_of(&self.status);
        match (self.shift, self.count_below, self.computed_below) {
            (Some(shift), Some(count), Some(computed)) => out.line(
                "Sturm check: shift, count below, computed",
                &format!("{}, {count}, {computed}   ({status})", number(shift, 10)),
            ),
            _ => out.line("Sturm check", &status),
        }
    }
}
