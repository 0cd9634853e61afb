//! The result of a dense solve: modes, shapes, groups, the accuracy report, the method and the
//! time of each stage.

use crate::certify::report::AccuracyReport;
use crate::spectrum::{Mode, ModeGroup};
use faer::Mat;
use std::time::Duration;

/// How the modes were computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Cholesky A = LLᵀ, C = L⁻¹BL⁻ᵀ, C = Y Λ Yᵀ ([`crate::linalg::eigen`]), X = L⁻ᵀY.
    CholeskyReduction,
    /// Massless coordinates condensed out first (A semidefinite), then the reduction.
    CondensedReduction {
        /// Number of massless directions (infinite modes).
        massless: usize,
    },
}

/// The result of [`crate::solve()`]: modes, shapes, groups and the accuracy report.
#[derive(Debug, Clone)]
pub struct ModalSolution {
    /// Selected modes, ascending in ω².
    pub modes: Vec<Mode>,
    /// n × modes.len() mode shapes (columns, A-orthonormal for finite modes; Euclidean unit
    /// vectors of the null space of A for infinite modes), or None for values only.
    pub vectors: Option<Mat<f64>>,
    /// Groups of equal frequencies; each group's columns in `vectors` form an A-orthonormal
    /// basis of its eigenspace.
    pub groups: Vec<ModeGroup>,
    /// How the accuracy of every number above is known.
    pub accuracy: AccuracyReport,
    /// Algorithm used.
    pub method: Method,
    /// Wall time of each stage.
    pub timings: SolveTimings,
}

/// Wall time of each stage of a dense [`crate::solve()`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveTimings {
    /// Cholesky of A (or the condensation of a semidefinite A) and the reduction C = L⁻¹BL⁻ᵀ.
    pub factor: Duration,
    /// Eigen-decomposition of C and back-transformation X = L⁻ᵀY.
    pub eigen: Duration,
    /// Accuracy report: residual products, per-mode bounds, orthogonality.
    pub accuracy: Duration,
    /// Refinement of poorly bounded modes (with their residual bounds).
    pub refine: Duration,
    /// Sturm (inertia) check.
    pub inertia: Duration,
}

impl std::ops::AddAssign for SolveTimings {
    /// Adds each stage's time: a solve done in parts (a first try, a wider selection) reports
    /// the sum.
    fn add_assign(&mut self, other: Self) {
        self.factor += other.factor;
        self.eigen += other.eigen;
        self.accuracy += other.accuracy;
        self.refine += other.refine;
        self.inertia += other.inertia;
    }
}

pub(crate) fn empty_solution() -> ModalSolution {
    ModalSolution {
        modes: Vec::new(),
        vectors: None,
        groups: Vec::new(),
        accuracy: AccuracyReport::empty(),
        method: Method::CholeskyReduction,
        timings: SolveTimings::default(),
    }
}
