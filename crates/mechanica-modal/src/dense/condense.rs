//! Semidefinite mass matrices: static condensation of the massless directions.
//!
//! With QᵀAQ = diag(a) and the null space Q₀ of A (a_i ≤ 2n·u·max a), write x = Q₁z + Q₀w.
//! (For a dense A, Q = D⁻¹Q_H from the orthogonal eigenvectors Q_H of the unit-diagonal
//! H = D⁻¹AD⁻¹, D a diagonal of powers of two: a congruence, so the pencil keeps its
//! eigenvalues, and a graded A's massless directions are judged on H.) The pencil splits as [[B₁₁ − ω²A₁, B₁₀], [B₀₁, B₀₀]] [z; w] = 0 with A₁ = diag(a₁) > 0, so
//! w = −B₀₀⁻¹B₀₁z and (B₁₁ − B₁₀B₀₀⁻¹B₀₁) z = ω² A₁ z: a definite pencil of order n − r, plus r
//! infinite eigenvalues (λ = −∞) with eigenvectors Q₀ (the Fix–Heiberger reduction, SIAM J.
//! Numer. Anal. 9, 1972, in its simplest form). B₀₀ singular makes det(λA + B) ≡ 0.
//!
//! A diagonal A (lumped masses with massless coordinates, e.g. the rotations of a lumped beam
//! model) needs no eigen-decomposition: Q is the permutation that sorts its diagonal, so QᵀBQ is
//! a reordering of B and the lift Q₁z + Q₀w a scatter of rows. That replaces the O(n³) eigen-
//! decomposition of A and the 4n³ flops of QᵀBQ by O(n²), and the condensed pencil's A₁ is
//! diagonal again (the reduction then scales, [`crate::linalg::reduce`]).

use crate::error::ModalError;
use crate::linalg::eigen::symmetric_eigen;
use crate::linalg::powers_of_two::{exponent, times_power_of_two};
use crate::linalg::reduce::is_diagonal;
use crate::problem::PencilProblem;
use crate::refine::{Blocks, Condensation};
use faer::{Mat, MatRef, Par, Side};

/// A semidefinite pencil with its massless directions condensed out: the definite pencil
/// (S, A₁) of order n − r, the r infinite modes, and what maps the condensed modes back.
pub(crate) struct Condensed {
    /// The number r of massless directions (infinite modes).
    pub(crate) massless: usize,
    /// The condensed stiffness S = B₁₁ − B₁₀B₀₀⁻¹B₀₁, symmetrised.
    pub(crate) stiffness: Mat<f64>,
    /// Unit vectors spanning the null space of A: the infinite modes' shapes.
    pub(crate) infinite: Vec<Vec<f64>>,
    /// The number of negative eigenvalues of B₀₀, by which the inertia of B − sA exceeds the
    /// count of modes below s.
    pub(crate) stiffness_negatives: usize,
    /// The eigenvectors Q of A.
    basis: MassBasis,
    /// L₁ = diag(√a₁), G = B₀₀⁻¹B₀₁ and what refinement needs of the condensation.
    pub(crate) condensation: Condensation,
}

impl Condensed {
    /// Mode shapes x = Q₁z + Q₀w with w = −G z of the condensed mode shapes z.
    pub(crate) fn lift(&self, z: MatRef<'_, f64>) -> Mat<f64> {
        self.basis
            .combine(z, (&self.condensation.g * z).as_ref(), self.massless)
    }
}

/// A's eigenvalues (ascending) and eigenvectors, with the number of massless directions: the
/// eigenvalues at or below the tolerance (0 for a diagonal A, whose entries are exact data;
/// 2n·u·max|a| for a dense A, the rounding of its computed eigenvalues).
pub(crate) struct MassSpectrum {
    values: Vec<f64>,
    basis: MassBasis,
    /// How many eigenvalues lie at or below the tolerance.
    pub(crate) massless: usize,
}

/// The [`MassSpectrum`] of A, or [`ModalError::IndefiniteMass`] (naming `pivot`, the Cholesky
/// pivot that failed or was weakest) when A has an eigenvalue below minus the tolerance.
pub(crate) fn mass_spectrum(a: MatRef<'_, f64>, pivot: usize, par: Par) -> Result<MassSpectrum, ModalError> {
    let n = a.nrows();
    let (values, basis) = mass_eigen(a, par)?;
    let amax = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    // A lumped mass is exact data: massless only when it is exactly zero, however small it is
    // beside the others. A dense A's computed eigenvalues carry rounding of 2n·u·max|a|.
    let tolerance = match basis {
        MassBasis::Permutation(_) => 0.0,
        MassBasis::Dense(_) => 2.0 * n as f64 * f64::EPSILON * amax,
    };
    if values[0] < -tolerance {
        return Err(ModalError::IndefiniteMass {
            pivot,
            min_eigenvalue: values[0],
            tolerance,
        });
    }
    let massless = values.partition_point(|&v| v <= tolerance);
    Ok(MassSpectrum {
        values,
        basis,
        massless,
    })
}

/// Condenses the pencil whose mass matrix has the `spectrum` (at least one direction is taken
/// as massless: the weakest, when none is at or below the tolerance) with ‖B‖_F = `norm_b`:
/// [`ModalError::SingularPencil`] when B₀₀ is singular to working precision
/// (det(λA + B) ≡ 0).
pub(crate) fn condense(problem: &PencilProblem, spectrum: MassSpectrum, norm_b: f64) -> Result<Condensed, ModalError> {
    let b = problem.b();
    let n = problem.dim();
    let MassSpectrum {
        values,
        basis: q,
        massless,
    } = spectrum;
    let r = massless.max(1);
    let bq = q.congruence(b);
    let b00 = bq.as_ref().submatrix(0, 0, r, r).to_owned();
    let b10 = bq.as_ref().submatrix(r, 0, n - r, r).to_owned();
    let b11 = bq.as_ref().submatrix(r, r, n - r, n - r).to_owned();
    let e00 = b00
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| ModalError::NoConvergence { n: r })?;
    let d: Vec<f64> = (0..r).map(|i| e00.S()[i]).collect();
    let singular_tol = r as f64 * f64::EPSILON * norm_b.max(f64::MIN_POSITIVE);
    if let Some(p) = (0..r).find(|&i| d[i].abs() <= singular_tol) {
        return Err(ModalError::SingularPencil { nullity: r, pivot: p });
    }
    // G = B₀₀⁻¹ B₀₁ = V diag(1/d) Vᵀ B₁₀ᵀ.
    let v = e00.U().to_owned();
    let mut t = v.transpose() * b10.transpose();
    for i in 0..r {
        for j in 0..n - r {
            t[(i, j)] /= d[i];
        }
    }
    let g = &v * &t;
    let s_raw = &b11 - &b10 * &g;
    let stiffness = Mat::from_fn(n - r, n - r, |i, j| 0.5 * (s_raw[(i, j)] + s_raw[(j, i)]));
    let l1 = Mat::from_fn(n - r, n - r, |i, j| if i == j { values[r + i].sqrt() } else { 0.0 });
    let infinite: Vec<Vec<f64>> = (0..r).map(|c| q.column(c)).collect();
    let stiffness_negatives = d.iter().filter(|&&v| v < 0.0).count();
    let order = match &q {
        MassBasis::Permutation(order) => order.clone(),
        MassBasis::Dense(_) => Vec::new(),
    };
    let condensation = Condensation::new(order, &values, r, Blocks { b10, v, d, g }, l1);
    Ok(Condensed {
        massless: r,
        stiffness,
        infinite,
        stiffness_negatives,
        basis: q,
        condensation,
    })
}

/// The eigenvectors Q of the mass matrix (QᵀAQ diagonal): a dense matrix D⁻¹Q_H, or, for a diagonal A, the
/// permutation that sorts the diagonal (column c of Q is the unit vector e_order[c]).
enum MassBasis {
    Dense(Mat<f64>),
    Permutation(Vec<usize>),
}

/// Eigenvalues of A ascending with a basis P of eigenvectors, PᵀAP = diag(values); a diagonal A
/// is sorted, not decomposed. A dense A is first scaled to H = D⁻¹AD⁻¹ with D = diag(2^{s_j}),
/// 2^{2s_j} within a factor two of a_jj (exact), and P = D⁻¹Q for H = Q diag(values) Qᵀ: the
/// massless directions are then judged on the unit-diagonal H, so that a graded A's small but
/// nonzero eigenvalues (an A of rank n − 2 graded over 2^±20 had a third taken as massless)
/// are not mistaken for rounding of zero.
fn mass_eigen(a: MatRef<'_, f64>, par: Par) -> Result<(Vec<f64>, MassBasis), ModalError> {
    let n = a.nrows();
    if is_diagonal(a) {
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&i, &j| a[(i, i)].total_cmp(&a[(j, j)]));
        let values = order.iter().map(|&i| a[(i, i)]).collect();
        return Ok((values, MassBasis::Permutation(order)));
    }
    let half_exponents: Vec<i32> = (0..n)
        .map(|j| {
            let d = a[(j, j)];
            if d > 0.0 && d.is_finite() {
                exponent(d).div_euclid(2)
            } else {
                0
            }
        })
        .collect();
    let h = Mat::from_fn(n, n, |i, j| {
        times_power_of_two(a[(i, j)], -(half_exponents[i] + half_exponents[j]))
    });
    let eig = symmetric_eigen(h, true, par)?;
    let q = eig.vectors.ok_or(ModalError::NoConvergence { n })?;
    let p = Mat::from_fn(n, n, |i, j| times_power_of_two(q[(i, j)], -half_exponents[i]));
    Ok((eig.values, MassBasis::Dense(p)))
}

impl MassBasis {
    /// QᵀBQ (a reordering of B for a permutation).
    fn congruence(&self, b: MatRef<'_, f64>) -> Mat<f64> {
        match self {
            Self::Dense(q) => q.transpose() * b * q,
            Self::Permutation(order) => Mat::from_fn(b.nrows(), b.ncols(), |i, j| b[(order[i], order[j])]),
        }
    }

    /// Column c of Q, of unit length.
    fn column(&self, c: usize) -> Vec<f64> {
        match self {
            Self::Dense(q) => {
                let column: Vec<f64> = q.col(c).iter().copied().collect();
                let norm = crate::linalg::norms::euclidean_norm(&column);
                column.iter().map(|x| x / norm).collect()
            }
            Self::Permutation(order) => {
                let mut e = vec![0.0; order.len()];
                e[order[c]] = 1.0;
                e
            }
        }
    }

    /// Q₁ z − Q₀ y, with Q₀ the first `r` columns of Q and Q₁ the others (the lift of condensed
    /// mode shapes z, with y = G z the massless coordinates' response).
    fn combine(&self, z: MatRef<'_, f64>, y: MatRef<'_, f64>, r: usize) -> Mat<f64> {
        match self {
            Self::Dense(q) => {
                let n = q.nrows();
                q.as_ref().subcols(r, n - r) * z - q.as_ref().subcols(0, r) * y
            }
            Self::Permutation(order) => {
                let mut x = Mat::<f64>::zeros(order.len(), z.ncols());
                for j in 0..z.ncols() {
                    for (i, &row) in order[r..].iter().enumerate() {
                        x[(row, j)] = z[(i, j)];
                    }
                    for (i, &row) in order[..r].iter().enumerate() {
                        x[(row, j)] = -y[(i, j)];
                    }
                }
                x
            }
        }
    }
}
