//! Damped and gyroscopic small oscillations: A δ̈ + C δ̇ + B δ = 0, δ = x e^{st}, solved as the
//! quadratic eigenproblem det(s²A + sC + B) = 0 with a certified accuracy for every eigenvalue
//! (docs/theory.md, "Quadratic eigenproblems (damped and gyroscopic modes)").
//!
//! A is the mass matrix (8.28), B the stiffness matrix (8.85), C any real matrix: the Rayleigh
//! dissipation matrix (FM 4.64, symmetric) plus a gyroscopic matrix (skew-symmetric, §8e). None
//! needs to be symmetric or definite, and A may be singular: its null directions give infinite
//! eigenvalues, reported as such.
//!
//! # Method
//!
//! 1. **Scaling** (Fan, Lin & Van Dooren 2004): s = γ s̃ and the coefficients multiplied by δ,
//!    Ã = γ²δA, C̃ = γδC, B̃ = δB with γ ≈ √(‖B‖/‖A‖), δ ≈ 1/max(‖B‖, γ‖C‖, γ²‖A‖), both rounded
//!    to powers of two, so the scaled problem is the stored one exactly and no norm, product or
//!    eigenvalue overflows for entries anywhere in the range of doubles.
//! 2. **Linearization** without inverting A: the first companion pencil
//!    λ[Ã 0; 0 I] + [C̃ B̃; −I 0], right eigenvectors [s̃x; x], left eigenvectors with y on top.
//! 3. **QZ** (faer's real generalized Schur decomposition and eigenvectors), eigenvalues as
//!    homogeneous pairs (α, β), s̃ = α/β: a singular A gives β = 0, not an overflow.
//! 4. **Certification** of each eigenvalue on the stored problem ([`QuadraticEigenvalue`]):
//!    Tisseur's backward error η of (s, x), the condition κ from the left and right
//!    eigenvectors, and the first-order bound |s − s_exact| ≤ η κ |s|; eigenvalues whose bounds
//!    overlap (a double root, critical damping) get a cluster bound instead.
//! 5. **Modes**: conjugate pairs, real pairs with parallel shapes, single real roots and
//!    infinite eigenvalues, each classified with its bound ([`QuadraticModeKind`]).

mod certify;
mod classify;
mod linearize;
mod scaling;
#[cfg(test)]
mod tests;

use crate::error::ModalError;
use faer::{Mat, MatRef, c64};

/// Options of [`quadratic_modes`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct QuadraticOptions {
    /// Return the right eigenvector x of every eigenvalue ([`QuadraticModes::vectors`]).
    pub vectors: bool,
}

/// How an eigenvalue's [`QuadraticEigenvalue::error_bound`] was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum QuadraticBoundKind {
    /// η κ |s| (Tisseur 2000): first order in η. It is the leading term of the error of a simple
    /// eigenvalue and holds as long as the bound is small against the distance to the other
    /// eigenvalues, which is checked (otherwise the eigenvalue gets a cluster bound).
    FirstOrder,
    /// The eigenvalue's first-order disk overlaps another's (a multiple or nearly multiple root,
    /// where first-order theory understates the error): the bound is the distance to the
    /// farthest member of the cluster plus the largest first-order bound in it.
    Cluster,
}

/// One eigenvalue s of det(s²A + sC + B) = 0 with its accuracy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticEigenvalue {
    /// s = σ + iω (1/s, rad/s); None for an infinite eigenvalue.
    pub s: Option<c64>,
    /// Tisseur's backward error η = ‖(s²A + sC + B)x‖ / ((|s|²‖A‖ + |s|‖C‖ + ‖B‖)‖x‖) (Frobenius
    /// norms), plus a bound on the rounding of its own evaluation; in homogeneous form for an
    /// infinite eigenvalue.
    pub backward_error: f64,
    /// Tisseur's relative condition κ = (|s|²‖A‖ + |s|‖C‖ + ‖B‖)‖y‖‖x‖ / (|s| |y*(2sA + C)x|);
    /// None where it is not defined (s = 0 within its bound, an infinite eigenvalue, or
    /// y*(2sA + C)x = 0).
    pub condition: Option<f64>,
    /// Bound on |s_computed − s_exact| for the stored A, C, B (see `bound_kind`); for an infinite
    /// eigenvalue a bound on |1/s| of the exact eigenvalue, which it shows to be 0 within.
    pub error_bound: f64,
    /// First-order or cluster bound.
    pub bound_kind: QuadraticBoundKind,
}

/// What a mode (one or two eigenvalues) is physically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum QuadraticModeKind {
    /// A conjugate pair s = σ ± iω with σ < 0 and ω ≠ 0 beyond their bounds: a decaying
    /// oscillation.
    Underdamped,
    /// Two real negative roots, separated by their bounds: a decaying motion without
    /// oscillation.
    Overdamped,
    /// Decaying, but the bounds cannot tell a double real root from a complex pair or two close
    /// real roots (critical damping within the accuracy).
    Critical,
    /// s = 0 within its bound: a rigid-body or neutrally stable direction.
    Rigid,
    /// Re s > its bound: the motion grows.
    Unstable,
    /// Re s = 0 within its bound and ω ≠ 0: an undamped oscillation (conservative or gyroscopic).
    Neutral,
    /// A single real negative root (first-order decay, as of a damper on a massless coordinate).
    Relaxation,
    /// An infinite eigenvalue: a massless direction (A x = 0).
    Infinite,
    /// The bound contains points of more than one kind (σ and ω both within their bounds of zero
    /// while s is not): the accuracy does not decide.
    Undecided,
}

/// A mode: one or two eigenvalues of [`QuadraticModes::eigenvalues`].
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticMode {
    /// Its kind.
    pub kind: QuadraticModeKind,
    /// Indices into [`QuadraticModes::eigenvalues`]: two for a conjugate pair (Im s > 0 first) or
    /// a pair of real roots, one for a single real root or an infinite eigenvalue.
    pub eigenvalues: Vec<usize>,
    /// Undamped natural frequency ω_n = √|s₁s₂| (= |s| for a conjugate pair or a single root,
    /// rad/s); None for an infinite eigenvalue.
    pub natural_frequency: Option<f64>,
    /// Damped frequency |Im s| (rad/s); 0 for real roots and infinite eigenvalues.
    pub damped_frequency: f64,
    /// Damping ratio ζ = −(s₁ + s₂)/(2ω_n) (= −σ/|s| for a conjugate pair or a single root); None
    /// when ω_n = 0 or infinite.
    pub damping_ratio: Option<f64>,
}

/// The solution of det(s²A + sC + B) = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticModes {
    /// All 2n eigenvalues, in the order of the modes.
    pub eigenvalues: Vec<QuadraticEigenvalue>,
    /// The modes, by natural frequency ascending, infinite ones last.
    pub modes: Vec<QuadraticMode>,
    /// With [`QuadraticOptions::vectors`]: the n × 2n right eigenvectors, column k that of
    /// eigenvalue k, of unit 2-norm.
    pub vectors: Option<Mat<c64>>,
    /// The largest backward error of any eigenvalue.
    pub max_backward_error: f64,
    /// The exponent g of the frequency scale γ = 2^g (s = γ s̃).
    pub frequency_scale_exponent: i32,
    /// The exponent d of the coefficient scale δ = 2^d.
    pub coefficient_scale_exponent: i32,
}

/// The eigenvalues, bounds and modes of A δ̈ + C δ̇ + B δ = 0 (see the module docs). A, C, B
/// must be n × n with finite entries ([`ModalError::BadShape`], [`ModalError::NonFinite`]);
/// coefficients whose entries span more binary orders than double precision holds once scaled
/// are [`ModalError::OutOfRange`], a polynomial with det ≡ 0 is
/// [`ModalError::SingularQuadratic`], and a result outside the range of doubles is
/// [`ModalError::OutOfRange`].
pub fn quadratic_modes(
    a: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    options: &QuadraticOptions,
) -> Result<QuadraticModes, ModalError> {
    let scaled = scaling::ScaledProblem::new(a, c, b)?;
    let pairs = linearize::solve_companion(&scaled)?;
    let certified = certify::certify(&scaled, pairs)?;
    classify::assemble(&scaled, certified, options)
}
