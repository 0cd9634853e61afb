//! The definite pencil in which refinement corrects a mode and measures its residual: (B, A)
//! itself through the Cholesky factor of A, or the statically condensed pencil (S, A₁).

use crate::linalg::norms::euclidean_norm;
use crate::linalg::reduce::LowerFactor;
use crate::refine::condensed::Condensation;
use crate::refine::correction::ReducedCorrection;
use faer::{Mat, Par};

/// The definite pencil in which refinement corrects a mode and measures its residual.
#[derive(Clone, Copy)]
pub(crate) enum Metric<'a> {
    /// A = LLᵀ positive definite (L lower): corrections L⁻ᵀKL⁻¹r, residuals in the A⁻¹-norm.
    Cholesky(LowerFactor<'a>),
    /// A diagonal with exactly massless coordinates, condensed statically: corrections and
    /// residuals of the condensed pencil (S, A₁) ([`Condensation`]).
    Condensed(&'a Condensation),
}

impl Metric<'_> {
    /// δX ≈ (B − ρA)⁻¹R with K, the reduced correction, applied on the definite pencil.
    pub(crate) fn correction(&self, r: Mat<f64>, rho: f64, reduced: &mut dyn ReducedCorrection) -> Mat<f64> {
        match self {
            Self::Cholesky(l) => {
                let mut w = r;
                l.solve(w.as_mut(), Par::Seq);
                let mut delta = reduced.apply(w, rho);
                l.solve_transposed(delta.as_mut(), Par::Seq);
                delta
            }
            Self::Condensed(c) => c.correction(&r, rho, reduced),
        }
    }

    /// The definite pencil's residual for a residual r of (B, A), and its inverse-mass norm.
    pub(crate) fn definite_residual(&self, r: Vec<f64>) -> (Vec<f64>, f64) {
        match self {
            Self::Cholesky(l) => {
                let mut y = Mat::from_fn(r.len(), 1, |i, _| r[i]);
                l.solve(y.as_mut(), Par::Seq);
                let norm = euclidean_norm(y.col_as_slice(0));
                (r, norm)
            }
            Self::Condensed(c) => {
                let (s, _, r0_norm) = c.condensed_residual(&r);
                let norm = c.inverse_mass_norm(&s, r0_norm);
                (s, norm)
            }
        }
    }
}
