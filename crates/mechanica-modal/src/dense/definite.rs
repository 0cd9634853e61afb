//! The finite spectrum of a definite pencil from the Cholesky factor L of A: the reduction
//! C = L⁻¹BL⁻ᵀ, the eigen-decomposition of C (or its values and tridiagonal form), the selection
//! and the back-transformation X = L⁻ᵀY.

use crate::certify::a_priori::APrioriModel;
use crate::dense::options::Selection;
use crate::dense::solution::SolveTimings;
use crate::error::ModalError;
use crate::linalg::eigen::{
    OnTridiagonal, TridiagonalForm, symmetric_eigen_returning_input, symmetric_values_keeping_form,
};
use crate::linalg::reduce::{back_transform_into, reduce_owned};
use faer::{Mat, MatRef, Par};
use std::time::Instant;

/// Finite spectrum of a definite pencil: all ω² ascending, the selected index range, and
/// the selected eigenvectors (A-orthonormal) when asked for.
pub(crate) struct Definite {
    pub omega_sq: Vec<f64>,
    pub first: usize,
    pub end: usize,
    pub vectors: Option<Mat<f64>>,
    /// All n orthonormal eigenvectors Y of the reduced matrix C (when vectors were computed),
    /// for refinement without a new factorization ([`crate::refine::ReducedSpectrum`]).
    pub reduced: Option<Mat<f64>>,
    /// Values only: C's tridiagonal form, from which [`crate::values_only`] forms the vectors
    /// of the few modes whose a-priori bound is too weak.
    pub form: Option<TridiagonalForm>,
    /// Values only: the a-priori error model, when already computed.
    pub a_priori: Option<APrioriModel>,
    /// The reduction's time (as `factor`) and the eigensolver's (as `eigen`).
    pub timings: SolveTimings,
    /// Error estimates of all n ω² (not bounds) when some came from the reversed pencil
    /// (`crate::dense::reversed`): refinement forms its clusters from them, since the
    /// first-order bounds of such modes are normwise and would join modes known apart.
    pub estimates: Option<Vec<f64>>,
}

pub(crate) fn select(omega_sq: &[f64], selection: Selection) -> Result<(usize, usize), ModalError> {
    let n = omega_sq.len();
    match selection {
        Selection::All => Ok((0, n)),
        Selection::Lowest(k) if k <= n => Ok((0, k)),
        Selection::Lowest(k) => Err(ModalError::TooManyModes {
            requested: k,
            available: n,
        }),
        Selection::Interval { lower, upper } => {
            let first = omega_sq.partition_point(|&w| w < lower);
            let end = omega_sq.partition_point(|&w| w <= upper);
            Ok((first, end.max(first)))
        }
    }
}

/// Solves the definite pencil with Cholesky factor `l` of A.
pub(crate) fn solve_definite(
    l: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    selection: Selection,
    vectors: bool,
    par: Par,
) -> Result<Definite, ModalError> {
    solve_definite_owned(l, b.to_owned(), selection, vectors, par, None)
}

/// [`solve_definite`] on a copy of B that the caller no longer needs (reduced in place).
pub(crate) fn solve_definite_owned(
    l: MatRef<'_, f64>,
    b: Mat<f64>,
    selection: Selection,
    vectors: bool,
    par: Par,
    on_tridiagonal: Option<OnTridiagonal<'_>>,
) -> Result<Definite, ModalError> {
    let n = b.nrows();
    if n == 0 {
        // faer's eigensolvers underflow a size computation at n = 0; never call them there.
        let (first, end) = select(&[], selection)?;
        return Ok(Definite {
            omega_sq: Vec::new(),
            first,
            end,
            vectors: vectors.then(|| Mat::zeros(0, 0)),
            reduced: None,
            form: None,
            a_priori: None,
            timings: SolveTimings::default(),
            estimates: None,
        });
    }
    let clock = Instant::now();
    let c = reduce_owned(l, b, par);
    let mut timings = SolveTimings {
        factor: clock.elapsed(),
        ..SolveTimings::default()
    };
    let clock = Instant::now();
    if !vectors {
        let (omega_sq, form) = symmetric_values_keeping_form(c, par, on_tridiagonal)?;
        let (first, end) = select(&omega_sq, selection)?;
        timings.eigen = clock.elapsed();
        return Ok(Definite {
            omega_sq,
            first,
            end,
            vectors: None,
            reduced: None,
            form: Some(form),
            a_priori: None,
            timings,
            estimates: None,
        });
    }
    let (eigen, mut spent) = symmetric_eigen_returning_input(c, true, par, on_tridiagonal)?;
    let omega_sq = eigen.values;
    let (first, end) = select(&omega_sq, selection)?;
    let (x, y) = match eigen.vectors {
        Some(y) => {
            // X = L⁻ᵀ Y(:, first..end), written into the reduced matrix's spent storage (each
            // thread copies and solves its own column chunk, so the copy runs on every thread).
            spent.truncate(n, end - first);
            back_transform_into(l, y.subcols(first, end - first), spent.as_mut(), par);
            (spent, y)
        }
        None => return Err(ModalError::NoConvergence { n }),
    };
    timings.eigen = clock.elapsed();
    Ok(Definite {
        omega_sq,
        first,
        end,
        vectors: Some(x),
        reduced: Some(y),
        form: None,
        a_priori: None,
        timings,
        estimates: None,
    })
}
