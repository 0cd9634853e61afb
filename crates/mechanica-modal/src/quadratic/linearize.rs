//! The first companion linearization of the scaled problem and its QZ eigen-decomposition.
//!
//! L(λ) = λ X + Y with X = [Ã 0; 0 I], Y = [C̃ B̃; −I 0]: L(λ)[λx; x] = 0 exactly when
//! P̃(λ)x = 0, and a left eigenvector [w₁; w₂] of L has w₁ = y with y*P̃(λ) = 0 (w₁ = 0 would
//! force w₂ = 0). A is never inverted: a singular Ã makes X singular and gives eigenvalues with
//! β = 0. faer's real QZ returns each eigenvalue as (α, β), λ = α/β, a complex conjugate pair
//! as two columns (real and imaginary parts) of the eigenvector matrices; its left vector u of a
//! complex eigenvalue satisfies uᵀ(−Y) = λ uᵀX, so y = ū (checked by the tests).

use super::scaling::ScaledProblem;
use crate::error::ModalError;
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::ComputeEigenvectors;
use faer::linalg::gevd::{gevd_real, gevd_scratch};
use faer::linalg::temp_mat_scratch;
use faer::{Mat, c64};

/// One eigenvalue of the scaled problem (the one with Im > 0 of a conjugate pair) with its
/// right and left eigenvectors.
pub(super) struct Eigenpair {
    /// Homogeneous coordinates, |a|² + b² = 1, b ≥ 0: s̃ = a/b (infinite for b = 0).
    pub a: c64,
    pub b: f64,
    /// Whether the conjugate (ā, b) with the conjugate vectors is also an eigenvalue.
    pub conjugate_pair: bool,
    /// Right eigenvector x, P̃ x = 0 (length n).
    pub x: Vec<c64>,
    /// Left eigenvector y, y* P̃ = 0 (length n).
    pub y: Vec<c64>,
}

/// The eigenvalues of the companion pencil of `p`, one per conjugate pair.
pub(super) fn solve_companion(p: &ScaledProblem) -> Result<Vec<Eigenpair>, ModalError> {
    let n = p.order();
    let m = 2 * n;
    if n == 0 {
        return Ok(Vec::new());
    }
    // −Y z = λ X z.
    let mut lhs = Mat::from_fn(m, m, |i, j| match (i < n, j < n) {
        (true, true) => -p.c[(i, j)],
        (true, false) => -p.b[(i, j - n)],
        (false, true) => f64::from(u8::from(i - n == j)),
        (false, false) => 0.0,
    });
    let mut rhs = Mat::from_fn(m, m, |i, j| match (i < n, j < n) {
        (true, true) => p.a[(i, j)],
        (false, false) => f64::from(u8::from(i == j)),
        _ => 0.0,
    });
    let scale = lhs.norm_l2().max(rhs.norm_l2());
    let (mut alpha_re, mut alpha_im, mut beta) = (Diag::<f64>::zeros(m), Diag::<f64>::zeros(m), Diag::<f64>::zeros(m));
    let (mut left, mut right) = (Mat::<f64>::zeros(m, m), Mat::<f64>::zeros(m, m));
    let par = faer::get_global_parallelism();
    let yes = ComputeEigenvectors::Yes;
    // faer's estimate leaves out the temporaries of the eigenvector back-substitution (two
    // norm columns and a few right-hand sides of two columns each): added here.
    let scratch = gevd_scratch::<f64>(m, yes, yes, par, Default::default()).and(temp_mat_scratch::<f64>(m, 16));
    let mut memory = MemBuffer::try_new(scratch).map_err(|_| ModalError::Factorization {
        what: "the companion linearization",
        detail: format!("no memory for the QZ workspace of order {m}"),
    })?;
    gevd_real(
        lhs.as_mut(),
        rhs.as_mut(),
        alpha_re.as_mut(),
        alpha_im.as_mut(),
        beta.as_mut(),
        Some(left.as_mut()),
        Some(right.as_mut()),
        par,
        MemStack::new(&mut memory),
        Default::default(),
    )
    .map_err(|_| ModalError::NoConvergenceQz { n: m })?;
    let values = Values {
        re: alpha_re.column_vector().iter().copied().collect(),
        im: alpha_im.column_vector().iter().copied().collect(),
        beta: beta.column_vector().iter().copied().collect(),
    };
    let mut pairs = collect_eigenpairs(n, &values, &left, &right, scale)?;
    for pair in &mut pairs {
        let usable = |v: &[c64]| {
            v.iter().all(|z| z.re.is_finite() && z.im.is_finite()) && v.iter().any(|z| *z != c64::new(0.0, 0.0))
        };
        if !(usable(&pair.x) && usable(&pair.y)) {
            singular_vectors(p, pair)?;
        }
    }
    Ok(pairs)
}

/// x and y from the smallest singular triple of P̃(a, b), where faer's back-substitution gave
/// no usable vectors (it returns NaN for some infinite eigenvalues of higher index).
fn singular_vectors(p: &ScaledProblem, pair: &mut Eigenpair) -> Result<(), ModalError> {
    let n = p.order();
    let (a, b) = (pair.a, pair.b);
    let poly = Mat::from_fn(n, n, |i, j| {
        a * a * p.a[(i, j)] + a * b * p.c[(i, j)] + p.b[(i, j)] * (b * b)
    });
    let svd = poly.svd().map_err(|_| ModalError::NoConvergenceQz { n: 2 * n })?;
    let sigma = svd.S().column_vector();
    let smallest = (0..n).min_by(|&i, &j| sigma[i].re.total_cmp(&sigma[j].re)).unwrap_or(0);
    pair.x = (0..n).map(|r| svd.V()[(r, smallest)]).collect();
    pair.y = (0..n).map(|r| svd.U()[(r, smallest)]).collect();
    Ok(())
}

/// The (α, β) of the QZ decomposition.
struct Values {
    re: Vec<f64>,
    im: Vec<f64>,
    beta: Vec<f64>,
}

/// One [`Eigenpair`] per real eigenvalue and per conjugate pair of the linearization; an
/// (α, β) with both parts at rounding level of the pencil means det P̃ ≡ 0.
fn collect_eigenpairs(
    n: usize,
    values: &Values,
    left: &Mat<f64>,
    right: &Mat<f64>,
    scale: f64,
) -> Result<Vec<Eigenpair>, ModalError> {
    let m = 2 * n;
    let tiny = 2.0 * m as f64 * f64::EPSILON * scale;
    let mut pairs = Vec::with_capacity(m);
    let mut j = 0;
    while j < m {
        let (re, im, beta) = (values.re[j], values.im[j], values.beta[j]);
        if ![re, im, beta].iter().all(|v| v.is_finite()) {
            return Err(ModalError::NoConvergenceQz { n: m });
        }
        let alpha = c64::new(re, im);
        let size = alpha.norm().hypot(beta);
        if size <= tiny {
            return Err(ModalError::SingularQuadratic { order: n });
        }
        let pair = im != 0.0 && j + 1 < m;
        let column = |u: &Mat<f64>, r: usize| {
            if pair {
                c64::new(u[(r, j)], u[(r, j + 1)])
            } else {
                c64::new(u[(r, j)], 0.0)
            }
        };
        // Normalized homogeneous coordinates with b ≥ 0, Im a ≥ 0 for a pair.
        let sign = if beta < 0.0 { -1.0 } else { 1.0 };
        let (mut a, b) = (alpha * (sign / size), beta * sign / size);
        let flip = pair && a.im < 0.0;
        let conj = |z: c64| if flip { z.conj() } else { z };
        a = conj(a);
        let offset = if a.norm() >= b { 0 } else { n };
        pairs.push(Eigenpair {
            a,
            b,
            conjugate_pair: pair,
            x: (0..n).map(|r| conj(column(right, r + offset))).collect(),
            y: (0..n).map(|r| conj(column(left, r).conj())).collect(),
        });
        j += if pair { 2 } else { 1 };
    }
    Ok(pairs)
}
