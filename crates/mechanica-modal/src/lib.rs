//! Small oscillations: A δ̈ + B δ = 0 and det(λA + B) = 0 ((8.84)–(8.92), see docs/theory.md),
//! solved with faer, every result carrying its own accuracy report.
//!
//! This crate works on bare matrices; it needs no mechanism. Entry points: [`solve()`] on a
//! validated [`PencilProblem`] (dense), [`solve_sparse`] on a [`SparsePencil`] (the k lowest
//! modes of a large sparse pencil), [`count_below`] / [`count_below_sparse`] (how many modes lie
//! below a shift, certified by Sylvester's inertia), [`FreeResponse`] (the motion from initial
//! conditions), [`quadratic_modes`] (damped and gyroscopic modes, det(s²A + sC + B) = 0, each
//! eigenvalue with its backward error, condition and bound; module [`quadratic`]).
//!
//! # Contract
//!
//! - **Sign convention.** det(λA + B) = 0 (8.89): an oscillatory mode has λ = −ω² < 0. Modes
//!   are ordered by ω² = −λ ascending (unstable, rigid-body, oscillatory, infinite).
//! - **Accuracy.** Every mode carries a bound on |ω²_computed − ω²_exact| for the stored A and
//!   B, from its backward error and condition (first order), a priori (values only), or from an
//!   extended-precision residual (refined modes, a rigorous residual / Kato–Temple bound); every
//!   pair its backward error; every solve its A-orthogonality error and a Sturm check that no
//!   mode below a shift was missed or invented ([`AccuracyReport`], [`SparseAccuracyReport`]).
//!   Sketched residuals ([`Residuals::Sketched`]) are upper bounds that fail with probability
//!   at most [`certify::FAILURE_PROBABILITY`] each.
//! - **Stiff and graded problems.** With [`Refinement::Auto`] the modes whose bound guarantees
//!   fewer than 8 digits ([`dense::AUTO_REFINE_RELATIVE_BOUND`]) are refined from the lowest up
//!   (at most max(64, n/16)) by Newton steps with double-double residuals and get a residual
//!   bound; where the reduction cannot resolve the bottom at all, the low modes are first taken
//!   from the reversed pencil A x = μ(B + sA)x. Tested on graded chains with ratios up to 1e12
//!   against 60-digit references (tools/modal_reference.py) and on random chains and trees with
//!   masses over 8 decades and stiffnesses over 12 against a double-double inertia reference.
//! - **Classification** ([`ModeKind`], [`classify`]): a mode is zero when |ω²| is within the
//!   data resolution of A and B (or its interval contains zero within 1e3 of it), oscillatory or
//!   unstable when its interval excludes zero, undecided otherwise; a B with a Cholesky factor
//!   makes every mode oscillatory (Sylvester). Repeated frequencies are grouped ([`ModeGroup`]), each
//!   group's shapes an A-orthonormal basis of its eigenspace.
//! - **Semidefinite A**: massless directions are condensed out and reported as infinite modes;
//!   an indefinite A is an error naming the failed Cholesky pivot.
//!
//! # Pipeline
//!
//! Dense ([`dense`]): Cholesky A = LLᵀ (or, for a semidefinite A, static condensation of the
//! massless directions), the reduction C = L⁻¹BL⁻ᵀ, the eigen-decomposition of C (blocked
//! tridiagonalization and tridiagonal divide and conquer; values only by a root-free QL
//! iteration), X = L⁻ᵀY; then the accuracy report ([`certify`]), refinement of weakly bounded
//! modes, the Sturm check, classification and grouping ([`spectrum`]). Sparse ([`sparse`]):
//! shift-invert block Lanczos on a sparse Cholesky factor of B − σA, Rayleigh–Ritz on the
//! pencil, double-double residuals and quadratic bounds, certified by the inertia of B − τA at a
//! shift τ in a gap above the k-th mode; small pencils go to the dense solver.
//!
//! # Layout
//!
//! Modules depend one way, checked by tools/module_graph.py: [`error`], [`problem`],
//! [`tuning`] and the machine helpers (`runtime`) at the bottom; the dense kernels
//! (`linalg`: Cholesky, reduction, symmetric eigensolver) and double-double arithmetic (`dd`)
//! above them; [`spectrum`] (modes, classification, clusters); [`certify`] (the accuracy
//! report, sketches, inertia counts, the bottom certificate); `refine` (Newton steps, bordered
//! systems, projected corrections); then the solvers [`dense`] and [`sparse`] (which uses the
//! dense solver for small pencils and Rayleigh–Ritz) and [`response`]; [`quadratic`] (the
//! quadratic eigenproblem, on faer's QZ) uses only the error type, the norms and the
//! power-of-two scaling of [`dense`]. The test problems with
//! known spectra are in `testing` (cargo feature `testing`); the tuning choices are
//! [`Tuning::DEFAULT`].

pub mod certify;
mod dd;
pub mod dense;
pub mod error;
#[doc(hidden)]
pub mod linalg;
pub mod problem;
pub mod quadratic;
mod refine;
pub mod response;
mod runtime;
pub mod sparse;
pub mod spectrum;
#[cfg(feature = "testing")]
pub mod testing;
pub mod tuning;

pub use certify::{
    AccuracyReport, BoundKind, InertiaCheck, InertiaCount, Residuals, count_below, proven_definite_with_margin,
};
pub use dense::{Method, ModalSolution, Refinement, Selection, SolveOptions, SolveTimings, solve};
pub use error::ModalError;
pub use faer;
pub use problem::PencilProblem;
pub use quadratic::{
    QuadraticBoundKind, QuadraticEigenvalue, QuadraticMode, QuadraticModeKind, QuadraticModes, QuadraticOptions,
    quadratic_modes,
};
pub use response::{CoordinateLaw, FreeResponse, InitialFit, ModalCoordinate};
pub use runtime::scratch::release as release_scratch;
pub use sparse::{
    MatrixMarket, SparseAccuracyReport, SparseInertiaCount, SparseModalSolution, SparsePencil, SparseSolveOptions,
    SparseSolveTimings, check_every_coordinate_used, count_below_sparse, parse_matrix_market, read_matrix_market,
    solve_sparse,
};
pub use spectrum::{Mode, ModeGroup, ModeKind, classify};
pub use tuning::Tuning;
