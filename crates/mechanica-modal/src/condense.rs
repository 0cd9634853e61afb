//! Semidefinite mass matrices: static condensation of the massless directions.
//!
//! With A = Q diag(a) Qᵀ and the null space Q₀ of A (a_i ≤ 2n·u·max a), write x = Q₁z + Q₀w.
//! The pencil splits as [[B₁₁ − ω²A₁, B₁₀], [B₀₁, B₀₀]] [z; w] = 0 with A₁ = diag(a₁) > 0, so
//! w = −B₀₀⁻¹B₀₁z and (B₁₁ − B₁₀B₀₀⁻¹B₀₁) z = ω² A₁ z: a definite pencil of order n − r, plus r
//! infinite eigenvalues (λ = −∞) with eigenvectors Q₀ (the Fix–Heiberger reduction, SIAM J.
//! Numer. Anal. 9, 1972, in its simplest form). B₀₀ singular makes det(λA + B) ≡ 0.

use crate::solve::{Finish, Method, ModalSolution, SolveOptions, solve_definite};
use crate::symmetric_eigen::symmetric_eigen;
use crate::{ModalError, PencilProblem};
use faer::{Mat, MatRef, Par, Side};

/// Solves a pencil whose Cholesky factorization of A failed at `pivot`.
pub(crate) fn solve_semidefinite(
    problem: &PencilProblem,
    pivot: usize,
    options: &SolveOptions,
    norm_a: f64,
    norm_b: f64,
    par: Par,
) -> Result<ModalSolution, ModalError> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    let clock = std::time::Instant::now();
    let eig = symmetric_eigen(a.to_owned(), true, par)?;
    let values = eig.values;
    let q = eig.vectors.ok_or(ModalError::NoConvergence { n })?;
    let amax = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let tolerance = 2.0 * n as f64 * f64::EPSILON * amax;
    if values[0] < -tolerance {
        return Err(ModalError::IndefiniteMass {
            pivot,
            min_eigenvalue: values[0],
            tolerance,
        });
    }
    let r = values.partition_point(|&v| v <= tolerance).max(1);
    let q0 = q.subcols(0, r);
    let q1 = q.subcols(r, n - r);
    let bq = q.transpose() * b * &q;
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
    let v = e00.U();
    let mut t = v.transpose() * b10.transpose();
    for i in 0..r {
        for j in 0..n - r {
            t[(i, j)] /= d[i];
        }
    }
    let g = v * &t;
    let s_raw = &b11 - &b10 * &g;
    let s = Mat::from_fn(n - r, n - r, |i, j| 0.5 * (s_raw[(i, j)] + s_raw[(j, i)]));
    let l1 = Mat::from_fn(n - r, n - r, |i, j| if i == j { values[r + i].sqrt() } else { 0.0 });
    let want_vectors = options.vectors || options.refinement == crate::Refinement::Always;
    let condensation = clock.elapsed();
    let mut def = solve_definite(l1.as_ref(), s.as_ref(), options.selection, want_vectors, par)?;
    def.timings.factor += condensation;
    let infinite: Vec<Vec<f64>> = (0..r).map(|c| (0..n).map(|i| q0[(i, c)]).collect()).collect();
    let lift = |z: MatRef<'_, f64>| -> Mat<f64> { q1 * z - q0 * (&g * z) };
    let finish = Finish {
        problem,
        l: l1.as_ref(),
        norm_a,
        norm_b,
        options,
        par,
    };
    finish.run(def, infinite, Some(&lift), Method::CondensedReduction { massless: r })
}
