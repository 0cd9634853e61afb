//! Small oscillations: A δ̈ + B δ = 0 and det(λA + B) = 0 (8.84–8.92), solved with faer,
//! with every result carrying its own accuracy report.
//!
//! This crate works on bare matrices; it needs no mechanism. Entry point: [`solve()`] on a
//! validated [`PencilProblem`]; [`count_below`] certifies how many modes lie below a shift.
//!
//! - **Sign convention.** det(λA + B) = 0 (8.89): an oscillatory mode has λ = −ω² < 0. Modes
//!   are ordered by ω² = −λ ascending (unstable, rigid-body, oscillatory, infinite).
//! - **Dense method** ([`solve()`]): Cholesky A = LLᵀ, the symmetric reduction C = L⁻¹BL⁻ᵀ in
//!   about n³ flops ([`reduce`], as LAPACK `dsygst`), the eigen-decomposition of C
//!   ([`symmetric_eigen`]: this crate's blocked tridiagonalization and tridiagonal divide and
//!   conquer, faer's blocked Householder application; values only by this crate's root-free
//!   QL/QR), X = L⁻ᵀY. faer's QZ (`generalized_eigen`) is not used: on this machine it loses accuracy
//!   and speed at a few hundred unknowns (see `examples/faer_facts.rs`).
//! - **Accuracy** ([`accuracy`]): per-pair backward error, ‖XᵀAX − I‖, a bound per eigenvalue
//!   and a Sturm check with every solve. The residuals are exact by default (5n²m flops);
//!   [`Residuals::Sketched`] bounds them from above with Gaussian sketches ([`sketch`]) at
//!   O(n²) cost, each bound failing with probability ≤ 1e-12. The Sturm check of an all-pairs
//!   solve certifies the bottom of the spectrum with a Cholesky factorization of B − sA
//!   (from n = 640 factored on idle core time while the eigenvectors are formed, module
//!   `idle_certificate`); subsets count with an LBLᵀ factorization at a shift in a gap next to
//!   the selection.
//! - **Classification** ([`ModeKind`]): zero when |ω²| is within its own error bound.
//!   Repeated frequencies are grouped ([`ModeGroup`]) with an A-orthonormal eigenspace basis.
//! - **Semidefinite A**: massless directions are condensed out and reported as infinite modes;
//!   an indefinite A is an error naming the failed Cholesky pivot.
//! - **Stiff problems**: the reduction is accurate only relative to the largest eigenvalue;
//!   [`Refinement::Auto`] refines every mode whose bound guarantees fewer than 8 digits by
//!   Newton steps with double-double residuals (`refine`), and replaces its bound by a
//!   gap-weighted residual bound. The Newton correction is applied through the reduced
//!   problem's computed eigen-decomposition (O(n²) per step); only when that stops contracting
//!   is the bordered matrix factored (LBLᵀ, n³/3). When A and B both have few nonzeros (banded
//!   or assembled matrices stored densely) each simple mode instead takes bordered steps on a
//!   sparse LU of B − ω₀²A, with its iterate in double-double, so that its certified bound is
//!   not limited by rounding the vector (down to u·ω²). Tested on graded chains with ratios up
//!   to 1e12 against 60-digit mpmath references (tools/modal_reference.py). A values-only solve forms the
//!   vectors of its weakly bounded modes only, by inverse iteration on the tridiagonal form
//!   (`values_only`), measures their bounds and refines them the same way.
//! - **Sparse** ([`solve_sparse`] on a [`SparsePencil`] from faer `SparseColMat`s, triplets or
//!   Matrix Market files): the k lowest modes by shift-invert block Lanczos on faer's sparse
//!   Cholesky, certified by the inertia of B − τA ([`count_below_sparse`]), with Rayleigh–Ritz
//!   refinement, double-double residuals and quadratic (Kato–Temple type) error bounds.
//! - **Free response** ([`FreeResponse`]): δ(t) = Σ q_k(t) x_k from δ(0), δ̇(0) (8.91), with
//!   zero (q + q̇t), unstable (cosh/sinh), repeated and massless (static) modes.

pub mod certify;
mod dd;
pub mod dense;
pub mod error;
#[doc(hidden)]
pub mod linalg;
pub mod problem;
mod refine;
pub mod response;
mod runtime;
pub mod sparse;
pub mod spectrum;
#[cfg(feature = "testing")]
pub mod testing;
pub mod tuning;

pub use certify::{AccuracyReport, BoundKind, InertiaCheck, InertiaCount, Residuals, count_below};
pub use dense::{Method, ModalSolution, Refinement, Selection, SolveOptions, SolveTimings, solve};
pub use error::ModalError;
pub use faer;
pub use problem::PencilProblem;
pub use response::{CoordinateLaw, FreeResponse, InitialFit, ModalCoordinate};
pub use runtime::scratch::release as release_scratch;
pub use sparse::{
    MatrixMarket, SparseAccuracyReport, SparseInertiaCount, SparseModalSolution, SparsePencil, SparseSolveOptions,
    SparseSolveTimings, count_below_sparse, parse_matrix_market, read_matrix_market, solve_sparse,
};
pub use spectrum::{Mode, ModeGroup, ModeKind, classify};
pub use tuning::Tuning;

// Old name; removed once the C layer uses the new one.
#[doc(hidden)]
pub type SparseOptions = SparseSolveOptions;
