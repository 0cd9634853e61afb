//! Whether the mass matrix A is positive definite, proven: the dense solve reduces with the
//! Cholesky factor of A only where A is proven definite, since every bound it reports rests on
//! ‖L⁻¹‖ being that of the exact A. A factorization that passes its pivot test does not prove
//! it: an A of rank n − 1 whose null vector is not a coordinate factors with a last pivot of
//! rounding size, and its infinite eigenvalue came out as a finite mode (4.5e15 ± 1.1e27 on
//! seven coordinates) whose interval did not contain it.
//!
//! A diagonal A is its own exact factorization. A dense A is proven by the scaled and shifted
//! Cholesky test ([`crate::certify::inertia`]), its shift taken from the spread of the factor
//! already computed, and where that cannot decide (λ_min of the unit-diagonal A below a few
//! hundred units of rounding) by the same test in double-double arithmetic
//! ([`crate::certify::extended_definiteness`]) up to [`MASS_PROOF_UP_TO`] coordinates. An A
//! that fails both is singular or within 1e-24 of it: its massless directions are condensed out
//! as for a failed pivot. An A whose pivot test failed but which the double-double test proves
//! definite is refused ([`ModalError::OutOfRange`]): condensing would call its finite top mode
//! infinite. Above that order a dense A that passes the pivot test is reduced with its factor,
//! unproven (docs/limits.md).

use crate::certify::extended_definiteness::proven_definite_extended;
use crate::certify::inertia::{factor_spread, proven_definite_with_spread_guess};
use crate::dense::condense::{MassSpectrum, mass_spectrum};
use crate::error::ModalError;
use crate::linalg::reduce::{Cholesky, is_diagonal};
use crate::runtime::scratch;
use faer::{Mat, MatRef, Par};

/// How the solve treats A.
pub(crate) enum MassFactor {
    /// A is positive definite (proven, or, above [`MASS_PROOF_UP_TO`] coordinates, passing the
    /// pivot test): its Cholesky factor.
    Definite(Mat<f64>),
    /// A has massless directions: its eigen-decomposition, for the condensation.
    Massless(MassSpectrum),
}

/// Decides from the Cholesky factorization of A (`cholesky`, of the lower triangle of `a`)
/// whether the solve reduces with the factor or condenses massless directions first.
/// [`ModalError::IndefiniteMass`] when A has an eigenvalue below −2n·u·max|a|;
/// [`ModalError::OutOfRange`] when a pivot is negligible in double precision although A is
/// proven definite in double-double: its highest eigenvalue is finite but beyond what a
/// reduction in double resolves, and condensing it would report it infinite.
pub(crate) fn mass_factor(a: MatRef<'_, f64>, cholesky: Cholesky, par: Par) -> Result<MassFactor, ModalError> {
    let l = match cholesky {
        Cholesky::Failed { pivot } => {
            if !is_diagonal(a) && proven_definite_extended(a, MASS_PROOF_UP_TO) {
                // Definite, yet singular to double precision.
                return Err(beyond_double_precision(pivot));
            }
            return mass_spectrum(a, pivot, par).map(MassFactor::Massless);
        }
        Cholesky::Factor(l) => l,
    };
    let proven = |l: &Mat<f64>| {
        proven_definite_with_spread_guess(a, 0.0, scaled_spread(a, l.as_ref()), par)
            || proven_definite_extended(a, MASS_PROOF_UP_TO)
    };
    if is_diagonal(a) || a.nrows() > MASS_PROOF_UP_TO || proven(&l) {
        return Ok(MassFactor::Definite(l));
    }
    let weakest = weakest_pivot(a, l.as_ref());
    scratch::give_back(l);
    mass_spectrum(a, weakest, par).map(MassFactor::Massless)
}

/// The largest order at which a dense mass matrix is proven definite before it is reduced
/// (the double-double test costs about 20n³/3 flops: 0.1 s at 256). Above it no proof is made:
/// a failed one would leave no better choice than the factor, since taking the directions of
/// small scaled eigenvalues as massless calls a graded definite A's top mode infinite (a
/// hanging planar chain of 300–450 point masses over four decades).
pub(crate) const MASS_PROOF_UP_TO: usize = 256;

/// The refusal of an A that is definite but singular to working precision.
fn beyond_double_precision(pivot: usize) -> ModalError {
    ModalError::OutOfRange {
        what: "mass matrix A".to_string(),
        detail: format!(
            "it is positive definite (proven in double-double arithmetic) but its Cholesky pivot {pivot} is \
             negligible in double precision, so its highest mode can be neither reduced nor condensed"
        ),
    }
}

/// The spread ρ of diag(A)^{-1/2}|L| ([`factor_spread`]): that of the proof's shifted factor,
/// nearly, so its shift is right the first time.
fn scaled_spread(a: MatRef<'_, f64>, l: MatRef<'_, f64>) -> f64 {
    let weights: Vec<f64> = (0..a.nrows()).map(|i| 1.0 / a[(i, i)].sqrt()).collect();
    factor_spread(l, &weights)
}

/// The index of the smallest pivot relative to its diagonal entry, l_ii²/a_ii.
fn weakest_pivot(a: MatRef<'_, f64>, l: MatRef<'_, f64>) -> usize {
    (0..a.nrows())
        .min_by(|&i, &j| (l[(i, i)] * l[(i, i)] / a[(i, i)]).total_cmp(&(l[(j, j)] * l[(j, j)] / a[(j, j)])))
        .unwrap_or(0)
}
