//! The result of a sparse solve: the modes, their shapes and groups, and the report of how they
//! were obtained and how accurate they are.

use crate::sparse::inertia::SparseInertiaCount;
use crate::spectrum::{Mode, ModeGroup};
use faer::Mat;
use std::time::Duration;

/// Wall time of each stage of a sparse solve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SparseSolveTimings {
    /// Symbolic analysis and Cholesky factorization of B − σA (all shifts tried).
    pub factor: Duration,
    /// Lanczos iterations (all rounds).
    pub lanczos: Duration,
    /// Rayleigh–Ritz refinement, residuals and bounds.
    pub refine: Duration,
    /// Inertia (Sturm) checks, on their own thread: this time overlaps `lanczos` or `refine`
    /// unless faer's global parallelism is sequential.
    pub inertia: Duration,
    /// Of lanczos + refine: the triangular solves with the factor of B − σA.
    pub solves: Duration,
}

/// How the sparse result was obtained and how accurate it is.
#[derive(Debug, Clone, PartialEq)]
pub struct SparseAccuracyReport {
    /// The shift σ of the factored operator (every mode lies above it).
    pub shift: f64,
    /// Cholesky factorizations tried to find a positive definite B − σA.
    pub shift_attempts: usize,
    /// Stored entries of the Cholesky factor L of B − σA (0 on the dense path): the memory of
    /// the solve is O(this + n·basis size).
    pub factor_nnz: usize,
    /// ‖A‖_F and ‖B‖_F.
    pub norm_a: f64,
    /// ‖B‖_F.
    pub norm_b: f64,
    /// Thick restarts over all Lanczos runs.
    pub restarts: usize,
    /// Applications of K⁻¹A.
    pub operator_applications: usize,
    /// Lanczos runs (1 + deflated reruns for missed modes); 0 on the dense path.
    pub lanczos_runs: usize,
    /// Multiplicity of the k-th (highest returned) mode's eigenvalue among all modes computed
    /// below the inertia shift τ, which is the whole eigenspace when `consistent` (τ lies in a
    /// real gap above the k-th mode). It exceeds the last returned group's multiplicity when
    /// the count k cuts through a repeated eigenvalue.
    pub kth_group_multiplicity: usize,
    /// Largest backward error η of the returned pairs.
    pub max_backward_error: f64,
    /// max |(XᵀAX − I)_ij| of the returned vectors.
    pub orthogonality_error: f64,
    /// The inertia check: B − τA at τ in a gap above the k-th mode.
    pub inertia: Option<SparseInertiaCount>,
    /// How many computed modes lie below τ.
    pub computed_below: usize,
    /// Whether the inertia count equals computed_below (no mode below τ missed or invented).
    pub consistent: bool,
    /// True when the problem was solved densely: small enough (n ≤
    /// [`crate::Tuning::dense_limit`]), or Lanczos did not converge on it and n ≤
    /// [`crate::Tuning::dense_rescue_limit`].
    pub dense_fallback: bool,
    /// Stage timings.
    pub timings: SparseSolveTimings,
}

/// The k lowest modes of a sparse pencil.
#[derive(Debug, Clone)]
pub struct SparseModalSolution {
    /// The modes, ascending in ω² (error bounds and backward errors filled in).
    pub modes: Vec<Mode>,
    /// n × k A-orthonormal mode shapes.
    pub vectors: Mat<f64>,
    /// Groups of numerically equal frequencies (repeated modes).
    pub groups: Vec<ModeGroup>,
    /// Accuracy and cost.
    pub report: SparseAccuracyReport,
}
