//! Refinement of one simple eigenpair, or of one cluster of nearly equal eigenvalues, of
//! det(λA + B) = 0 with extended-precision residuals, for stiff and graded problems where the
//! Cholesky reduction is accurate only relative to the largest eigenvalue.
//!
//! Method (Dongarra, Moler & Wilkinson, "Improving the accuracy of computed eigenvalues and
//! eigenvectors", SIAM J. Numer. Anal. 20, 1983, adapted to the symmetric pencil): Newton's
//! method on F(x, ω²) = (B − ω²A)x = 0 with the normalisation (Ax₀)ᵀx = 1, the Jacobian frozen
//! at the starting pair and factored once, in double precision, as the symmetric bordered matrix
//! [[B − ω₀²A, −Ax₀], [−(Ax₀)ᵀ, 0]] (Bunch–Kaufman LBLᵀ). The residual (B − ω²A)x and the
//! Rayleigh quotient are computed in double-double, so the iteration converges to the pair of
//! the pencil as stored, to working precision, as long as the double-precision solve has a
//! relative accuracy below 1 (true for stiffness ratios far beyond 1e12). Its cost is one
//! (n+1)³/3 factorization plus a few O(n²) double-double residuals per refined mode. When A and
//! B both have few nonzeros (a banded or assembled pencil stored densely), K = B − ω₀²A is
//! factored by a sparse LU with partial pivoting instead, its pattern analysed once for all
//! modes ([`SparseShifts`]), and the border is eliminated by blocks ([`refine_pair_sparse`]):
//! each simple mode then costs O(nnz(L + U)) per step instead of the batch's 4n² products
//! through the reduced eigenvectors (graded 1e12 chain, n = 2000: refine stage 3.1 → 1.6 s).
//!
//! It is chosen by [`crate::Refinement::Auto`] for every selected simple mode whose first-order
//! bound from the reduction exceeds 1e-8·|ω²| (fewer than 8 guaranteed digits). Modes whose
//! bound intervals overlap (a repeated frequency of a symmetric structure, or eigenvalues too
//! close to tell apart) are refined together as one block by [`refine_cluster_projected`]: the
//! block's invariant subspace is well defined where its single vectors are not.
//!
//! A condensed pencil (massless coordinates of a diagonal A, module `condense`) is refined the
//! same way in the original coordinates; its residuals are mapped exactly to residuals of the
//! condensed pencil (S, A₁) and its corrections go through the condensed spectrum ([`Metric`]).

use crate::condense::Condensation;
use crate::dd::{Dd, Operand, SplitVector, dot, dot_split};
use crate::linalg::eigen::TridiagonalForm;
use crate::linalg::eigen::inverse_iteration::{ShiftedTridiagonal, one_norm};
use crate::linalg::reduce::LowerFactor;
use crate::runtime::fork_join::map_items;
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Accum, Mat, MatRef, Par, Side};
use std::ops::Range;

/// Maximum Newton steps per pair.
pub const MAX_STEPS: usize = 12;

/// A refined pair.
#[derive(Debug, Clone)]
pub(crate) struct RefinedPair {
    /// A-normalised eigenvector.
    pub x: Vec<f64>,
    /// ω² (the double-double Rayleigh quotient, rounded).
    pub omega_sq: f64,
    /// ‖(B − ω²A)x‖_{A⁻¹} / ‖x‖_A from the double-double residual; for a condensed pencil
    /// ‖s‖_{A₁⁻¹} / ‖x‖_A of its residual s (plus the rounding allowance of s).
    pub residual_a_inv: f64,
    /// The residual (B − ω²A)x from double-double, rounded to double; for a condensed pencil
    /// the residual s of (S, A₁) (`Condensation::condensed_residual`), of order n − r.
    pub residual: Vec<f64>,
    /// Newton steps taken.
    pub steps: usize,
}

/// The modes of one cluster refined together ([`refine_cluster_projected`]).
#[derive(Debug, Clone)]
pub(crate) struct RefinedCluster {
    /// The refined pairs, ascending ω², each A-normalised.
    pub pairs: Vec<RefinedPair>,
    /// max_{k≠l} |x_kᵀAx_l| of the refined vectors, in double-double (0 for a single mode).
    pub orthogonality: f64,
}

impl RefinedCluster {
    /// A cluster of one pair.
    pub(crate) fn single(pair: RefinedPair) -> Self {
        Self {
            pairs: vec![pair],
            orthogonality: 0.0,
        }
    }
}

/// The definite pencil in which refinement corrects a mode and measures its residual.
#[derive(Clone, Copy)]
pub(crate) enum Metric<'a> {
    /// A = LLᵀ positive definite (L lower): corrections L⁻ᵀKL⁻¹r, residuals in the A⁻¹-norm.
    Cholesky(LowerFactor<'a>),
    /// A diagonal with exactly massless coordinates, condensed statically: corrections and
    /// residuals of the condensed pencil (S, A₁) (module `condense`).
    Condensed(&'a Condensation),
}

impl Metric<'_> {
    /// δX ≈ (B − ρA)⁻¹R with K, the reduced correction, applied on the definite pencil.
    fn correction(&self, r: Mat<f64>, rho: f64, reduced: &mut dyn ReducedCorrection) -> Mat<f64> {
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
    fn definite_residual(&self, r: Vec<f64>) -> (Vec<f64>, f64) {
        match self {
            Self::Cholesky(l) => {
                let mut y = Mat::from_fn(r.len(), 1, |i, _| r[i]);
                l.solve(y.as_mut(), Par::Seq);
                (r, y.norm_l2())
            }
            Self::Condensed(c) => {
                let (s, _, r0_norm) = c.condensed_residual(&r);
                let norm = c.inverse_mass_norm(&s, r0_norm);
                (s, norm)
            }
        }
    }
}

/// Refines (ω₀², x₀) by Newton steps on the bordered matrix [B − ω₀²A, −Ax₀; −(Ax₀)ᵀ, 0]
/// (nonsingular for a simple finite eigenvalue, also when A is singular), factored densely,
/// with the final residual measured in `metric`; None if the bordered matrix is singular to
/// working precision (the eigenvalue is not simple) or xᵀAx is not positive.
pub(crate) fn refine_pair(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    x0: &[f64],
    omega0: f64,
) -> Option<RefinedPair> {
    let ax0: Vec<f64> = a.product(x0).iter().map(|v| v.to_f64()).collect();
    let jacobian = BorderedJacobian::dense(a, b, &ax0, omega0);
    let (x, steps, _) = newton_steps(a, b, &jacobian, x0, omega0)?;
    finish_pair(a, b, metric, x, steps)
}

/// [`refine_pair`] for A and B with few nonzeros, the Jacobian factored sparsely
/// ([`BorderedJacobian::sparse`]): O(n·w²) per mode for a bandwidth w, where the spectral
/// correction of [`refine_cluster_projected`] costs 4n² per step. None if the factorization
/// fails or the steps do not converge (then the other methods are tried).
pub(crate) fn refine_pair_sparse(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: &SparseShifts,
    metric: Metric<'_>,
    x0: &[f64],
    omega0: f64,
) -> Option<RefinedPair> {
    let ax0: Vec<f64> = a.product(x0).iter().map(|v| v.to_f64()).collect();
    let jacobian = BorderedJacobian::sparse(shifts, &ax0, omega0)?;
    match newton_steps(a, b, &jacobian, x0, omega0)? {
        (x, steps, true) => finish_pair(a, b, metric, x, steps),
        _ => None,
    }
}

/// K = B − sA for a pencil whose A and B both have few nonzeros: the union of their patterns
/// with both values on it, and its LU symbolic analysis (column ordering, structure), found once
/// for every shift of a refinement stage.
pub(crate) struct SparseShifts {
    pattern: faer::sparse::SymbolicSparseColMat<usize>,
    b_values: Vec<f64>,
    a_values: Vec<f64>,
    symbolic: faer::sparse::linalg::solvers::SymbolicLu<usize>,
}

impl SparseShifts {
    /// None when A or B is dense, or the symbolic analysis fails.
    pub(crate) fn new(a: &Operand<'_>, b: &Operand<'_>) -> Option<Self> {
        let n = a.matrix().nrows();
        let mut column_starts = Vec::with_capacity(n + 1);
        let (mut rows, mut b_values, mut a_values) = (Vec::new(), Vec::new(), Vec::new());
        column_starts.push(0);
        for j in 0..n {
            let (bj, aj) = (b.column_nonzeros(j)?, a.column_nonzeros(j)?);
            // The rows of B's and A's column j merged (both ascending).
            let (mut p, mut q) = (0, 0);
            while p < bj.len() || q < aj.len() {
                let row_b = bj.get(p).map_or(usize::MAX, |e| e.0);
                let row_a = aj.get(q).map_or(usize::MAX, |e| e.0);
                let row = row_b.min(row_a);
                rows.push(row);
                b_values.push(if row_b == row { bj[p].1 } else { 0.0 });
                a_values.push(if row_a == row { aj[q].1 } else { 0.0 });
                p += usize::from(row_b == row);
                q += usize::from(row_a == row);
            }
            column_starts.push(rows.len());
        }
        let pattern = faer::sparse::SymbolicSparseColMat::new_checked(n, n, column_starts, None, rows);
        let symbolic = faer::sparse::linalg::solvers::SymbolicLu::try_new(pattern.as_ref()).ok()?;
        Some(Self {
            pattern,
            b_values,
            a_values,
            symbolic,
        })
    }

    /// The LU factorization with partial pivoting of B − shift·A; None if it fails.
    fn factor(&self, shift: f64) -> Option<faer::sparse::linalg::solvers::Lu<usize, f64>> {
        let values: Vec<f64> = self
            .b_values
            .iter()
            .zip(&self.a_values)
            .map(|(b, a)| b - shift * a)
            .collect();
        let k = faer::sparse::SparseColMatRef::new(self.pattern.as_ref(), &values);
        faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(self.symbolic.clone(), k).ok()
    }
}

/// Newton steps of [`refine_pair`] with the frozen Jacobian `jacobian`: the iterate, the steps
/// taken and whether a step fell below the rounding of a double iterate; None if a step was not
/// finite. The iterate is kept in double-double, and the steps go on past that point while
/// they still halve (to about u² of the iterate): the final residual, and so the certified
/// bound, is then not limited by rounding the vector to double.
fn newton_steps(
    a: &Operand<'_>,
    b: &Operand<'_>,
    jacobian: &BorderedJacobian,
    x0: &[f64],
    omega0: f64,
) -> Option<(SplitVector, usize, bool)> {
    let n = x0.len();
    let mut x = SplitVector::of(x0.to_vec());
    let mut omega = Dd::of(omega0);
    let mut converged = false;
    let mut previous = f64::INFINITY;
    for step in 1..=MAX_STEPS {
        let bx = b.product_split(&x);
        let axd = a.product_split(&x);
        let residual: Vec<f64> = (0..n).map(|i| -(bx[i].minus(omega.times(axd[i]))).to_f64()).collect();
        // Normalisation residual: (Ax₀)ᵀx − 1, computed as x₀ᵀ(Ax) in double-double.
        let normalisation = dot(x0, &axd).minus(Dd::of(1.0)).to_f64();
        let (dx, d_omega) = jacobian.solve(residual, normalisation)?;
        let xmax = x.hi.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = dx.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        x.add(&dx);
        omega = omega.plus(Dd::of(d_omega));
        converged |= dmax <= 2.0 * f64::EPSILON * xmax && d_omega.abs() <= 2.0 * f64::EPSILON * omega.hi.abs();
        if converged && (dmax <= 4.0 * f64::EPSILON * f64::EPSILON * xmax || dmax > 0.5 * previous) {
            return Some((x, step, true));
        }
        previous = dmax;
    }
    Some((x, MAX_STEPS, converged))
}

/// The Jacobian [K, −a; −aᵀ, 0] of [`refine_pair`] with K = B − ω₀²A and a = A x₀, factored
/// once in double precision.
enum BorderedJacobian {
    /// Bunch–Kaufman LBLᵀ of the dense matrix of order n + 1 ((n + 1)³/3 flops).
    Dense(faer::linalg::solvers::Lblt<f64>),
    /// A sparse LU of K alone with partial pivoting (the dense border row would fill the
    /// factors), the border by block elimination: K⁻¹a and aᵀK⁻¹a are formed once.
    Sparse {
        lu: faer::sparse::linalg::solvers::Lu<usize, f64>,
        a: Vec<f64>,
        k_inv_a: Vec<f64>,
        schur: f64,
    },
}

impl BorderedJacobian {
    fn dense(a: &Operand<'_>, b: &Operand<'_>, ax0: &[f64], omega0: f64) -> Self {
        let n = ax0.len();
        let border = Mat::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
            (true, true) => b.matrix()[(i, j)] - omega0 * a.matrix()[(i, j)],
            (true, false) => -ax0[i],
            (false, true) => -ax0[j],
            (false, false) => 0.0,
        });
        Self::Dense(border.lblt(Side::Lower))
    }

    /// The sparse factorization of K = B − ω₀²A (O(n·w²) for a bandwidth w instead of
    /// (n + 1)³/3); None if it fails or gives a non-finite K⁻¹a (K singular to working
    /// precision). Block elimination loses accuracy along K's near-null vector, which is x₀
    /// itself; the Newton steps measure their residuals in double-double, and steps that do not
    /// converge are discarded ([`refine_pair_sparse`]).
    fn sparse(shifts: &SparseShifts, ax0: &[f64], omega0: f64) -> Option<Self> {
        let n = ax0.len();
        let lu = shifts.factor(omega0)?;
        let k_inv_a = lu.solve(Mat::from_fn(n, 1, |i, _| ax0[i]));
        let k_inv_a: Vec<f64> = k_inv_a.col(0).iter().copied().collect();
        let schur: f64 = ax0.iter().zip(&k_inv_a).map(|(u, v)| u * v).sum();
        if !(schur.is_finite() && schur != 0.0 && k_inv_a.iter().all(|v| v.is_finite())) {
            return None;
        }
        Some(Self::Sparse {
            lu,
            a: ax0.to_vec(),
            k_inv_a,
            schur,
        })
    }

    /// (δx, δω²) with K δx − a δω² = r and −aᵀδx = s; None if not finite.
    fn solve(&self, r: Vec<f64>, s: f64) -> Option<(Vec<f64>, f64)> {
        let n = r.len();
        let (dx, d_omega) = match self {
            Self::Dense(lblt) => {
                let rhs = Mat::from_fn(n + 1, 1, |i, _| if i < n { r[i] } else { s });
                let delta = lblt.solve(&rhs);
                ((0..n).map(|i| delta[(i, 0)]).collect::<Vec<f64>>(), delta[(n, 0)])
            }
            Self::Sparse { lu, a, k_inv_a, schur } => {
                // δx = K⁻¹r + δω² K⁻¹a, and −aᵀδx = s gives δω².
                let y = lu.solve(Mat::from_fn(n, 1, |i, _| r[i]));
                let a_y: f64 = a.iter().zip(y.col(0).iter()).map(|(u, v)| u * v).sum();
                let d_omega = -(s + a_y) / schur;
                ((0..n).map(|i| y[(i, 0)] + d_omega * k_inv_a[i]).collect(), d_omega)
            }
        };
        (dx.iter().all(|v| v.is_finite()) && d_omega.is_finite()).then_some((dx, d_omega))
    }
}

/// The correction of [`refine_cluster_projected`]: an approximate inverse of C − ρI on the
/// complement of the refined modes, C = L⁻¹BL⁻ᵀ, applied in the reduced coordinates.
pub(crate) trait ReducedCorrection {
    /// Σ_{j∉G} y_j (y_jᵀw)/(ω̃²_j − ρ) for the computed eigenpairs (ω̃²_j, y_j) of C outside the
    /// refined modes G, for every column of `w`.
    fn apply(&mut self, w: Mat<f64>, rho: f64) -> Mat<f64>;
}

/// The reduced problem's spectrum C = Y diag(ω²) Yᵀ, C = L⁻¹BL⁻ᵀ, A = LLᵀ: an approximate
/// inverse of B − ρA that costs O(n²) to apply, so refinement needs no new factorization.
pub(crate) struct ReducedSpectrum<'a> {
    /// All n orthonormal eigenvectors of C.
    pub y: MatRef<'a, f64>,
    /// All n eigenvalues of C (ω², ascending).
    pub omega_sq: &'a [f64],
    /// The modes being refined (indices into `omega_sq`).
    pub modes: Range<usize>,
}

impl ReducedCorrection for ReducedSpectrum<'_> {
    fn apply(&mut self, w: Mat<f64>, rho: f64) -> Mat<f64> {
        // Sequential: refinement runs clusters on the threads (a fork per product would cost more
        // than these O(n²) products).
        let mut c = Mat::<f64>::zeros(self.y.ncols(), w.ncols());
        matmul(
            c.as_mut(),
            Accum::Replace,
            self.y.transpose(),
            w.as_ref(),
            1.0,
            Par::Seq,
        );
        for j in 0..c.nrows() {
            let gap = self.omega_sq[j] - rho;
            let excluded = self.modes.contains(&j) || gap == 0.0;
            for k in 0..c.ncols() {
                c[(j, k)] = if excluded { 0.0 } else { c[(j, k)] / gap };
            }
        }
        let mut out = Mat::<f64>::zeros(self.y.nrows(), w.ncols());
        matmul(out.as_mut(), Accum::Replace, self.y, c.as_ref(), 1.0, Par::Seq);
        out
    }
}

/// The reduced problem in tridiagonal form C = Q T Qᵀ with the refined modes' orthonormal
/// eigenvectors Z of T: the correction of a values-only solve, which has no Y. The same
/// operator as [`ReducedSpectrum`] evaluated as Q P (T − ρI)⁻¹ P Qᵀ with P = I − Z Zᵀ: the
/// shifted tridiagonal solve is nearly singular at ρ ≈ θ, but its error lies almost entirely in
/// span Z (Wilkinson, "The Algebraic Eigenvalue Problem", §5.56), which the second projection
/// removes. That needs span Z to be T's invariant subspace to working precision, which inverse
/// iteration does not give a cluster (its single vectors are ill determined, and orthogonalising
/// them loses digits): at the first application Z takes two steps of subspace inverse iteration
/// Z ← orth((T − ρI)⁻¹Z) at the cluster's ρ, which damp every other direction by the ratio of
/// the cluster's spread to its gap.
pub(crate) struct TridiagonalCorrection<'a> {
    /// T and Q.
    pub form: &'a mut TridiagonalForm,
    /// The refined modes' orthonormal eigenvectors of T, one column each.
    pub z: Mat<f64>,
    /// Whether `z` has had its subspace inverse iteration.
    pub purified: bool,
}

impl TridiagonalCorrection<'_> {
    /// Two steps of Z ← orth((T − ρI)⁻¹Z); false if a solve or the orthonormalisation fails.
    fn purify(&mut self, shifted: &ShiftedTridiagonal) -> bool {
        for _ in 0..2 {
            for k in 0..self.z.ncols() {
                shifted.solve_in_place(self.z.col_as_slice_mut(k));
            }
            if !orthonormalize(&mut self.z) {
                return false;
            }
        }
        true
    }
}

impl ReducedCorrection for TridiagonalCorrection<'_> {
    fn apply(&mut self, mut w: Mat<f64>, rho: f64) -> Mat<f64> {
        self.form.apply_q_transpose(w.as_mut());
        let (diag, subdiag) = (self.form.diag(), self.form.subdiag());
        let tiny = f64::EPSILON * one_norm(diag, subdiag);
        let shifted = ShiftedTridiagonal::new(diag, subdiag, rho, tiny);
        if !self.purified {
            self.purified = true;
            if !self.purify(&shifted) {
                w.col_iter_mut().for_each(|c| c.iter_mut().for_each(|v| *v = f64::NAN));
                return w;
            }
        }
        for k in 0..w.ncols() {
            let u = w.col_as_slice_mut(k);
            project_out(u, self.z.as_ref());
            if shifted.solve_in_place(u) != 1.0 {
                // Growth beyond 1e150: no usable correction (the caller sees non-finite values).
                u.iter_mut().for_each(|v| *v = f64::NAN);
                return w;
            }
            project_out(u, self.z.as_ref());
        }
        self.form.apply_q(w.as_mut());
        w
    }
}

/// Orthonormalises the columns of `z` in place by modified Gram–Schmidt applied twice; false
/// if a column is not finite or falls to zero.
fn orthonormalize(z: &mut Mat<f64>) -> bool {
    for k in 0..z.ncols() {
        for _ in 0..2 {
            for j in 0..k {
                let overlap: f64 = (0..z.nrows()).map(|i| z[(i, j)] * z[(i, k)]).sum();
                for i in 0..z.nrows() {
                    let zij = z[(i, j)];
                    z[(i, k)] -= overlap * zij;
                }
            }
        }
        let column = z.col_as_slice_mut(k);
        let norm = column.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return false;
        }
        column.iter_mut().for_each(|v| *v /= norm);
    }
    true
}

/// u ← u − Σ_k z_k (z_kᵀu) for orthonormal columns z_k.
fn project_out(u: &mut [f64], z: MatRef<'_, f64>) {
    for k in 0..z.ncols() {
        let zk = z.col(k);
        let overlap: f64 = u.iter().zip(zk.iter()).map(|(p, q)| p * q).sum();
        u.iter_mut().zip(zk.iter()).for_each(|(p, q)| *p -= overlap * q);
    }
}

/// Maximum steps of [`refine_pair_projected`] before it gives up.
pub const MAX_PROJECTED_STEPS: usize = 8;

/// A correction below this many ulps of x that no longer halves has reached rounding level:
/// the iteration stops there (the bound comes from the final residual either way).
const STAGNATION_ULPS: f64 = 16.0;

/// Refines the simple pair (ω²_i, x₀): [`refine_cluster_projected`] for one mode.
#[cfg(test)]
pub(crate) fn refine_pair_projected(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
) -> Option<RefinedPair> {
    let x0 = MatRef::from_column_major_slice(x0, x0.len(), 1);
    refine_cluster_projected(a, b, metric, correction, x0).and_then(|c| c.pairs.into_iter().next())
}

/// Refines a cluster G of p modes with nearly equal ω² (p = 1: a simple pair), starting from
/// their computed vectors X₀ (n × p, A-orthonormal to working precision), by block
/// Rayleigh-quotient steps with a projected correction: the p × p Rayleigh-quotient matrix
/// M = (XᵀAX)⁻¹XᵀBX and R = BX − AXM in double-double, ρ = trace M / p, then
/// X ← X − L⁻ᵀ K L⁻¹ R with K the [`ReducedCorrection`], Σ_{j∉G} y_j y_jᵀ/(ω̃²_j − ρ).
///
/// For p = 1 this is the Newton step of [`refine_pair`] with the bordered Jacobian replaced by
/// the reduction's computed decomposition, which has a backward error of the same order as an
/// LBLᵀ factorization of B − ρA when the reduction is accurate. For p > 1 it is the block
/// (subspace) form of that step, which needs no single vector of the cluster to be well
/// defined: X converges to the invariant subspace, and a final Rayleigh–Ritz step on (XᵀBX,
/// XᵀAX) gives the A-orthonormal pairs. It converges linearly with the ratio of the cluster's
/// spread and the decomposition's error to the gap to the other modes. None when a step above
/// rounding level fails to halve the correction (graded problems where the computed spectrum is
/// too far from the exact one, or a cluster that is not separated from the rest): for p = 1 the
/// caller then falls back to [`refine_pair`].
pub(crate) fn refine_cluster_projected(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: MatRef<'_, f64>,
) -> Option<RefinedCluster> {
    let (n, p) = (x0.nrows(), x0.ncols());
    if p == 0 {
        return None;
    }
    let mut x = x0.to_owned();
    let mut previous = f64::INFINITY;
    for step in 1..=MAX_PROJECTED_STEPS {
        let ax: Vec<Vec<Dd>> = (0..p).map(|k| a.product(x.col_as_slice(k))).collect();
        let bx: Vec<Vec<Dd>> = (0..p).map(|k| b.product(x.col_as_slice(k))).collect();
        let m = rayleigh_quotient_matrix(&x, &ax, &bx)?;
        let rho = (0..p).fold(Dd::of(0.0), |t, k| t.plus(m[k][k])).to_f64() / p as f64;
        let w = Mat::from_fn(n, p, |i, k| {
            (0..p).fold(bx[k][i], |r, j| r.minus(m[j][k].times(ax[j][i]))).to_f64()
        });
        let delta = metric.correction(w, rho, correction);
        // f64::max ignores NaN, so a failed correction is caught here, not by dmax.
        if !delta.col_iter().all(|c| c.iter().all(|v| v.is_finite())) {
            return None;
        }
        let xmax = x.col_iter().flat_map(|c| c.iter()).fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = delta
            .col_iter()
            .flat_map(|c| c.iter())
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let at_rounding = dmax <= STAGNATION_ULPS * f64::EPSILON * xmax;
        let contracting = dmax <= 0.5 * previous;
        if !dmax.is_finite() || !(contracting || at_rounding) {
            return None;
        }
        for k in 0..p {
            for (xi, di) in x.col_as_slice_mut(k).iter_mut().zip(delta.col_as_slice(k)) {
                *xi -= di;
            }
        }
        if dmax <= 2.0 * f64::EPSILON * xmax || (at_rounding && !contracting) {
            return finish_cluster(a, b, metric, x, step);
        }
        previous = dmax;
    }
    None
}

/// More projected Newton steps ([`refine_cluster_projected`] for one mode) on a refined simple
/// mode, with the iterate in double-double ([`SplitVector`]): where rounding a double vector
/// limits the residual (k·u·|x| at a stiff spring of a graded pencil), the steps go on while
/// they halve, to about u² of the iterate. A step that does not halve is not taken. `steps` is
/// what the mode took before; None if no step was taken or one was not finite.
pub(crate) fn polish_simple_mode(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    correction: &mut dyn ReducedCorrection,
    x0: &[f64],
    steps: usize,
) -> Option<RefinedPair> {
    let n = x0.len();
    let mut x = SplitVector::of(x0.to_vec());
    let mut previous = f64::INFINITY;
    let mut taken = 0;
    for _ in 0..MAX_PROJECTED_STEPS {
        let ax = a.product_split(&x);
        let bx = b.product_split(&x);
        let rho = dot_split(&x, &bx).over(dot_split(&x, &ax));
        let w = Mat::from_fn(n, 1, |i, _| bx[i].minus(rho.times(ax[i])).to_f64());
        let delta = metric.correction(w, rho.to_f64(), correction);
        let step: Vec<f64> = delta.col(0).iter().map(|d| -d).collect();
        if !step.iter().all(|v| v.is_finite()) {
            return None;
        }
        let xmax = x.hi.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dmax = step.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if dmax > 0.5 * previous {
            break;
        }
        x.add(&step);
        taken += 1;
        if dmax <= 4.0 * f64::EPSILON * f64::EPSILON * xmax {
            break;
        }
        previous = dmax;
    }
    if taken == 0 {
        return None;
    }
    finish_pair(a, b, metric, x, steps + taken)
}

/// [`refine_cluster_projected`] for many simple modes at once, for a positive definite A with
/// the reduced spectrum at hand: the same projected Newton step per mode (ρ_k its Rayleigh
/// quotient, the correction L⁻ᵀ Σ_{j≠k} y_j y_jᵀ/(ω̃²_j − ρ_k) L⁻¹ r_k), but the correction of
/// all modes still iterating is applied as two triangular solves and two products with Y on a
/// block of columns. One mode at a time, each correction reads Y twice and L twice (3n²
/// numbers, memory-bound at 2n² flops per column); a block reads them once per step. The
/// double-double residuals stay per mode, on the pool's threads. Each entry is the mode's
/// refined pair, or None where the step did not contract (the caller falls back as for a
/// cluster of one). `reduced` is Y and all n eigenvalues of C; `modes[c]` is the index in
/// that spectrum of column c of `x0`.
pub(crate) fn refine_simple_modes(
    a: &Operand<'_>,
    b: &Operand<'_>,
    l: LowerFactor<'_>,
    reduced: (MatRef<'_, f64>, &[f64]),
    modes: &[usize],
    x0: MatRef<'_, f64>,
    par: Par,
) -> Vec<Option<RefinedPair>> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        Iterating,
        Converged { steps: usize },
        Failed,
    }
    let (y, omega_all) = reduced;
    let (n, k) = (x0.nrows(), x0.ncols());
    let mut x = x0.to_owned();
    let mut state = vec![State::Iterating; k];
    let mut previous = vec![f64::INFINITY; k];
    for step in 1..=MAX_PROJECTED_STEPS {
        let active: Vec<usize> = (0..k).filter(|&c| state[c] == State::Iterating).collect();
        if active.is_empty() {
            break;
        }
        // Residual r = Bx − ρAx in double-double, ρ = xᵀBx / xᵀAx, per active mode.
        let residual_of = |&c: &usize| {
            let xc = x.col_as_slice(c);
            let (ax, bx) = (a.product(xc), b.product(xc));
            let rho = dot(xc, &bx).over(dot(xc, &ax));
            let r: Vec<f64> = (0..n).map(|i| bx[i].minus(rho.times(ax[i])).to_f64()).collect();
            (rho.to_f64(), r)
        };
        let residuals: Vec<(f64, Vec<f64>)> = map_items(&active, par, residual_of);
        let mut w = Mat::from_fn(n, active.len(), |i, c| residuals[c].1[i]);
        l.solve(w.as_mut(), par);
        let mut coefficients = Mat::<f64>::zeros(y.ncols(), active.len());
        matmul(
            coefficients.as_mut(),
            Accum::Replace,
            y.transpose(),
            w.as_ref(),
            1.0,
            par,
        );
        for (c, &mode) in active.iter().enumerate() {
            let rho = residuals[c].0;
            let own = modes[mode];
            for j in 0..coefficients.nrows() {
                let gap = omega_all[j] - rho;
                let value = coefficients[(j, c)];
                coefficients[(j, c)] = if j == own || gap == 0.0 { 0.0 } else { value / gap };
            }
        }
        let mut delta = Mat::<f64>::zeros(n, active.len());
        matmul(delta.as_mut(), Accum::Replace, y, coefficients.as_ref(), 1.0, par);
        l.solve_transposed(delta.as_mut(), par);
        for (c, &mode) in active.iter().enumerate() {
            let d = delta.col_as_slice(c);
            if !d.iter().all(|v| v.is_finite()) {
                state[mode] = State::Failed;
                continue;
            }
            let xmax = x.col_as_slice(mode).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let dmax = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let at_rounding = dmax <= STAGNATION_ULPS * f64::EPSILON * xmax;
            let contracting = dmax <= 0.5 * previous[mode];
            if !dmax.is_finite() || !(contracting || at_rounding) {
                state[mode] = State::Failed;
                continue;
            }
            for (xi, di) in x.col_as_slice_mut(mode).iter_mut().zip(d) {
                *xi -= di;
            }
            if dmax <= 2.0 * f64::EPSILON * xmax || (at_rounding && !contracting) {
                state[mode] = State::Converged { steps: step };
            }
            previous[mode] = dmax;
        }
    }
    let metric = Metric::Cholesky(l);
    let converged: Vec<(usize, usize)> = (0..k)
        .filter_map(|mode| match state[mode] {
            State::Converged { steps } => Some((mode, steps)),
            State::Iterating | State::Failed => None,
        })
        .collect();
    let finished = map_items(&converged, par, |&(mode, steps)| {
        finish_pair(a, b, metric, SplitVector::of(x.col_as_slice(mode).to_vec()), steps)
    });
    let mut pairs: Vec<Option<RefinedPair>> = vec![None; k];
    for (&(mode, _), pair) in converged.iter().zip(finished) {
        pairs[mode] = pair;
    }
    pairs
}

/// A sparse pencil's (`shifts`) single mode by [`refine_pair_sparse`] first, and a cluster's
/// members one by one ([`refine_members`]); then
/// [`refine_cluster_projected`] through `correction` when there is one, and for a single mode
/// the dense bordered Newton step of [`refine_pair`] where that declines (the bordered step
/// needs a simple eigenvalue; a dense pencil's cluster whose block refinement fails tries its
/// members one by one on dense factorizations, (n + 1)³/3 each).
pub(crate) fn refine_cluster(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: Option<&SparseShifts>,
    metric: Metric<'_>,
    correction: Option<&mut dyn ReducedCorrection>,
    x0: MatRef<'_, f64>,
    omega0: f64,
) -> Option<RefinedCluster> {
    let single = (x0.ncols() == 1).then(|| x0.col(0).iter().copied().collect::<Vec<f64>>());
    let sparse = match (&single, shifts) {
        (Some(x), Some(shifts)) => refine_pair_sparse(a, b, shifts, metric, x, omega0).map(RefinedCluster::single),
        (None, Some(_)) => refine_members(a, b, shifts, metric, x0),
        (_, None) => None,
    };
    sparse
        .or_else(|| correction.and_then(|c| refine_cluster_projected(a, b, metric, c, x0)))
        .or_else(|| match (single, shifts) {
            (Some(x), _) => refine_pair(a, b, metric, &x, omega0).map(RefinedCluster::single),
            (None, None) => refine_members(a, b, None, metric, x0),
            (None, Some(_)) => None,
        })
}

/// The members of a cluster refined one by one by bordered Newton steps (each from its own
/// start vector and Rayleigh quotient; on a sparse LU with `shifts`, [`refine_pair_sparse`],
/// else the dense LBLᵀ of [`refine_pair`]): modes whose first-order bounds overlap but whose
/// eigenvalues are simple (in a graded chain the unrefined bounds are wide). Accepted only when
/// the refined intervals ω²_k ± (‖r_k‖_{A⁻¹} + u|ω²_k|) are separated (the clusters of
/// `solve::clusters`, ascending, all single) and the vectors A-orthogonal to √u: each member
/// is then a simple eigenvalue of its own. None otherwise (a repeated eigenvalue, or two
/// members that converged to the same pair).
fn refine_members(
    a: &Operand<'_>,
    b: &Operand<'_>,
    shifts: Option<&SparseShifts>,
    metric: Metric<'_>,
    x0: MatRef<'_, f64>,
) -> Option<RefinedCluster> {
    let mut pairs = Vec::with_capacity(x0.ncols());
    for k in 0..x0.ncols() {
        let x: Vec<f64> = x0.col(k).iter().copied().collect();
        let rayleigh = dot(&x, &b.product(&x)).over(dot(&x, &a.product(&x))).to_f64();
        let pair = match shifts {
            Some(shifts) => refine_pair_sparse(a, b, shifts, metric, &x, rayleigh),
            None => refine_pair(a, b, metric, &x, rayleigh),
        };
        pairs.push(pair?);
    }
    let omega: Vec<f64> = pairs.iter().map(|p| p.omega_sq).collect();
    let reach: Vec<f64> = pairs
        .iter()
        .map(|p| p.residual_a_inv + f64::EPSILON * p.omega_sq.abs())
        .collect();
    let ascending = omega.windows(2).all(|w| w[0] < w[1]);
    if !ascending || crate::spectrum::clusters(&omega, &reach).len() != pairs.len() {
        return None;
    }
    let mut orthogonality = 0.0_f64;
    for (k, pk) in pairs.iter().enumerate() {
        let apk = a.product(&pk.x);
        for pl in &pairs[..k] {
            orthogonality = orthogonality.max(dot(&pl.x, &apk).to_f64().abs());
        }
    }
    (orthogonality <= f64::EPSILON.sqrt()).then_some(RefinedCluster { pairs, orthogonality })
}

/// M = (XᵀAX)⁻¹ XᵀBX in double-double from the double-double products AX and BX (one vector
/// per column), by Gaussian elimination on the Gram matrix XᵀAX (symmetric positive definite
/// and close to I for an A-orthonormal X, so no pivoting); None if a pivot is not positive.
fn rayleigh_quotient_matrix(x: &Mat<f64>, ax: &[Vec<Dd>], bx: &[Vec<Dd>]) -> Option<Vec<Vec<Dd>>> {
    let p = ax.len();
    let mut gram: Vec<Vec<Dd>> = (0..p)
        .map(|k| (0..p).map(|j| dot(x.col_as_slice(k), &ax[j])).collect())
        .collect();
    let mut m: Vec<Vec<Dd>> = (0..p)
        .map(|k| (0..p).map(|j| dot(x.col_as_slice(k), &bx[j])).collect())
        .collect();
    for k in 0..p {
        let pivot = gram[k][k];
        if pivot.hi.is_nan() || pivot.hi <= 0.0 {
            return None;
        }
        for i in k + 1..p {
            let factor = gram[i][k].over(pivot);
            for j in k..p {
                gram[i][j] = gram[i][j].minus(factor.times(gram[k][j]));
            }
            for j in 0..p {
                m[i][j] = m[i][j].minus(factor.times(m[k][j]));
            }
        }
    }
    for k in (0..p).rev() {
        for j in 0..p {
            let mut v = m[k][j];
            for i in k + 1..p {
                v = v.minus(gram[k][i].times(m[i][j]));
            }
            m[k][j] = v.over(gram[k][k]);
        }
    }
    Some(m)
}

/// Rayleigh–Ritz on the converged cluster (p > 1): the A-orthonormal Ritz vectors of
/// (XᵀBX, XᵀAX) in ascending order, each finished by [`finish_pair`], and their mutual
/// A-orthogonality in double-double.
fn finish_cluster(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    x: Mat<f64>,
    steps: usize,
) -> Option<RefinedCluster> {
    let p = x.ncols();
    if p == 1 {
        return finish_pair(a, b, metric, SplitVector::of(x.col_as_slice(0).to_vec()), steps)
            .map(RefinedCluster::single);
    }
    let ax: Vec<Vec<Dd>> = (0..p).map(|k| a.product(x.col_as_slice(k))).collect();
    let bx: Vec<Vec<Dd>> = (0..p).map(|k| b.product(x.col_as_slice(k))).collect();
    let symmetric = |products: &[Vec<Dd>], i: usize, j: usize| {
        let upper = dot(x.col_as_slice(i), &products[j]).to_f64();
        let lower = dot(x.col_as_slice(j), &products[i]).to_f64();
        0.5 * (upper + lower)
    };
    let gram = Mat::from_fn(p, p, |i, j| symmetric(&ax, i, j));
    let projected = Mat::from_fn(p, p, |i, j| symmetric(&bx, i, j));
    let factor = gram.llt(Side::Lower).ok()?;
    let lg = factor.L();
    let mut c = projected;
    solve_lower_triangular_in_place(lg, c.as_mut(), Par::Seq);
    solve_lower_triangular_in_place(lg, c.as_mut().transpose_mut(), Par::Seq);
    let eigen = c.self_adjoint_eigen(Side::Lower).ok()?;
    let mut v = eigen.U().to_owned();
    solve_upper_triangular_in_place(lg.transpose(), v.as_mut(), Par::Seq);
    let rotated = &x * &v;
    let pairs: Vec<RefinedPair> = (0..p)
        .map(|k| finish_pair(a, b, metric, SplitVector::of(rotated.col_as_slice(k).to_vec()), steps))
        .collect::<Option<_>>()?;
    let mut orthogonality = 0.0_f64;
    for k in 0..p {
        let axk = a.product(&pairs[k].x);
        for j in 0..k {
            orthogonality = orthogonality.max(dot(&pairs[j].x, &axk).to_f64().abs());
        }
    }
    Some(RefinedCluster { pairs, orthogonality })
}

/// A-normalises x, then its double-double Rayleigh quotient, residual and A⁻¹-norm residual;
/// the vector returned is x rounded to double.
fn finish_pair(
    a: &Operand<'_>,
    b: &Operand<'_>,
    metric: Metric<'_>,
    mut x: SplitVector,
    steps: usize,
) -> Option<RefinedPair> {
    let n = a.matrix().nrows();
    let axd = a.product_split(&x);
    let xax = dot_split(&x, &axd);
    if xax.hi.is_nan() || xax.hi <= 0.0 {
        return None;
    }
    x.scale(1.0 / xax.hi.sqrt());
    let axd = a.product_split(&x);
    let bxd = b.product_split(&x);
    let xax = dot_split(&x, &axd);
    let rq = dot_split(&x, &bxd).over(xax);
    let r: Vec<f64> = (0..n).map(|i| bxd[i].minus(rq.times(axd[i])).to_f64()).collect();
    let (r, norm) = metric.definite_residual(r);
    let residual_a_inv = norm / xax.to_f64().sqrt();
    let omega_sq = rq.to_f64();
    if !omega_sq.is_finite() || !residual_a_inv.is_finite() {
        return None;
    }
    Some(RefinedPair {
        x: x.hi,
        omega_sq,
        residual_a_inv,
        residual: r,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::reduce::{Cholesky, back_transform, cholesky, reduce};
    use crate::testing;

    /// A, B, L, Y, ω² and X = L⁻ᵀY.
    type Reduced = (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>, Vec<f64>, Mat<f64>);

    /// The graded 1e12 chain: L, the reduced spectrum and the back-transformed modes.
    fn graded() -> Reduced {
        let stiffness = testing::graded_exponents(16, 12);
        let (a, b) = testing::spring_chain(&stiffness, &[0; 16]);
        reduced_modes(a, b)
    }

    /// A, B, L, the spectrum of C = L⁻¹BL⁻ᵀ (faer's dense solver) and X = L⁻ᵀY.
    fn reduced_modes(a: Mat<f64>, b: Mat<f64>) -> Reduced {
        let n = a.nrows();
        let Cholesky::Factor(l) = cholesky(a.as_ref(), Par::Seq) else {
            panic!("the test's masses are definite");
        };
        let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
        let eig = c.self_adjoint_eigen(Side::Lower).expect("small EVD converges");
        let omega: Vec<f64> = (0..n).map(|i| eig.S()[i]).collect();
        let y = eig.U().to_owned();
        let mut x = y.clone();
        back_transform(l.as_ref(), x.as_mut(), Par::Seq);
        (a, b, l, y, omega, x)
    }

    /// The spectral correction and the bordered LBLᵀ Newton step converge to the same pair: both
    /// Rayleigh quotients agree to a few ulps, and the residuals are of the same size.
    /// The bordered LBLᵀ Newton step from (ω₀², x₀), the reference the other steps must meet.
    fn bordered(a: &Mat<f64>, b: &Mat<f64>, l: &Mat<f64>, x0: &[f64], omega0: f64) -> RefinedPair {
        refine_pair(
            &Operand::new(a.as_ref()),
            &Operand::new(b.as_ref()),
            Metric::Cholesky(LowerFactor::new(l.as_ref())),
            x0,
            omega0,
        )
        .expect("the bordered Newton step converges")
    }

    /// The pair `refined` with its vector rounded to double, measured again: the residual a
    /// double-precision vector can reach (the projected and batched steps iterate in double).
    fn rounded(a: &Mat<f64>, b: &Mat<f64>, l: &Mat<f64>, refined: &RefinedPair) -> RefinedPair {
        let (mass, stiffness) = (Operand::new(a.as_ref()), Operand::new(b.as_ref()));
        let metric = Metric::Cholesky(LowerFactor::new(l.as_ref()));
        finish_pair(&mass, &stiffness, metric, SplitVector::of(refined.x.clone()), 0).expect("the pair is finite")
    }

    /// Both steps reached the same ω², to 4 ulps (mode `i` named in the failure).
    fn assert_same_value(fast: &RefinedPair, slow: &RefinedPair, i: usize) {
        let w = slow.omega_sq;
        assert!(
            (fast.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
            "mode {i}: {} vs {w}",
            fast.omega_sq
        );
    }

    /// The projected step from x₀ on the dense pencil (A, B) with factor L, through `correction`.
    fn projected(
        a: &Mat<f64>,
        b: &Mat<f64>,
        l: &Mat<f64>,
        correction: &mut dyn ReducedCorrection,
        x0: &[f64],
    ) -> Option<RefinedPair> {
        refine_pair_projected(
            &Operand::new(a.as_ref()),
            &Operand::new(b.as_ref()),
            Metric::Cholesky(LowerFactor::new(l.as_ref())),
            correction,
            x0,
        )
    }

    #[test]
    fn spectral_and_bordered_refinement_agree_on_a_graded_chain() {
        let (a, b, l, y, omega, x) = graded();
        for i in 0..4 {
            let mut spectrum = ReducedSpectrum {
                y: y.as_ref(),
                omega_sq: &omega,
                modes: i..i + 1,
            };
            let x0: Vec<f64> = (0..16).map(|r| x[(r, i)]).collect();
            let fast = projected(&a, &b, &l, &mut spectrum, &x0).expect("converges");
            let slow = bordered(&a, &b, &l, &x0, omega[i]);
            assert_same_value(&fast, &slow, i);
            let limit = rounded(&a, &b, &l, &slow).residual_a_inv;
            assert!(
                fast.residual_a_inv <= 4.0 * limit,
                "mode {i}: {:e}",
                fast.residual_a_inv
            );
        }
    }

    /// The sparse bordered step (LU of K = B − ω₀²A, border by block elimination) converges to
    /// the pair of the dense LBLᵀ step on banded pencils of order 64 (stored densely, so taken
    /// sparse): the graded 1e12 chain with lumped masses, and the same chain with a tridiagonal
    /// consistent mass matrix (A's pattern merged into B's); the double-double iterate has a
    /// residual far below that of its rounding to double; a dense B is not taken sparse.
    #[test]
    fn sparse_and_dense_bordered_steps_agree_on_banded_pencils() {
        let n = 64;
        let (lumped, b) = testing::spring_chain(&testing::graded_exponents(n, 12), &vec![0; n]);
        let consistent = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 4.0 / 6.0,
            1 => 1.0 / 6.0,
            _ => 0.0,
        });
        for mass in [lumped, consistent] {
            let (a, b, l, _, omega, x) = reduced_modes(mass, b.clone());
            let (mass, stiffness) = (Operand::new(a.as_ref()), Operand::new(b.as_ref()));
            let shifts = SparseShifts::new(&mass, &stiffness).expect("banded operands are sparse");
            let metric = Metric::Cholesky(LowerFactor::new(l.as_ref()));
            for i in [0, 1, 2, n / 2, n - 1] {
                let x0: Vec<f64> = (0..n).map(|r| x[(r, i)]).collect();
                let fast = refine_pair_sparse(&mass, &stiffness, &shifts, metric, &x0, omega[i]).expect("converges");
                let slow = bordered(&a, &b, &l, &x0, omega[i]);
                assert_same_value(&fast, &slow, i);
                assert!(
                    fast.residual_a_inv <= 4.0 * slow.residual_a_inv,
                    "mode {i}: {:e} vs {:e}",
                    fast.residual_a_inv,
                    slow.residual_a_inv
                );
                // The double-double iterate's residual is far below its rounding's (measured
                // 1e-22–1e-19 against 3e-6–5e-4 on these chains).
                let limit = rounded(&a, &b, &l, &fast).residual_a_inv;
                assert!(
                    fast.residual_a_inv <= 1e-8 * limit,
                    "mode {i}: {:e} vs {limit:e}",
                    fast.residual_a_inv
                );
            }
        }
        let dense = crate::certify::sketch::gaussian(n, n, 3);
        let dense_b = Mat::from_fn(n, n, |i, j| dense[(i, j)] + dense[(j, i)]);
        let identity = Mat::<f64>::identity(n, n);
        assert!(SparseShifts::new(&Operand::new(identity.as_ref()), &Operand::new(dense_b.as_ref())).is_none());
    }

    /// The batch of simple modes converges, on one thread and on two, to the pairs the bordered
    /// Newton step finds one at a time: the batched corrections are the single-mode ones.
    #[test]
    fn batched_simple_modes_agree_with_the_bordered_step() {
        let (a, b, l, y, omega, x) = graded();
        let modes = [0, 1, 2, 3, 5];
        let x0 = Mat::from_fn(16, modes.len(), |r, c| x[(r, modes[c])]);
        for par in [Par::Seq, Par::rayon(2)] {
            let batch = refine_simple_modes(
                &Operand::new(a.as_ref()),
                &Operand::new(b.as_ref()),
                LowerFactor::new(l.as_ref()),
                (y.as_ref(), &omega),
                &modes,
                x0.as_ref(),
                par,
            );
            for (c, &i) in modes.iter().enumerate() {
                let fast = batch[c].as_ref().expect("the batch step converges");
                let start: Vec<f64> = x0.col(c).iter().copied().collect();
                let slow = bordered(&a, &b, &l, &start, omega[i]);
                assert_same_value(fast, &slow, i);
                assert!(
                    fast.residual_a_inv <= 4.0 * rounded(&a, &b, &l, &slow).residual_a_inv,
                    "mode {i}"
                );
                assert!(fast.steps >= 1, "mode {i}");
            }
        }
    }

    /// The values-only correction through Q and (T − ρI)⁻¹ converges without the eigenvectors
    /// Y, to the pair the bordered Newton step finds, from start vectors formed by inverse
    /// iteration on T.
    #[test]
    fn tridiagonal_correction_agrees_with_the_bordered_step() {
        let (a, b, l, _, _, _) = graded();
        let c = reduce(l.as_ref(), b.as_ref(), Par::Seq);
        let (values, mut form) =
            crate::linalg::eigen::symmetric_values_keeping_form(c, Par::Seq, None).expect("values converge");
        let (mut x, z) = form.eigenvectors(&values[..4]).expect("inverse iteration converges");
        back_transform(l.as_ref(), x.as_mut(), Par::Seq);
        for i in 0..4 {
            let x0: Vec<f64> = x.col(i).iter().copied().collect();
            let mut correction = TridiagonalCorrection {
                form: &mut form,
                z: z.subcols(i, 1).to_owned(),
                purified: false,
            };
            let fast = projected(&a, &b, &l, &mut correction, &x0).expect("the tridiagonal correction converges");
            let slow = bordered(&a, &b, &l, &x0, values[i]);
            assert_same_value(&fast, &slow, i);
        }
    }

    /// A spectrum too far from the true one (eigenvalues off by a factor 3) makes the correction
    /// stop contracting; the spectral refinement then declines, and the bordered one still works.
    #[test]
    fn a_wrong_spectrum_is_declined() {
        let (a, b, l, y, omega, x) = graded();
        let wrong: Vec<f64> = omega
            .iter()
            .enumerate()
            .map(|(j, w)| if j == 1 { 3.0 * w } else { *w })
            .collect();
        let mut spectrum = ReducedSpectrum {
            y: y.as_ref(),
            omega_sq: &wrong,
            modes: 0..1,
        };
        // Start from a mixture of modes 0 and 1, so the wrong ω²₁ drives the correction.
        let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)] + 0.3 * x[(r, 1)]).collect();
        assert!(projected(&a, &b, &l, &mut spectrum, &x0).is_none());
        let slow = bordered(&a, &b, &l, &x0, omega[0]);
        let x0: Vec<f64> = (0..16).map(|r| x[(r, 0)]).collect();
        let mut right = ReducedSpectrum {
            y: y.as_ref(),
            omega_sq: &omega,
            modes: 0..1,
        };
        let w = projected(&a, &b, &l, &mut right, &x0).expect("converges").omega_sq;
        assert!(
            (slow.omega_sq - w).abs() <= 4.0 * f64::EPSILON * w,
            "{} vs {w}",
            slow.omega_sq
        );
    }
}
