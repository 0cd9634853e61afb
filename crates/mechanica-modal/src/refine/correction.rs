//! The corrections of the projected Newton step: an approximate inverse of C − ρI on the
//! complement of the refined modes, through the reduced problem's eigenvectors
//! ([`ReducedSpectrum`]) or, for values-only solves, through its tridiagonal form
//! ([`TridiagonalCorrection`]).

use crate::linalg::eigen::TridiagonalForm;
use crate::linalg::eigen::inverse_iteration::{ShiftedTridiagonal, one_norm};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
use std::ops::Range;

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
