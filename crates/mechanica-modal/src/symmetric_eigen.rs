//! Eigen-decomposition C = Y diag(ω²) Yᵀ of the reduced symmetric matrix C = L⁻¹BL⁻ᵀ (8.89
//! after the reduction): a blocked Householder tridiagonalization C = Q T Qᵀ, the tridiagonal
//! divide and conquer T = Z Λ Zᵀ of module `tridiagonal_divide` (faer's as fallback), and faer's
//! blocked Householder application Y = Q Z; values
//! only: the root-free QL/QR iteration of module `tridiagonal_values` on T.
//!
//! Why not faer's `self_adjoint_eigen`: faer 0.24 tridiagonalizes column by column, reading and
//! writing the whole trailing matrix once per column (a rank-2 update fused with a
//! matrix-vector product). Here the panel algorithm of LAPACK `dsytrd`/`dlatrd` (Dongarra,
//! Hammarling & Sorensen, "Block reduction of matrices to condensed forms for eigenvalue
//! computations", J. Comput. Appl. Math. 27, 1989) is used: a panel of [`PANEL`] columns is
//! reduced with one read-only symmetric matrix-vector product per column, and the trailing
//! matrix is updated once per panel by a symmetric rank-2·[`PANEL`] update (half the flops,
//! as matrix products). Only the lower triangle of C is read. From order `PARALLEL_SYMV_FROM` (640)
//! half of every matrix-vector product runs on a spinning helper thread (module `symv_team`):
//! with the pool's sleeping threads, woken once per column, the reduction took 41–47 ms at
//! n = 1000 and 0.29–0.37 s at n = 2000; with the team 34 ms and 0.21–0.24 s (OpenBLAS `dsytrd`
//! 35 ms and 0.22–0.27 s on the same machine). The helper also takes the panel's correction of
//! each product (dlatrd's y −= V Wᵀv + W Vᵀv) and half of each trailing update, which faer's
//! pool did with threads that had gone to sleep during the panel.

use crate::ModalError;
use crate::fork_join::{COLUMNS_PER_CHUNK, by_column_chunks};
use crate::reduce::{columns_holding, subtract_lower_product};
use crate::symv_team::SymvTeam;
use crate::tridiagonal_divide::tridiagonal_divide_and_conquer;
use crate::tridiagonal_values::tridiagonal_eigenvalues;
use crate::tridiagonal_vectors::tridiagonal_eigenvectors;
use faer::linalg::evd::{ComputeEigenvectors, self_adjoint_evd_scratch, tridiagonal_self_adjoint_evd};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_left_in_place_scratch,
    apply_block_householder_sequence_on_the_left_in_place_with_conj,
    apply_block_householder_sequence_transpose_on_the_left_in_place_scratch,
    apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj, make_householder_in_place,
    upgrade_householder_factor,
};
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, ColMut, ColRef, Conj, Mat, MatMut, MatRef, Par};
use std::thread::Thread;

/// Columns reduced per panel before the trailing matrix is updated (LAPACK's `dsytrd` default).
pub const PANEL: usize = 32;

/// Trailing orders below this use one thread for the symmetric matrix-vector product, and
/// smaller matrices no helper thread at all (measured: one thread is faster at order 500, two
/// at order 1000).
const PARALLEL_SYMV_FROM: usize = 640;

/// From this trailing order the trailing update of a team's tridiagonalization is split between
/// the caller and the team's helper (each half one sequential product) instead of faer's pool,
/// whose threads have gone to sleep during the panel and contend with the spinning helper.
const SPLIT_UPDATE_FROM: usize = 128;

/// The eigen-decomposition of a symmetric matrix: values ascending, vectors orthonormal.
#[derive(Debug, Clone)]
pub struct SymmetricEigen {
    /// Eigenvalues, ascending.
    pub values: Vec<f64>,
    /// Orthonormal eigenvectors as columns, in the order of `values` (None: values only).
    pub vectors: Option<Mat<f64>>,
}

/// T = Qᵀ C Q: the diagonal and subdiagonal of T; Q = H₀ H₁ ⋯ H_{n−2} with H_k = I − v_k v_kᵀ/τ_k
/// (faer's convention) stored below the subdiagonal of the matrix that was reduced.
struct Tridiagonal {
    diag: Vec<f64>,
    subdiag: Vec<f64>,
    tau: Vec<f64>,
}

/// Called with T's diagonal and off-diagonal as soon as the tridiagonal form is known (the
/// solver starts its idle-time certificate there, module `idle_certificate`).
pub(crate) type OnTridiagonal<'a> = &'a mut dyn FnMut(&[f64], &[f64]);

/// Eigen-decomposition of the symmetric matrix `c` (only its lower triangle is read).
pub fn symmetric_eigen(c: Mat<f64>, vectors: bool, par: Par) -> Result<SymmetricEigen, ModalError> {
    symmetric_eigen_returning_input(c, vectors, par, None).map(|(eigen, _)| eigen)
}

/// [`symmetric_eigen`], also handing back the input's storage (overwritten by the Householder
/// vectors) so that the caller can reuse it instead of allocating: a fresh n×n matrix costs
/// its page faults (measured 10–20 ms at n = 2000).
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
/// (2.7–3.4× faster than faer's values-only tridiagonal solver, which also fails to converge
/// on some graded matrices).
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

    /// Unit eigenvectors Y = Q Z of the reduced matrix for the ascending eigenvalues `values`
    /// of T (Z by inverse iteration on T, [`crate::tridiagonal_vectors`]), and Z itself.
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
/// chunk sequential: the threads then never wait for each other between blocks of reflectors.
/// Measured at n = 1000, Q·Z of all n columns inside the solve (36 solves alternating with
/// faer's parallel application): median 42.3 against 48.0 ms, paired ratio 0.89 [q1 0.82,
/// q3 0.95]; alone (60 alternated runs, twice) 44.0 / 40.3 against 47.9 / 46.5 ms.
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
    let inside = if z.ncols() < 2 * COLUMNS_PER_CHUNK {
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

/// Reduces the lower triangle of `a` to tridiagonal form T = Qᵀ A Q by panels (`dsytrd`, lower).
fn tridiagonalize(a: &mut Mat<f64>, par: Par) -> Tridiagonal {
    let n = a.nrows();
    let mut t = Tridiagonal {
        diag: vec![0.0; n],
        subdiag: vec![0.0; n],
        tau: vec![f64::INFINITY; n.saturating_sub(1)],
    };
    if par.degree() < 2 || n <= PARALLEL_SYMV_FROM {
        reduce_panels(a, &mut t, None, par);
    } else {
        let team = SymvTeam::new();
        std::thread::scope(|scope| {
            match std::thread::Builder::new().spawn_scoped(scope, || team.serve()) {
                Ok(helper) => {
                    let helper = helper.thread().clone();
                    // Stopped on every exit, also by unwinding: the scope joins the helper.
                    let _stop = team.stop_on_drop(&helper);
                    reduce_panels(a, &mut t, Some((&team, &helper)), par);
                }
                // No thread could be created: one thread does it all.
                Err(_) => reduce_panels(a, &mut t, None, par),
            }
        });
    }
    t.diag[n - 1] = a[(n - 1, n - 1)];
    t.subdiag.truncate(n - 1);
    t
}

/// The panel loop of [`tridiagonalize`]; `team` computes half of every large symmetric product.
fn reduce_panels(a: &mut Mat<f64>, t: &mut Tridiagonal, team: Option<(&SymvTeam, &Thread)>, par: Par) {
    let n = a.nrows();
    let mut w = Mat::<f64>::zeros(n, PANEL);
    // [V W] and [W V] side by side: the trailing update is then one product of inner dimension
    // 2·nb, one pass over the trailing matrix instead of two (measured: tridiagonalization
    // 4–8 % faster at n = 1000, 8–10 % at 2000; panels of 48 or 64 columns were slower).
    let mut vw = Mat::<f64>::zeros(n, 2 * PANEL);
    let mut wv = Mat::<f64>::zeros(n, 2 * PANEL);
    let mut p = 0;
    while p + 1 < n {
        let nb = PANEL.min(n - 1 - p);
        reduce_panel(a, &mut w, p, nb, t, team);
        // A(q.., q..) −= V Wᵀ + W Vᵀ = [V W][W V]ᵀ on the lower triangle, q = p + nb (the
        // syr2k of dsytrd).
        let q = p + nb;
        let m = n - q;
        let v2 = a.as_ref().submatrix(q, p, m, nb);
        let w2 = w.as_ref().submatrix(q, 0, m, nb);
        let mut lhs = vw.as_mut().submatrix_mut(0, 0, m, 2 * nb);
        lhs.rb_mut().subcols_mut(0, nb).copy_from(v2);
        lhs.rb_mut().subcols_mut(nb, nb).copy_from(w2);
        let mut rhs = wv.as_mut().submatrix_mut(0, 0, m, 2 * nb);
        rhs.rb_mut().subcols_mut(0, nb).copy_from(w2);
        rhs.rb_mut().subcols_mut(nb, nb).copy_from(v2);
        let trailing = a.as_mut().submatrix_mut(q, q, m, m);
        match team {
            Some((team, helper)) if m >= SPLIT_UPDATE_FROM => {
                // The helper is awake (between two symmetric products): it takes the lower
                // right triangle, this thread the columns left of it, half the area each.
                let split = columns_holding(m, 0.25 * (m * m) as f64);
                let (left_triangle, _, below_left, mut right_triangle) = trailing.split_at_mut(split, split);
                let (lhs_top, lhs_bottom) = lhs.rb().split_at_row(split);
                let (rhs_top, rhs_bottom) = rhs.rb().split_at_row(split);
                team.beside(
                    helper,
                    &mut || subtract_lower_product(right_triangle.rb_mut(), lhs_bottom, rhs_bottom, Par::Seq),
                    || {
                        subtract_lower_product(left_triangle, lhs_top, rhs_top, Par::Seq);
                        matmul(below_left, Accum::Add, lhs_bottom, rhs_top.transpose(), -1.0, Par::Seq);
                    },
                );
            }
            _ => subtract_lower_product(trailing, lhs.rb(), rhs.rb(), par),
        }
        for k in p..q {
            t.diag[k] = a[(k, k)];
            a[(k + 1, k)] = t.subdiag[k];
        }
        p = q;
    }
}

/// Reduces columns p..p+nb (`dlatrd`, lower): for each column k it applies the panel's earlier
/// reflectors to column k, generates H_k, and stores w_k = τ⁻¹(A v_k − V Wᵀv_k − W Vᵀv_k) −
/// ½τ⁻²(…ᵀv_k) v_k in column k − p of `w`, so that the trailing update is A −= V Wᵀ + W Vᵀ.
/// While the panel is open, A(k+1, k) holds the reflector's unit head; T's subdiagonal goes to
/// `t.subdiag`.
fn reduce_panel(
    a: &mut Mat<f64>,
    w: &mut Mat<f64>,
    p: usize,
    nb: usize,
    t: &mut Tridiagonal,
    team: Option<(&SymvTeam, &Thread)>,
) {
    let n = a.nrows();
    let (mut y, mut partial) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..nb {
        let k = p + i;
        if i > 0 {
            // a(k.., k) −= V(k.., p..k) W(k, 0..i)ᵀ + W(k.., 0..i) V(k, p..k)ᵀ
            let (left, mut right) = a.as_mut().split_at_col_mut(k);
            let v = left.rb().submatrix(k, p, n - k, i);
            let mut col = right.rb_mut().submatrix_mut(k, 0, n - k, 1);
            let wk = w.as_ref().submatrix(k, 0, n - k, i);
            matmul(
                col.rb_mut(),
                Accum::Add,
                v,
                wk.row(0).transpose().as_mat(),
                -1.0,
                Par::Seq,
            );
            matmul(
                col.rb_mut(),
                Accum::Add,
                wk,
                v.row(0).transpose().as_mat(),
                -1.0,
                Par::Seq,
            );
        }
        // H_k annihilates a(k+2.., k).
        let tau = {
            let col = a.col_as_slice_mut(k);
            let (head, tail) = col[k + 1..].split_at_mut(1);
            make_householder_in_place(&mut head[0], ColMut::from_slice_mut(tail)).tau
        };
        t.subdiag[k] = a[(k + 1, k)];
        t.tau[k] = tau;
        a[(k + 1, k)] = 1.0;
        let tau_inv = tau.recip();
        let m = n - k - 1;
        let y = &mut y[..m];
        panel_product(a, w, p, i, y, &mut partial[..m], team);
        let v = &a.col_as_slice(k)[k + 1..];
        let mut dot = 0.0;
        for (yr, vr) in y.iter_mut().zip(v) {
            *yr *= tau_inv;
            dot += *yr * vr;
        }
        let alpha = -0.5 * tau_inv * dot;
        let wk = &mut w.col_as_slice_mut(i)[k + 1..];
        for ((wr, yr), vr) in wk.iter_mut().zip(y.iter()).zip(v) {
            *wr = yr + alpha * vr;
        }
    }
}

/// dlatrd's y for column k = p + i of a panel: y = S v − V (Wᵀ v) − W (Vᵀ v), with
/// S = A(k+1.., k+1..) (lower triangle read, not yet updated by the panel), v = A(k+1.., k),
/// V = A(k+1.., p..k) and W = w(k+1.., 0..i). With a team, from order [`PARALLEL_SYMV_FROM`],
/// the helper computes the right-hand columns of S v and the correction into `partial`, this
/// thread the left-hand columns, so that the two take about the same time.
fn panel_product(
    a: &Mat<f64>,
    w: &Mat<f64>,
    p: usize,
    i: usize,
    y: &mut [f64],
    partial: &mut [f64],
    team: Option<(&SymvTeam, &Thread)>,
) {
    let q = p + i + 1;
    let m = y.len();
    let v = &a.col_as_slice(q - 1)[q..];
    match team {
        Some((team, helper)) if m >= PARALLEL_SYMV_FROM => {
            // The caller takes a quarter of m² plus m·i, the estimated cost of the helper's
            // correction (4 passes over the two m×i panels, held in cache).
            let split = columns_holding(m, 0.25 * (m * m) as f64 + (m * i) as f64);
            team.beside(
                helper,
                &mut || {
                    partial.fill(0.0);
                    symv_columns(a, q, split..m, v, partial);
                    subtract_panel_correction(a, w, p, i, partial);
                },
                || {
                    y.fill(0.0);
                    symv_columns(a, q, 0..split, v, y);
                },
            );
            y.iter_mut().zip(partial.iter()).for_each(|(e, h)| *e += h);
        }
        _ => {
            y.fill(0.0);
            symv_columns(a, q, 0..m, v, y);
            subtract_panel_correction(a, w, p, i, y);
        }
    }
}

/// y −= V (Wᵀ v) + W (Vᵀ v) of [`panel_product`] (nothing for a panel's first column).
fn subtract_panel_correction(a: &Mat<f64>, w: &Mat<f64>, p: usize, i: usize, y: &mut [f64]) {
    if i == 0 {
        return;
    }
    let k = p + i;
    let m = y.len();
    let v_panel = a.as_ref().submatrix(k + 1, p, m, i);
    let w_panel = w.as_ref().submatrix(k + 1, 0, m, i);
    let v = a.as_ref().submatrix(k + 1, k, m, 1);
    let mut coefficients = [0.0; PANEL];
    let mut c = faer::MatMut::from_column_major_slice_mut(&mut coefficients[..i], i, 1);
    let mut y = faer::MatMut::from_column_major_slice_mut(y, m, 1);
    matmul(c.rb_mut(), Accum::Replace, w_panel.transpose(), v, 1.0, Par::Seq);
    matmul(y.rb_mut(), Accum::Add, v_panel, c.rb(), -1.0, Par::Seq);
    matmul(c.rb_mut(), Accum::Replace, v_panel.transpose(), v, 1.0, Par::Seq);
    matmul(y.rb_mut(), Accum::Add, w_panel, c.rb(), -1.0, Par::Seq);
}

/// Adds the contributions of columns `cols` of S = A(q.., q..) to y = S v.
fn symv_columns(a: &Mat<f64>, q: usize, cols: std::ops::Range<usize>, v: &[f64], y: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if crate::dd::fused_available() {
        // SAFETY: the running CPU supports FMA and AVX2, checked just above.
        return unsafe { avx2::symv_columns(a, q, cols, v, y) };
    }
    symv_columns_as::<false>(a, q, cols, v, y);
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! The symmetric matrix-vector kernel with AVX2 and FMA: four columns at a time, so that
    //! each load and store of y serves four columns of S (OpenBLAS's `dsymv` kernels do the same).
    use super::{mul_add, symv_columns_as};
    use faer::Mat;
    use std::arch::x86_64::{
        __m256d, _mm_add_pd, _mm_cvtsd_f64, _mm_unpackhi_pd, _mm256_castpd256_pd128, _mm256_extractf128_pd,
        _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };

    /// Sum of the four lanes.
    #[target_feature(enable = "fma,avx2")]
    fn lane_sum(x: __m256d) -> f64 {
        let pair = _mm_add_pd(_mm256_castpd256_pd128(x), _mm256_extractf128_pd::<1>(x));
        _mm_cvtsd_f64(_mm_add_pd(pair, _mm_unpackhi_pd(pair, pair)))
    }

    /// [`super::symv_columns`] for CPUs with AVX2 and FMA.
    #[target_feature(enable = "fma,avx2")]
    pub(super) fn symv_columns(a: &Mat<f64>, q: usize, cols: std::ops::Range<usize>, v: &[f64], y: &mut [f64]) {
        let m = v.len();
        let mut j = cols.start;
        while j + 4 <= cols.end && j + 4 <= m {
            // The 4×4 diagonal block (lower triangle) in scalar arithmetic.
            let mut dots = [0.0; 4];
            for c in 0..4 {
                let col = &a.col_as_slice(q + j + c)[q + j + c..q + j + 4];
                dots[c] = mul_add::<true>(col[0], v[j + c], dots[c]);
                for (r, s) in col.iter().enumerate().skip(1) {
                    let i = j + c + r;
                    dots[c] = mul_add::<true>(*s, v[i], dots[c]);
                    y[i] = mul_add::<true>(*s, v[j + c], y[i]);
                }
            }
            // Rows j+4..m of the four columns.
            let below = |c: usize| &a.col_as_slice(q + j + c)[q + j + 4..q + m];
            let (s0, rest0) = below(0).as_chunks::<4>();
            let (s1, rest1) = below(1).as_chunks::<4>();
            let (s2, rest2) = below(2).as_chunks::<4>();
            let (s3, rest3) = below(3).as_chunks::<4>();
            let (vb, v_rest) = v[j + 4..].as_chunks::<4>();
            let (yb, y_rest) = y[j + 4..].as_chunks_mut::<4>();
            let vj = [
                _mm256_set1_pd(v[j]),
                _mm256_set1_pd(v[j + 1]),
                _mm256_set1_pd(v[j + 2]),
                _mm256_set1_pd(v[j + 3]),
            ];
            let mut acc = [_mm256_setzero_pd(); 4];
            let rows = s0.iter().zip(s1).zip(s2).zip(s3).zip(vb).zip(yb.iter_mut());
            for (((((c0, c1), c2), c3), vv), yy) in rows {
                // SAFETY: every pointer comes from a [f64; 4] chunk, so each 4-lane load or
                // store stays inside its slice.
                unsafe {
                    let x = _mm256_loadu_pd(vv.as_ptr());
                    let mut out = _mm256_loadu_pd(yy.as_ptr());
                    for (k, chunk) in [c0, c1, c2, c3].into_iter().enumerate() {
                        let s = _mm256_loadu_pd(chunk.as_ptr());
                        acc[k] = _mm256_fmadd_pd(s, x, acc[k]);
                        out = _mm256_fmadd_pd(s, vj[k], out);
                    }
                    _mm256_storeu_pd(yy.as_mut_ptr(), out);
                }
            }
            for (r, (vv, yy)) in v_rest.iter().zip(y_rest.iter_mut()).enumerate() {
                for (c, rest) in [rest0, rest1, rest2, rest3].into_iter().enumerate() {
                    dots[c] = mul_add::<true>(rest[r], *vv, dots[c]);
                    *yy = mul_add::<true>(rest[r], v[j + c], *yy);
                }
            }
            for c in 0..4 {
                y[j + c] += dots[c] + lane_sum(acc[c]);
            }
            j += 4;
        }
        symv_columns_as::<true>(a, q, j..cols.end, v, y);
    }
}

/// x·y + z, with one rounding when `FUSED` (only in code compiled for FMA: elsewhere
/// `f64::mul_add` is a library call).
#[inline(always)]
fn mul_add<const FUSED: bool>(x: f64, y: f64, z: f64) -> f64 {
    if FUSED { x.mul_add(y, z) } else { x * y + z }
}

/// Column j of S (rows j..) contributes s_jj v_j + Σ s_ij v_i to y_j and s_ij v_j to y_i (i > j):
/// one pass over the column does both (a dot product fused with an axpy).
#[inline(always)]
fn symv_columns_as<const FUSED: bool>(a: &Mat<f64>, q: usize, cols: std::ops::Range<usize>, v: &[f64], y: &mut [f64]) {
    const LANES: usize = 8;
    for j in cols {
        let col = &a.col_as_slice(q + j)[q + j..];
        let vj = v[j];
        let (yj, y_below) = y[j..].split_at_mut(1);
        let (below, v_below) = (&col[1..], &v[j + 1..]);
        let mut acc = [0.0; LANES];
        let (s_chunks, s_rest) = below.as_chunks::<LANES>();
        let (v_chunks, v_rest) = v_below.as_chunks::<LANES>();
        let (y_chunks, y_rest) = y_below.as_chunks_mut::<LANES>();
        for ((s, vv), yy) in s_chunks.iter().zip(v_chunks).zip(y_chunks.iter_mut()) {
            for l in 0..LANES {
                acc[l] = mul_add::<FUSED>(s[l], vv[l], acc[l]);
                yy[l] = mul_add::<FUSED>(s[l], vj, yy[l]);
            }
        }
        let mut dot = mul_add::<FUSED>(col[0], vj, 0.0);
        for ((s, vv), yy) in s_rest.iter().zip(v_rest).zip(y_rest.iter_mut()) {
            dot = mul_add::<FUSED>(*s, *vv, dot);
            *yy = mul_add::<FUSED>(*s, vj, *yy);
        }
        let lanes = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
        yj[0] += dot + lanes;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn symmetric(n: usize, seed: u64) -> Mat<f64> {
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
    fn symmetric_products_match_the_dense_product_on_every_kernel_and_split() {
        // Orders around the 4-column blocks and the 4-row chunks, offsets q > 0, odd splits.
        for n in [2, 5, 9, 12, 37, 700] {
            let a = symmetric(n, 7 + n as u64);
            for q in [1, 2, n / 2].into_iter().filter(|&q| q >= 1 && q < n) {
                let m = n - q;
                let v = &a.col_as_slice(q - 1)[q..];
                let exact: Vec<f64> = (0..m)
                    .map(|i| (0..m).map(|j| a[(q + i.max(j), q + i.min(j))] * v[j]).sum())
                    .collect();
                let scale = a.norm_max() * v.iter().map(|x| x.abs()).sum::<f64>();
                let tol = 4.0 * m as f64 * f64::EPSILON * scale;
                let split = m / 3;
                let mut plain = vec![0.0; m];
                symv_columns_as::<false>(&a, q, 0..split, v, &mut plain);
                symv_columns_as::<false>(&a, q, split..m, v, &mut plain);
                let mut dispatched = vec![0.0; m];
                symv_columns(&a, q, 0..split, v, &mut dispatched);
                symv_columns(&a, q, split..m, v, &mut dispatched);
                let mut parallel = vec![0.0; m];
                let mut partial = vec![0.0; m];
                let team = SymvTeam::new();
                std::thread::scope(|scope| {
                    let helper = scope.spawn(|| team.serve()).thread().clone();
                    // Repeated, so that both the helper's and the caller's claim of the second
                    // half occur (which one wins depends on timing).
                    for _ in 0..20 {
                        let w = Mat::<f64>::zeros(0, 0);
                        panel_product(&a, &w, q - 1, 0, &mut parallel, &mut partial, Some((&team, &helper)));
                    }
                    team.stop(&helper);
                });
                for i in 0..m {
                    for (name, got) in [("plain", &plain), ("dispatched", &dispatched), ("parallel", &parallel)] {
                        assert!(
                            (got[i] - exact[i]).abs() <= tol,
                            "n {n} q {q} row {i}: {name} {} vs {}",
                            got[i],
                            exact[i]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn panel_products_subtract_the_pending_update_on_either_thread() {
        // y = S v − V (Wᵀ v) − W (Vᵀ v) against its definition, with the helper taking the
        // correction (order 700 > PARALLEL_SYMV_FROM) and without a team.
        let n = 700;
        let a = symmetric(n, 3);
        let w = symmetric(n, 4);
        for (p, i) in [(0, 1), (0, 5), (3, 31)] {
            let q = p + i + 1;
            let m = n - q;
            let v = &a.col_as_slice(q - 1)[q..];
            let exact: Vec<f64> = (0..m)
                .map(|r| {
                    let sv: f64 = (0..m).map(|j| a[(q + r.max(j), q + r.min(j))] * v[j]).sum();
                    let correction: f64 = (0..i)
                        .map(|c| {
                            let wtv: f64 = (0..m).map(|j| w[(q + j, c)] * v[j]).sum();
                            let vtv: f64 = (0..m).map(|j| a[(q + j, p + c)] * v[j]).sum();
                            a[(q + r, p + c)] * wtv + w[(q + r, c)] * vtv
                        })
                        .sum();
                    sv - correction
                })
                .collect();
            let scale = a.norm_max() * (a.norm_max() + w.norm_max()) * m as f64;
            let tol = 8.0 * m as f64 * f64::EPSILON * scale;
            let (mut alone, mut together, mut partial) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            panel_product(&a, &w, p, i, &mut alone, &mut partial, None);
            let team = SymvTeam::new();
            std::thread::scope(|scope| {
                let helper = scope.spawn(|| team.serve()).thread().clone();
                panel_product(&a, &w, p, i, &mut together, &mut partial, Some((&team, &helper)));
                team.stop(&helper);
            });
            for r in 0..m {
                for (name, got) in [("alone", &alone), ("with the helper", &together)] {
                    assert!(
                        (got[r] - exact[r]).abs() <= tol,
                        "p {p} i {i} row {r}: {name} {} vs {}",
                        got[r],
                        exact[r]
                    );
                }
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
