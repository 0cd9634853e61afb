//! The error type of the modal crate.

use thiserror::Error;

/// What was wrong with which matrix input, or which step of a solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModalError {
    /// A matrix is not square, or A and B differ in size.
    #[error("{what} has shape {rows}×{cols}, expected {expected}×{expected}")]
    BadShape {
        /// Which matrix.
        what: &'static str,
        /// Its row count.
        rows: usize,
        /// Its column count.
        cols: usize,
        /// The size it should have.
        expected: usize,
    },
    /// An entry is NaN or infinite.
    #[error("{what}[{row}, {col}] is not finite: {value}")]
    NonFinite {
        /// Which matrix.
        what: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix that must be symmetric is not, beyond the stated tolerance.
    #[error(
        "{what} is not symmetric: |{what}[{row}, {col}] − {what}[{col}, {row}]| = {difference:.3e} > {tolerance:.3e}"
    )]
    NotSymmetric {
        /// Which matrix.
        what: &'static str,
        /// Row of the worst entry.
        row: usize,
        /// Column of the worst entry.
        col: usize,
        /// The asymmetry found.
        difference: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
    },
    /// The mass matrix A has a negative eigenvalue (it is indefinite, not merely semidefinite).
    #[error(
        "mass matrix A is indefinite: Cholesky pivot {pivot} failed and A has eigenvalue {min_eigenvalue:.3e} < −{tolerance:.3e}"
    )]
    IndefiniteMass {
        /// Index of the first Cholesky pivot that was not positive.
        pivot: usize,
        /// The most negative eigenvalue of A.
        min_eigenvalue: f64,
        /// The tolerance n·u·‖A‖ below which a negative eigenvalue counts as rounding of zero.
        tolerance: f64,
    },
    /// A is singular and B is singular on the null space of A, so the massless directions cannot
    /// be condensed out. Either det(λA + B) vanishes for every λ (a singular pencil), or the
    /// pencil is regular with infinite eigenvalues of higher index (A = [[1, 0], [0, 0]],
    /// B = [[0, 1], [1, 0]]: det(λA + B) = −1), which this solver does not reduce.
    #[error(
        "the massless directions cannot be condensed: B restricted to the {nullity}-dimensional null space of A has a zero pivot at {pivot} (the pencil is singular, or has infinite eigenvalues of higher index)"
    )]
    SingularPencil {
        /// Dimension of the null space of A.
        nullity: usize,
        /// Index (within the null space) of the failing pivot.
        pivot: usize,
    },
    /// More modes were requested than the pencil has.
    #[error("{requested} modes requested but the pencil has only {available}")]
    TooManyModes {
        /// Number requested.
        requested: usize,
        /// Number of finite modes available.
        available: usize,
    },
    /// An interval [lower, upper] of ω² was empty, reversed or not finite.
    #[error("interval [{lower}, {upper}] of ω² is not a finite interval with lower ≤ upper")]
    BadInterval {
        /// Lower end.
        lower: f64,
        /// Upper end.
        upper: f64,
    },
    /// A shift for the inertia count was not finite.
    #[error("shift {0} is not finite")]
    BadShift(f64),
    /// A convergence tolerance outside (0, 1) (or not finite).
    #[error("tolerance {0} must be finite and in (0, 1)")]
    BadTolerance(f64),
    /// A vector argument has the wrong length.
    #[error("{what} has length {len}, expected {expected}")]
    BadLength {
        /// Which vector.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length it should have.
        expected: usize,
    },
    /// An entry of a vector (or a scalar argument, index 0) is NaN or infinite.
    #[error("{what}[{index}] is not finite: {value}")]
    NonFiniteValue {
        /// Which vector or scalar.
        what: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The free response needs every mode with its shape (`Selection::All`, vectors on), of a
    /// solution of the same pencil.
    #[error(
        "the free response needs all {dim} modes with shapes; the solution has {modes} modes and {shapes} shape columns of length {shape_len}"
    )]
    IncompleteSolution {
        /// Order n of the pencil.
        dim: usize,
        /// Number of modes in the solution.
        modes: usize,
        /// Number of mode-shape columns (0 when values only).
        shapes: usize,
        /// Length of each shape column (0 when values only).
        shape_len: usize,
    },
    /// The free response at time t does not fit in a double: an unstable mode grew past f64::MAX.
    #[error("the free response overflows at t = {t}: unstable mode {mode} grows as cosh({exponent:.3e})")]
    ResponseOverflow {
        /// The requested time (s).
        t: f64,
        /// Index of the overflowing mode.
        mode: usize,
        /// Its exponent γ|t|.
        exponent: f64,
    },
    /// A sparse entry's index lies outside the n×n matrix.
    #[error("{what} has an entry at ({row}, {col}) outside its {dim}×{dim} shape")]
    IndexOutOfRange {
        /// Which matrix.
        what: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The order n.
        dim: usize,
    },
    /// No shift σ made B − σA positive definite (sparse solver): A is not positive semidefinite,
    /// or the pencil has modes far below the shifts tried; pass a shift below the lowest ω².
    #[error(
        "B − σA is not positive definite for any shift tried down to σ = {lowest_shift:.3e} (last failed pivot {pivot})"
    )]
    NoDefiniteShift {
        /// The lowest shift tried (rad²/s²).
        lowest_shift: f64,
        /// The Cholesky pivot that failed at that shift.
        pivot: usize,
    },
    /// The mass matrix gave a Lanczos vector a non-positive A-norm: A is not positive semidefinite.
    #[error("mass matrix A is not positive semidefinite: a Lanczos vector has xᵀAx = {value:.3e}")]
    MassNotSemidefinite {
        /// The value of xᵀAx found.
        value: f64,
    },
    /// The sparse Lanczos iteration did not converge all wanted pairs.
    #[error("Lanczos converged {converged} of {wanted} wanted pairs in {restarts} restarts")]
    LanczosNoConvergence {
        /// Pairs converged.
        converged: usize,
        /// Pairs wanted.
        wanted: usize,
        /// Restarts made.
        restarts: usize,
    },
    /// A sparse factorization failed for a reason other than a pivot (memory, index overflow).
    #[error("sparse factorization of {what} failed: {detail}")]
    Factorization {
        /// Which matrix.
        what: &'static str,
        /// faer's description.
        detail: String,
    },
    /// A Matrix Market file could not be read.
    #[error("cannot read Matrix Market file {path}: {detail}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        detail: String,
    },
    /// A Matrix Market file is malformed.
    #[error("Matrix Market line {line}: {detail}")]
    MatrixMarket {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        detail: String,
    },
    /// A coordinate has no entry in A or in B: its row of λA + B vanishes for every λ, so
    /// det(λA + B) ≡ 0 (a singular pencil). Checked before anything of the pencil's order is
    /// allocated, so a file declaring a huge order with few entries is refused at once.
    #[error("coordinate {index} of the order-{order} pencil has no entry in A or B: det(λA + B) vanishes for every λ")]
    EmptyCoordinate {
        /// The first coordinate without an entry.
        index: usize,
        /// The declared order n.
        order: usize,
    },
    /// The pencil's entries span more binary orders than double precision holds once scaled
    /// to a common range, or a result (an ω², a bound) lies outside the range of doubles.
    #[error("{what} is outside the range of double precision: {detail}")]
    OutOfRange {
        /// The entry or result concerned.
        what: String,
        /// Its value and the range it would need.
        detail: String,
    },
    /// det(s²A + sC + B) vanishes for every s (a singular quadratic polynomial: A, C and B share
    /// a null vector, or all three vanish), so its eigenvalues are not defined.
    #[error("det(s²A + sC + B) vanishes for every s: the order-{order} quadratic polynomial is singular")]
    SingularQuadratic {
        /// The order n.
        order: usize,
    },
    /// faer's QZ iteration did not converge on the linearization of a quadratic eigenproblem.
    #[error("the QZ iteration did not converge on the {n}×{n} linearization")]
    NoConvergenceQz {
        /// Order 2n of the linearization.
        n: usize,
    },
    /// faer's eigensolver did not converge.
    #[error("the symmetric eigensolver did not converge on the reduced {n}×{n} matrix")]
    NoConvergence {
        /// Order of the reduced problem.
        n: usize,
    },
}
