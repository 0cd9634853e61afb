//! Rayleigh–Ritz on the span of the converged Ritz vectors for the original pencil (A, B): the
//! projected pencil solved densely, which makes the vectors A-orthonormal and gives each ω² as
//! a Rayleigh quotient.

use crate::dense::{Refinement, Selection, SolveOptions, solve};
use crate::error::ModalError;
use crate::problem::PencilProblem;
use crate::sparse::operator::{Mass, product, product_into};
use crate::sparse::pencil::mul;
use faer::{Mat, MatRef};

/// Rayleigh–Ritz on span(X) for the original pencil.
pub(crate) struct Refined {
    pub(crate) omega_sq: Vec<f64>,
    /// n × cols column-major, A-orthonormal.
    pub(crate) vectors: Vec<f64>,
}

/// Rayleigh–Ritz on span(X) (n × cols, column-major) for the pencil (A, B): the finite Ritz
/// pairs of the projected pencil, ω² ascending, the vectors A-orthonormal.
pub(crate) fn rayleigh_ritz(
    a: Mass<'_>,
    b: faer::sparse::SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    cols: usize,
) -> Result<Refined, ModalError> {
    let n = a.nrows();
    let mut ax = vec![0.0; n * cols];
    let mut bx = vec![0.0; n * cols];
    a.apply_block(&x[..n * cols], &mut ax);
    for c in 0..cols {
        mul(b, &x[n * c..n * (c + 1)], &mut bx[n * c..n * (c + 1)]);
    }
    let xm = MatRef::from_column_major_slice(x, n, cols);
    let pa = product(xm.transpose(), MatRef::from_column_major_slice(&ax, n, cols));
    let pb = product(xm.transpose(), MatRef::from_column_major_slice(&bx, n, cols));
    let sym = |m: &Mat<f64>| Mat::from_fn(cols, cols, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let projected = PencilProblem::new(sym(&pa).as_ref(), sym(&pb).as_ref())?;
    let sol = solve(
        &projected,
        &SolveOptions {
            selection: Selection::All,
            vectors: true,
            refinement: Refinement::Off,
            ..SolveOptions::default()
        },
    )?;
    let y = sol.vectors.ok_or(ModalError::NoConvergence { n: cols })?;
    let finite = sol.modes.iter().take_while(|m| m.omega_sq.is_finite()).count();
    let mut vectors = vec![0.0; n * finite];
    product_into(&mut vectors, xm, y.subcols(0, finite));
    Ok(Refined {
        omega_sq: sol.modes[..finite].iter().map(|m| m.omega_sq).collect(),
        vectors,
    })
}
