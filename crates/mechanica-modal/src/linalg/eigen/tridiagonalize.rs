//! The blocked Householder tridiagonalization C = Q T Qᵀ of a symmetric matrix (LAPACK
//! `dsytrd`/`dlatrd`, lower; Dongarra, Hammarling & Sorensen, "Block reduction of matrices to
//! condensed forms for eigenvalue computations", J. Comput. Appl. Math. 27, 1989): a panel of
//! [`crate::Tuning::panel`] columns is reduced with one read-only symmetric matrix-vector product
//! per column, and the trailing matrix is updated once per panel by a symmetric
//! rank-2·[`crate::Tuning::panel`] update (half the flops, as matrix products). Only the lower
//! triangle of C is read. On large trailing matrices half of every matrix-vector product, of its
//! panel correction and of each trailing update runs on a spinning helper thread
//! ([`super::symv_team`]).

use crate::linalg::eigen::symv_team::SymvTeam;
use crate::linalg::reduce::{columns_holding, subtract_lower_product};
use crate::tuning::Tuning;
use faer::linalg::householder::make_householder_in_place;
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, ColMut, Mat, Par};
use std::thread::Thread;

/// T = Qᵀ C Q: the diagonal and subdiagonal of T; Q = H₀ H₁ ⋯ H_{n−2} with H_k = I − v_k v_kᵀ/τ_k
/// (faer's convention) stored below the subdiagonal of the matrix that was reduced.
pub(crate) struct Tridiagonal {
    pub(crate) diag: Vec<f64>,
    pub(crate) subdiag: Vec<f64>,
    /// The reflectors' τ_k.
    pub(crate) tau: Vec<f64>,
}

/// Reduces the lower triangle of `a` to tridiagonal form T = Qᵀ A Q by panels (`dsytrd`, lower).
pub(crate) fn tridiagonalize(a: &mut Mat<f64>, par: Par) -> Tridiagonal {
    let n = a.nrows();
    let mut t = Tridiagonal {
        diag: vec![0.0; n],
        subdiag: vec![0.0; n],
        tau: vec![f64::INFINITY; n.saturating_sub(1)],
    };
    if par.degree() < 2 || n <= Tuning::DEFAULT.parallel_symv_from {
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
    let mut w = Mat::<f64>::zeros(n, Tuning::DEFAULT.panel);
    // [V W] and [W V] side by side: the trailing update is then one product of inner dimension
    // 2·nb, one pass over the trailing matrix instead of two.
    let mut vw = Mat::<f64>::zeros(n, 2 * Tuning::DEFAULT.panel);
    let mut wv = Mat::<f64>::zeros(n, 2 * Tuning::DEFAULT.panel);
    let mut p = 0;
    while p + 1 < n {
        let nb = Tuning::DEFAULT.panel.min(n - 1 - p);
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
            Some((team, helper)) if m >= Tuning::DEFAULT.split_update_from => {
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

/// dlatrd's y for column k = p + i of a panel: y = S v − V (Wᵀ v) − W (Vᵀ v), with S = A(k+1..,
/// k+1..) (lower triangle read, not yet updated by the panel), v = A(k+1.., k), V = A(k+1.., p..k)
/// and W = w(k+1.., 0..i). With a team, from order [`crate::Tuning::parallel_symv_from`], the
/// helper computes the right-hand columns of S v and the correction into `partial`, this thread the
/// left-hand columns, so that the two take about the same time.
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
        Some((team, helper)) if m >= Tuning::DEFAULT.parallel_symv_from => {
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
    let mut coefficients = [0.0; Tuning::DEFAULT.panel];
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
    if crate::runtime::cpu::fused_available() {
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
    use crate::linalg::eigen::tests::symmetric;

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
        // correction (order 700 > `Tuning::parallel_symv_from`) and without a team.
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
}
