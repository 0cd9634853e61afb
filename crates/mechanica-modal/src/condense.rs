//! Semidefinite mass matrices: static condensation of the massless directions.
//!
//! With A = Q diag(a) Qᵀ and the null space Q₀ of A (a_i ≤ 2n·u·max a), write x = Q₁z + Q₀w.
//! The pencil splits as [[B₁₁ − ω²A₁, B₁₀], [B₀₁, B₀₀]] [z; w] = 0 with A₁ = diag(a₁) > 0, so
//! w = −B₀₀⁻¹B₀₁z and (B₁₁ − B₁₀B₀₀⁻¹B₀₁) z = ω² A₁ z: a definite pencil of order n − r, plus r
//! infinite eigenvalues (λ = −∞) with eigenvectors Q₀ (the Fix–Heiberger reduction, SIAM J.
//! Numer. Anal. 9, 1972, in its simplest form). B₀₀ singular makes det(λA + B) ≡ 0.
//!
//! A diagonal A (lumped masses with massless coordinates, e.g. the rotations of a lumped beam
//! model) needs no eigen-decomposition: Q is the permutation that sorts its diagonal, so QᵀBQ is
//! a reordering of B and the lift Q₁z + Q₀w a scatter of rows. That replaces the O(n³) eigen-
//! decomposition of A and the 4n³ flops of QᵀBQ by O(n²), and the condensed pencil's A₁ is
//! diagonal again (the reduction then scales, module `reduce`).

use crate::linalg::eigen::symmetric_eigen;
use crate::refine::ReducedCorrection;
use crate::solve::{Finish, Method, ModalSolution, SolveOptions, solve_definite};
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
    let (values, q) = mass_eigen(a, par)?;
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
    let s = Mat::from_fn(n - r, n - r, |i, j| 0.5 * (s_raw[(i, j)] + s_raw[(j, i)]));
    let l1 = Mat::from_fn(n - r, n - r, |i, j| if i == j { values[r + i].sqrt() } else { 0.0 });
    let want_vectors = options.vectors || options.refinement == crate::Refinement::Always;
    let condensation = clock.elapsed();
    let mut def = solve_definite(l1.as_ref(), s.as_ref(), options.selection, want_vectors, par)?;
    def.timings.factor += condensation;
    let infinite: Vec<Vec<f64>> = (0..r).map(|c| q.column(c)).collect();
    let negatives = d.iter().filter(|&&v| v < 0.0).count();
    let condensed = Condensation::new(&q, &values, r, Blocks { b10, v, d, g }, l1);
    // x = Q₁z + Q₀w with w = −G z.
    let lift = |z: MatRef<'_, f64>| -> Mat<f64> { q.combine(z, (&condensed.g * z).as_ref(), r) };
    let finish = Finish {
        problem,
        l: condensed.l1.as_ref(),
        norm_a,
        norm_b,
        options,
        par,
        condensed_stiffness_negatives: Some(negatives),
        condensation: condensed.refinable.then_some(&condensed),
    };
    finish.run(
        def,
        infinite,
        Some(&lift),
        Method::CondensedReduction { massless: r },
        Default::default(),
    )
}

/// The static condensation of the pencil (B, A) as refinement needs it: the exact identity
/// (S − ρA₁)z = r₁ − B₁₀B₀₀⁻¹r₀ for any x = Q[w; z] and its residual r = (B − ρA)x, with
/// S = B₁₁ − B₁₀B₀₀⁻¹B₀₁ the condensed stiffness. A residual measured in double-double on the
/// stored A and B thus becomes the residual of the condensed definite pencil (S, A₁), whose
/// residual bounds ([`crate::certify::residual_bounds::residual_bounds`]) then hold for the stored data, however
/// much the condensation's own rounding (stiff springs to massless nodes: the subtraction in S
/// loses u·‖B₁₀‖‖B₀₀⁻¹‖‖B₀₁‖) changed S.
pub(crate) struct Condensation {
    /// The massless coordinates first, then the others (MassBasis::Permutation).
    order: Vec<usize>,
    /// Number r of massless coordinates.
    massless: usize,
    /// B₁₀: rows of the coordinates with mass, columns of the massless ones.
    b10: Mat<f64>,
    /// B₀₀ = V diag(d) Vᵀ.
    v: Mat<f64>,
    d: Vec<f64>,
    /// G = B₀₀⁻¹B₀₁ (w = −G z on the condensed modes).
    g: Mat<f64>,
    /// L₁ = diag(√a₁), the Cholesky factor of the condensed mass matrix.
    pub(crate) l1: Mat<f64>,
    /// 4r·u·(κ(B₀₀) + 2)·‖B₁₀‖_F·‖B₀₀⁻¹‖₂: the rounding of B₁₀B₀₀⁻¹r₀ per unit ‖r₀‖.
    rounding: f64,
    /// Refinement is offered only when A is diagonal and its massless entries are exactly zero,
    /// so that the condensed pencil is the stored one, not a perturbation of it.
    pub(crate) refinable: bool,
}

/// The blocks of QᵀBQ a condensation keeps: B₁₀, B₀₀ = V diag(d) Vᵀ and G = B₀₀⁻¹B₀₁.
struct Blocks {
    b10: Mat<f64>,
    v: Mat<f64>,
    d: Vec<f64>,
    g: Mat<f64>,
}

impl Condensation {
    fn new(q: &MassBasis, values: &[f64], r: usize, blocks: Blocks, l1: Mat<f64>) -> Self {
        let Blocks { b10, v, d, g } = blocks;
        let order = match q {
            MassBasis::Permutation(order) => order.clone(),
            MassBasis::Dense(_) => Vec::new(),
        };
        let refinable = !order.is_empty() && values[..r].iter().all(|&a| a == 0.0);
        let dmin = d.iter().fold(f64::INFINITY, |m, v| m.min(v.abs()));
        let dmax = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let rounding =
            4.0 * r as f64 * f64::EPSILON * (dmax / dmin + 2.0) * crate::linalg::norms::frobenius_norm(b10.as_ref())
                / dmin;
        Self {
            order,
            massless: r,
            b10,
            v,
            d,
            g,
            l1,
            rounding,
            refinable,
        }
    }

    /// The residual s = r₁ − B₁₀B₀₀⁻¹r₀ of the condensed pencil, t = B₀₀⁻¹r₀, and ‖r₀‖, for a
    /// residual r of the full pencil in the original coordinates.
    pub(crate) fn condensed_residual(&self, r: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let (massless, massed) = self.order.split_at(self.massless);
        let r0: Vec<f64> = massless.iter().map(|&i| r[i]).collect();
        let vt_r0: Vec<f64> = (0..self.massless)
            .map(|k| (0..self.massless).map(|i| self.v[(i, k)] * r0[i]).sum::<f64>() / self.d[k])
            .collect();
        let t: Vec<f64> = (0..self.massless)
            .map(|i| (0..self.massless).map(|k| self.v[(i, k)] * vt_r0[k]).sum())
            .collect();
        let s = massed
            .iter()
            .enumerate()
            .map(|(row, &i)| r[i] - (0..self.massless).map(|k| self.b10[(row, k)] * t[k]).sum::<f64>())
            .collect();
        let r0_norm = r0.iter().map(|v| v * v).sum::<f64>().sqrt();
        (s, t, r0_norm)
    }

    /// ‖L₁⁻¹s‖ for the condensed residual s of [`Self::condensed_residual`], plus the rounding
    /// allowance of s (a bound of ‖L₁⁻¹‖ times [`Self::rounding`]·‖r₀‖).
    pub(crate) fn inverse_mass_norm(&self, s: &[f64], r0_norm: f64) -> f64 {
        let scaled = s
            .iter()
            .enumerate()
            .map(|(i, v)| (v / self.l1[(i, i)]).powi(2))
            .sum::<f64>()
            .sqrt();
        let lmin = (0..self.l1.nrows()).fold(f64::INFINITY, |m, i| m.min(self.l1[(i, i)]));
        scaled + self.rounding * r0_norm / lmin
    }

    /// The correction δX ≈ (B − ρA)⁻¹R by block elimination: δz = L₁⁻ᵀ K L₁⁻¹ s with K the
    /// reduced correction of the condensed pencil, δw = B₀₀⁻¹r₀ − G δz, scattered back.
    pub(crate) fn correction(&self, r: &Mat<f64>, rho: f64, reduced: &mut dyn ReducedCorrection) -> Mat<f64> {
        let (n, p) = (r.nrows(), r.ncols());
        let (massless, massed) = self.order.split_at(self.massless);
        let mut scaled = Mat::<f64>::zeros(massed.len(), p);
        let mut t = Mat::<f64>::zeros(massless.len(), p);
        for k in 0..p {
            let (s, tk, _) = self.condensed_residual(r.col_as_slice(k));
            for (i, v) in s.iter().enumerate() {
                scaled[(i, k)] = v / self.l1[(i, i)];
            }
            t.col_as_slice_mut(k).copy_from_slice(&tk);
        }
        let mut dz = reduced.apply(scaled, rho);
        for k in 0..p {
            for i in 0..massed.len() {
                dz[(i, k)] /= self.l1[(i, i)];
            }
        }
        let dw = &t - &self.g * &dz;
        let mut dx = Mat::<f64>::zeros(n, p);
        for k in 0..p {
            for (i, &row) in massed.iter().enumerate() {
                dx[(row, k)] = dz[(i, k)];
            }
            for (i, &row) in massless.iter().enumerate() {
                dx[(row, k)] = dw[(i, k)];
            }
        }
        dx
    }

    /// A₁ = L₁L₁ᵀ, the condensed mass matrix (diagonal).
    pub(crate) fn condensed_mass(&self) -> Mat<f64> {
        let m = self.l1.nrows();
        Mat::from_fn(
            m,
            m,
            |i, j| if i == j { self.l1[(i, i)] * self.l1[(i, i)] } else { 0.0 },
        )
    }

    /// The rows of X at the coordinates with mass: the condensed mode shapes Z.
    pub(crate) fn massed_rows(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let massed = &self.order[self.massless..];
        Mat::from_fn(massed.len(), x.ncols(), |i, k| x[(massed[i], k)])
    }
}

/// The eigenvectors Q of the mass matrix: a dense orthogonal matrix, or, for a diagonal A, the
/// permutation that sorts the diagonal (column c of Q is the unit vector e_order[c]).
enum MassBasis {
    Dense(Mat<f64>),
    Permutation(Vec<usize>),
}

/// Eigenvalues of A ascending and their eigenvectors; a diagonal A is sorted, not decomposed.
fn mass_eigen(a: MatRef<'_, f64>, par: Par) -> Result<(Vec<f64>, MassBasis), ModalError> {
    let n = a.nrows();
    if crate::linalg::reduce::is_diagonal(a) {
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&i, &j| a[(i, i)].total_cmp(&a[(j, j)]));
        let values = order.iter().map(|&i| a[(i, i)]).collect();
        return Ok((values, MassBasis::Permutation(order)));
    }
    let eig = symmetric_eigen(a.to_owned(), true, par)?;
    let q = eig.vectors.ok_or(ModalError::NoConvergence { n })?;
    Ok((eig.values, MassBasis::Dense(q)))
}

impl MassBasis {
    /// QᵀBQ (a reordering of B for a permutation).
    fn congruence(&self, b: MatRef<'_, f64>) -> Mat<f64> {
        match self {
            Self::Dense(q) => q.transpose() * b * q,
            Self::Permutation(order) => Mat::from_fn(b.nrows(), b.ncols(), |i, j| b[(order[i], order[j])]),
        }
    }

    /// Column c of Q.
    fn column(&self, c: usize) -> Vec<f64> {
        match self {
            Self::Dense(q) => q.col(c).iter().copied().collect(),
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
