//! Eigen-decomposition C = Y diag(ω²) Yᵀ of the reduced symmetric matrix C = L⁻¹BL⁻ᵀ ((8.89)
//! after the reduction, see docs/theory.md): the blocked Householder tridiagonalization
//! C = Q T Qᵀ (`tridiagonalize`), the tridiagonal divide and conquer T = Z Λ Zᵀ
//! (`divide_conquer`, faer's as fallback), and faer's blocked Householder application
//! Y = Q Z; values only: the root-free QL/QR iteration on T (`ql_values`); a few vectors of a
//! values-only solve: inverse iteration on T (`inverse_iteration`).
//!
//! faer 0.24's `self_adjoint_eigen` tridiagonalizes column by column, reading and writing the
//! whole trailing matrix once per column; the panel algorithm of LAPACK `dsytrd` reads it once
//! per matrix-vector product and updates it once per panel, as matrix products, and a spinning
//! helper thread (`symv_team`) takes half of each product on large matrices, where the pool's
//! sleeping threads would be woken once per column (the speed against faer and OpenBLAS is
//! measured in docs/benchmarks.md).

use crate::ModalError;
use crate::linalg::eigen::divide_conquer::tridiagonal_divide_and_conquer;
use crate::linalg::eigen::inverse_iteration::tridiagonal_eigenvectors;
use crate::linalg::eigen::ql_values::tridiagonal_eigenvalues;
use crate::linalg::eigen::tridiagonalize::{Tridiagonal, tridiagonalize};
use crate::runtime::fork_join::by_column_chunks;
use crate::tuning::Tuning;
use faer::linalg::evd::{ComputeEigenvectors, self_adjoint_evd_scratch, tridiagonal_self_adjoint_evd};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_left_in_place_scratch,
    apply_block_householder_sequence_on_the_left_in_place_with_conj,
    apply_block_householder_sequence_transpose_on_the_left_in_place_scratch,
    apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj, upgrade_householder_factor,
};
use faer::{ColMut, ColRef, Conj, Mat, MatMut, MatRef, Par};

pub(crate) mod divide_conquer;
pub(crate) mod inverse_iteration;
pub(crate) mod ql_values;
pub(crate) mod symv_team;
pub(crate) mod tridiagonalize;

/// The eigen-decomposition of a symmetric matrix: values ascending, vectors orthonormal.
#[derive(Debug, Clone)]
pub struct SymmetricEigen {
    /// Eigenvalues, ascending.
    pub values: Vec<f64>,
    /// Orthonormal eigenvectors as columns, in the order of `values` (None: values only).
    pub vectors: Option<Mat<f64>>,
}

/// Called with T's diagonal and off-diagonal as soon as the tridiagonal form is known (the
/// solver starts its idle-time certificate there, `crate::certify::idle_certificate`).
pub(crate) type OnTridiagonal<'a> = &'a mut dyn FnMut(&[f64], &[f64]);

/// Eigen-decomposition of the symmetric matrix `c` (only its lower triangle is read).
pub fn symmetric_eigen(c: Mat<f64>, vectors: bool, par: Par) -> Result<SymmetricEigen, ModalError> {
    symmetric_eigen_returning_input(c, vectors, par, None).map(|(eigen, _)| eigen)
}

/// [`symmetric_eigen`], also handing back the input's storage (overwritten by the Householder
/// vectors) so that the caller can reuse it instead of allocating: a fresh n×n matrix costs
/// its page faults.
pub(crate) fn symmetric_eigen_returning_input(
    mut c: Mat<f64>,
    vectors: bool,
    par: Par,
    on_tridiagonal: Option<OnTridiagonal<'_>>,
) -> Result<(SymmetricEigen, Mat<f64>), ModalError> {
    let n = c.nrows();
    if n == 0 {
        let eigen = SymmetricEigen {
            values: Vec::new(),
            vectors: vectors.then(|| Mat::zeros(0, 0)),
        };
        return Ok((eigen, c));
    }
    if !vectors {
        let (values, form) = symmetric_values_keeping_form(c, par, on_tridiagonal)?;
        return Ok((SymmetricEigen { values, vectors: None }, form.into_storage()));
    }
    let t = tridiagonalize(&mut c, par);
    if let Some(hook) = on_tridiagonal {
        hook(&t.diag, &t.subdiag);
    }
    let (values, mut z) = match tridiagonal_divide_and_conquer(&t.diag, &t.subdiag, par) {
        Some(pairs) => pairs,
        None => faer_tridiagonal_eigen(&t, par)?,
    };
    if n > 1 {
        let factor = block_factor(&c, &t.tau, par);
        apply_reflectors(
            c.as_ref().submatrix(1, 0, n - 1, n - 1),
            factor.as_ref(),
            z.as_mut().subrows_mut(1, n - 1),
            false,
            par,
        );
    }
    Ok((
        SymmetricEigen {
            values,
            vectors: Some(z),
        },
        c,
    ))
}

/// T = Z Λ Zᵀ by faer's divide and conquer: the fallback when the own one
/// ([`tridiagonal_divide_and_conquer`]) declines (a leaf's QL iteration did not converge).
fn faer_tridiagonal_eigen(t: &Tridiagonal, par: Par) -> Result<(Vec<f64>, Mat<f64>), ModalError> {
    let n = t.diag.len();
    let mut mem = faer::dyn_stack::MemBuffer::new(self_adjoint_evd_scratch::<f64>(
        n,
        ComputeEigenvectors::Yes,
        par,
        Default::default(),
    ));
    let stack = faer::dyn_stack::MemStack::new(&mut mem);
    let solve = |diag: &[f64], subdiag: &[f64], stack: &mut faer::dyn_stack::MemStack| {
        let mut values = vec![0.0; n];
        let mut z = Mat::<f64>::zeros(n, n);
        tridiagonal_self_adjoint_evd(
            ColRef::from_slice(diag).as_diagonal(),
            ColRef::from_slice(subdiag).as_diagonal(),
            ColMut::from_slice_mut(&mut values).as_diagonal_mut(),
            Some(z.as_mut()),
            par,
            stack,
            Default::default(),
        )
        .ok()
        .map(|_| (values, z))
    };
    if let Some(pairs) = solve(&t.diag, &t.subdiag, stack) {
        return Ok(pairs);
    }
    // faer's QR iteration (divide and conquer's leaves, n ≤ 128) fails on some tridiagonals
    // graded from tiny at the top to huge at the bottom, and not on the same matrix turned
    // upside down: T = P T' P with P the reversal, so T's eigenvectors are those of T' with
    // their rows reversed.
    let reversed = |v: &[f64]| v.iter().rev().copied().collect::<Vec<f64>>();
    let (values, z_reversed) =
        solve(&reversed(&t.diag), &reversed(&t.subdiag), stack).ok_or(ModalError::NoConvergence { n })?;
    Ok((values, Mat::from_fn(n, n, |i, j| z_reversed[(n - 1 - i, j)])))
}

/// What a values-only decomposition keeps so that a few eigenvectors can be formed afterwards
/// (for the modes whose a-priori bound is too weak, [`crate::values_only`]): T, Q's
/// reflectors in the reduced matrix's storage, and Q's block factor once it is needed.
pub(crate) struct TridiagonalForm {
    t: Tridiagonal,
    reflectors: Mat<f64>,
    factor: Option<Mat<f64>>,
    par: Par,
}

/// Eigenvalues of the symmetric matrix `c` (lower triangle read), ascending, and its
/// tridiagonal form for later eigenvectors. The values come from the root-free QL/QR iteration
/// ([`ql_values`]): faster than faer's values-only tridiagonal solver (measured in
/// docs/benchmarks.md), which also fails to converge on some graded matrices.
pub(crate) fn symmetric_values_keeping_form(
    mut c: Mat<f64>,
    par: Par,
    on_tridiagonal: Option<OnTridiagonal<'_>>,
) -> Result<(Vec<f64>, TridiagonalForm), ModalError> {
    let n = c.nrows();
    let t = if n == 0 {
        Tridiagonal {
            diag: Vec::new(),
            subdiag: Vec::new(),
            tau: Vec::new(),
        }
    } else {
        tridiagonalize(&mut c, par)
    };
    if let Some(hook) = on_tridiagonal {
        hook(&t.diag, &t.subdiag);
    }
    let values = tridiagonal_eigenvalues(&t.diag, &t.subdiag).map_err(|_| ModalError::NoConvergence { n })?;
    let form = TridiagonalForm {
        t,
        reflectors: c,
        factor: None,
        par,
    };
    Ok((values, form))
}

impl TridiagonalForm {
    /// T's diagonal.
    pub(crate) fn diag(&self) -> &[f64] {
        &self.t.diag
    }

    /// T's off-diagonal.
    pub(crate) fn subdiag(&self) -> &[f64] {
        &self.t.subdiag
    }

    /// Unit eigenvectors Y = Q Z of the reduced matrix for the ascending eigenvalues `values` of T
    /// (Z by inverse iteration on T, [`crate::linalg::eigen::inverse_iteration`]), and Z itself.
    pub(crate) fn eigenvectors(&mut self, values: &[f64]) -> Result<(Mat<f64>, Mat<f64>), ModalError> {
        let n = self.t.diag.len();
        let z = tridiagonal_eigenvectors(&self.t.diag, &self.t.subdiag, values)
            .map_err(|_| ModalError::NoConvergence { n })?;
        let z = Mat::from_fn(n, values.len(), |i, j| z[j * n + i]);
        let mut y = z.clone();
        self.apply_q(y.as_mut());
        Ok((y, z))
    }

    /// z ← Q z (T-coordinates to the reduced matrix's).
    pub(crate) fn apply_q(&mut self, z: MatMut<'_, f64>) {
        self.apply(z, false);
    }

    /// w ← Qᵀ w (the reduced matrix's coordinates to T's).
    pub(crate) fn apply_q_transpose(&mut self, w: MatMut<'_, f64>) {
        self.apply(w, true);
    }

    fn apply(&mut self, z: MatMut<'_, f64>, transpose: bool) {
        let n = self.t.diag.len();
        if n < 2 {
            return;
        }
        let factor = self
            .factor
            .get_or_insert_with(|| block_factor(&self.reflectors, &self.t.tau, self.par));
        let basis = self.reflectors.as_ref().submatrix(1, 0, n - 1, n - 1);
        apply_reflectors(basis, factor.as_ref(), z.subrows_mut(1, n - 1), transpose, self.par);
    }

    /// The reduced matrix's storage (n×n), for reuse by the caller.
    pub(crate) fn into_storage(self) -> Mat<f64> {
        self.reflectors
    }
}

/// Z ← Q Z (or Qᵀ Z) for the blocked reflectors `basis` with triangular factors `factor`
/// (faer's layout, [`block_factor`]), on column chunks of Z, one per thread of `par`, each
/// chunk sequential: the threads then never wait for each other between blocks of reflectors
/// (faster than faer's parallel application, measured in docs/benchmarks.md).
fn apply_reflectors(basis: MatRef<'_, f64>, factor: MatRef<'_, f64>, z: MatMut<'_, f64>, transpose: bool, par: Par) {
    type Apply = fn(MatRef<'_, f64>, MatRef<'_, f64>, Conj, MatMut<'_, f64>, Par, &mut faer::dyn_stack::MemStack);
    let (apply, scratch): (Apply, fn(usize, usize, usize) -> faer::dyn_stack::StackReq) = if transpose {
        (
            apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj::<f64>,
            apply_block_householder_sequence_transpose_on_the_left_in_place_scratch::<f64>,
        )
    } else {
        (
            apply_block_householder_sequence_on_the_left_in_place_with_conj::<f64>,
            apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>,
        )
    };
    let bs = factor.nrows();
    // Too few columns for two chunks (the values-only path's few vectors): one chunk, with
    // faer's parallel application inside it.
    let inside = if z.ncols() < 2 * Tuning::DEFAULT.columns_per_chunk {
        par
    } else {
        Par::Seq
    };
    by_column_chunks(z, par, &|chunk| {
        let mut mem = faer::dyn_stack::MemBuffer::new(scratch(chunk.nrows(), bs, chunk.ncols()));
        apply(
            basis,
            factor,
            Conj::No,
            chunk,
            inside,
            faer::dyn_stack::MemStack::new(&mut mem),
        );
    });
}

/// Block size of the compact WY factors used to apply Q (faer's own choice for this order).
fn block_size(n: usize) -> usize {
    faer::linalg::qr::no_pivoting::factor::recommended_block_size::<f64>(n, n)
}

/// The triangular factors of Q's blocks of reflectors (compact WY form, Schreiber & Van Loan
/// 1989) in faer's layout: block j occupies columns j..j+b of a b_max × (n−1) matrix.
fn block_factor(c: &Mat<f64>, tau: &[f64], par: Par) -> Mat<f64> {
    let n = c.nrows();
    let m = n - 1;
    let bs = block_size(n);
    let basis = c.as_ref().submatrix(1, 0, m, m);
    let mut factor = Mat::<f64>::zeros(bs, m);
    let mut j = 0;
    while j < m {
        let b = bs.min(m - j);
        let mut block = factor.as_mut().submatrix_mut(0, j, b, b);
        for k in 0..b {
            block[(k, k)] = tau[j + k];
        }
        upgrade_householder_factor(block, basis.submatrix(j, j, m - j, b), b, 1, par);
        j += b;
    }
    factor
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A random symmetric matrix (entries in (−1, 1)) from `seed`.
    pub(crate) fn symmetric(n: usize, seed: u64) -> Mat<f64> {
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let g = Mat::from_fn(n, n, |_, _| next());
        Mat::from_fn(n, n, |i, j| g[(i, j)] + g[(j, i)])
    }

    /// ‖C Y − Y Λ‖_max / ‖C‖_max and ‖YᵀY − I‖_max: a backward-stable decomposition keeps both
    /// at a small multiple of n·u.
    fn residuals(c: &Mat<f64>, e: &SymmetricEigen) -> (f64, f64) {
        let n = c.nrows();
        let y = e.vectors.as_ref().expect("vectors");
        let cy = c * y;
        let mut res = 0.0_f64;
        for j in 0..n {
            for i in 0..n {
                res = res.max((cy[(i, j)] - y[(i, j)] * e.values[j]).abs());
            }
        }
        let yty = y.transpose() * y;
        let mut orth = 0.0_f64;
        for j in 0..n {
            for i in 0..n {
                orth = orth.max((yty[(i, j)] - if i == j { 1.0 } else { 0.0 }).abs());
            }
        }
        (res / c.norm_max(), orth)
    }

    #[test]
    fn decomposition_is_backward_stable_across_panel_and_thread_boundaries() {
        // Orders around the panel width, the parallel threshold and faer's D&C threshold (128).
        for (n, par) in [
            (1, Par::Seq),
            (2, Par::Seq),
            (3, Par::Seq),
            (31, Par::Seq),
            (32, Par::Seq),
            (33, Par::Seq),
            (65, Par::Seq),
            (200, Par::Seq),
            (333, Par::rayon(2)),
            (1000, Par::rayon(2)),
            (700, Par::rayon(2)),
        ] {
            let c = symmetric(n, n as u64);
            let e = symmetric_eigen(c.clone(), true, par).expect("converges");
            let (res, orth) = residuals(&c, &e);
            let tol = 20.0 * n as f64 * f64::EPSILON;
            assert!(
                res <= tol && orth <= tol,
                "n = {n}: residual {res:.2e}, orthogonality {orth:.2e}"
            );
            // faer's own decomposition is an independent method: the eigenvalues must agree
            // to the same backward-error level (Weyl: |Δλ| ≤ ‖ΔC‖₂).
            let reference = c.self_adjoint_eigenvalues(faer::Side::Lower).expect("faer converges");
            let scale = c.norm_l2().max(f64::MIN_POSITIVE);
            for (mine, theirs) in e.values.iter().zip(&reference) {
                assert!((mine - theirs).abs() <= tol * scale, "n = {n}: {mine} vs {theirs}");
            }
            let values_only = symmetric_eigen(c.clone(), false, par).expect("converges");
            assert!(values_only.vectors.is_none());
            for (a, b) in values_only.values.iter().zip(&e.values) {
                assert!((a - b).abs() <= tol * scale, "n = {n}: values-only {a} vs {b}");
            }
        }
    }

    #[test]
    fn the_helper_thread_changes_no_bit() {
        // Whichever thread computes the second half of a product, it is summed the same way:
        // repeated decompositions on two threads agree bitwise with each other, and the values
        // agree with a sequential run (no helper) within the backward-error level.
        let n = 900;
        let c = symmetric(n, 11);
        let first = symmetric_eigen(c.clone(), true, Par::rayon(2)).expect("converges");
        for _ in 0..3 {
            let again = symmetric_eigen(c.clone(), true, Par::rayon(2)).expect("converges");
            assert_eq!(again.values, first.values);
            assert_eq!(again.vectors, first.vectors);
        }
        let sequential = symmetric_eigen(c.clone(), false, Par::Seq).expect("converges");
        let tol = 20.0 * n as f64 * f64::EPSILON * c.norm_l2();
        for (a, b) in sequential.values.iter().zip(&first.values) {
            assert!((a - b).abs() <= tol, "{a} vs {b}");
        }
    }

    #[test]
    fn tridiagonals_graded_upward_are_solved_upside_down_when_faer_fails() {
        // Graded from 1e-150 at the top to 1e150 at the bottom: faer's QR iteration does not
        // converge on these for n ≤ 128, but does on the reversed matrix.
        for n in [6, 20, 100] {
            let grade = |i: usize| 10f64.powf(-150.0 + 300.0 * i as f64 / (n - 1) as f64);
            let c = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
                0 => grade(i) * if i % 3 == 0 { -0.7 } else { 0.4 },
                1 => grade(i.max(j)) * 0.5,
                _ => 0.0,
            });
            let e = symmetric_eigen(c.clone(), true, Par::Seq).expect("solved upside down");
            let (res, orth) = residuals(&c, &e);
            let tol = 20.0 * n as f64 * f64::EPSILON;
            assert!(
                res <= tol && orth <= tol,
                "n = {n}: residual {res:.2e}, orthogonality {orth:.2e}"
            );
            // The values-only path (own root-free iteration) agrees.
            let values = symmetric_eigen(c.clone(), false, Par::Seq).expect("converges").values;
            for (a, b) in values.iter().zip(&e.values) {
                assert!((a - b).abs() <= tol * c.norm_max(), "n = {n}: {a:e} vs {b:e}");
            }
        }
    }

    #[test]
    fn already_diagonal_and_zero_columns_give_identity_reflectors() {
        // Zero subdiagonal columns make faer's reflector τ = ∞ (H = I); the panel must cope.
        let n = 70;
        let c = Mat::from_fn(n, n, |i, j| if i == j { (n - i) as f64 } else { 0.0 });
        let e = symmetric_eigen(c.clone(), true, Par::Seq).expect("converges");
        // T is already diagonal; the divide and conquer still rounds (within n·u·‖C‖).
        let tol = 4.0 * n as f64 * f64::EPSILON;
        for (k, v) in e.values.iter().enumerate() {
            assert!((v - (k + 1) as f64).abs() <= tol * n as f64, "{v} vs {}", k + 1);
        }
        let (res, orth) = residuals(&c, &e);
        assert!(
            res <= tol && orth <= tol,
            "residual {res:.2e}, orthogonality {orth:.2e}"
        );
        let zero = Mat::<f64>::zeros(40, 40);
        let e = symmetric_eigen(zero.clone(), true, Par::Seq).expect("converges");
        assert!(e.values.iter().all(|v| *v == 0.0));
        let (_, orth) = residuals(&zero, &e);
        assert!(orth <= tol, "orthogonality {orth:.2e}");
    }
}
