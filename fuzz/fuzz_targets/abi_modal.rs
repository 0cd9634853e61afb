//! The modal C ABI: dense solves, inertia counts, free responses and sparse solves of
//! det(λA + B) = 0 for small pencils from the input (mostly A positive definite, sometimes
//! singular, indefinite, asymmetric or non-finite), held to the output contract (`oracle`)
//! and to invariants checked against the library's own error bounds:
//! - the spectrum does not depend on the order of the coordinates: the pencil (PAPᵀ, PBPᵀ)
//!   has the same ω², each within the sum of the two stated error bounds;
//! - every returned pair has the residual its backward error states;
//! - the Sturm count below a shift in a clear gap of the spectrum counts the modes below it;
//! - the sparse solver's lowest modes are the dense solver's, within both bounds.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::oracle::{
    Sentinel, binary_exponent, check_status, doubles_untouched, sentinel_doubles, times_power_of_two,
};
use mechanica_fuzz::{Input, trace};

const MAX_ORDER: usize = 8;

/// A pencil of order n (column-major n×n A and B).
struct Pencil {
    n: usize,
    a: Vec<f64>,
    b: Vec<f64>,
}

fn symmetric(input: &mut Input, n: usize, wild: bool) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for j in 0..n {
        for i in j..n {
            let v = if wild { input.any_f64() } else { input.moderate(10.0) };
            m[i + n * j] = v;
            m[j + n * i] = v;
        }
    }
    m
}

fn pencil(input: &mut Input) -> Pencil {
    let n = 1 + input.below(MAX_ORDER);
    let a = match input.u8() % 8 {
        // Mᵀ M + δ I: positive definite.
        0..=4 => {
            let m: Vec<f64> = (0..n * n).map(|_| input.moderate(1.0)).collect();
            let delta = 1e-3 + input.fraction();
            (0..n * n)
                .map(|k| {
                    let (i, j) = (k % n, k / n);
                    (0..n).map(|r| m[r + n * i] * m[r + n * j]).sum::<f64>() + if i == j { delta } else { 0.0 }
                })
                .collect()
        }
        // Diagonal with zeros: massless coordinates.
        5 => (0..n * n)
            .map(|k| {
                if k % (n + 1) == 0 && input.bool() {
                    input.fraction()
                } else {
                    0.0
                }
            })
            .collect(),
        6 => symmetric(input, n, false),
        _ => (0..n * n).map(|_| input.any_f64()).collect(),
    };
    let wild = input.u8() >= 240;
    let b = symmetric(input, n, wild);
    Pencil { n, a, b }
}

impl Pencil {
    /// (PAPᵀ, PBPᵀ) for the permutation `p` (new index i holds old index p[i]).
    fn permuted(&self, p: &[usize]) -> Pencil {
        let n = self.n;
        let map = |m: &[f64]| (0..n * n).map(|k| m[p[k % n] + n * p[k / n]]).collect();
        Pencil {
            n,
            a: map(&self.a),
            b: map(&self.b),
        }
    }
}

/// A solve with all modes and vectors; the result handle is destroyed on drop.
struct Solved {
    handle: *mut mech_modal_result_t,
    modes: Vec<mech_modal_mode_t>,
    vectors: Vec<f64>,
    accuracy: mech_modal_accuracy_t,
}

impl Drop for Solved {
    fn drop(&mut self) {
        unsafe { mech_modal_result_destroy(self.handle) };
    }
}

fn solve(p: &Pencil, input: &mut Input) -> Option<Solved> {
    let mut options = Sentinel::<mech_modal_options_t>::new();
    assert_eq!(unsafe { mech_modal_options_default(options.ptr()) }, MECH_STATUS_OK);
    let mut options = options.value;
    options.refinement = input.enum_i32(3);
    let mut handle = std::ptr::null_mut();
    let residuals = input.enum_i32(2);
    let status =
        unsafe { mech_modal_solve_with_residuals(p.n, p.a.as_ptr(), p.b.as_ptr(), &options, residuals, &mut handle) };
    check_status("mech_modal_solve_with_residuals", status);
    if status != MECH_STATUS_OK {
        assert!(handle.is_null(), "a failed solve wrote a handle");
        return None;
    }
    let (mut count, mut dim) = (0usize, 0usize);
    assert_eq!(
        unsafe { mech_modal_result_size(handle, &mut count, &mut dim) },
        MECH_STATUS_OK
    );
    assert!(
        count <= p.n && dim == p.n,
        "{count} modes of dimension {dim} for order {}",
        p.n
    );
    let mut modes = vec![Sentinel::<mech_modal_mode_t>::new().value; count];
    assert_eq!(
        unsafe { mech_modal_result_modes(handle, modes.as_mut_ptr(), count) },
        MECH_STATUS_OK
    );
    let mut vectors = vec![0.0; count * dim];
    assert_eq!(
        unsafe { mech_modal_result_vectors(handle, vectors.as_mut_ptr(), vectors.len()) },
        MECH_STATUS_OK
    );
    let mut accuracy = Sentinel::<mech_modal_accuracy_t>::new();
    assert_eq!(
        unsafe { mech_modal_result_accuracy(handle, accuracy.ptr()) },
        MECH_STATUS_OK
    );
    let solved = Solved {
        handle,
        modes,
        vectors,
        accuracy: accuracy.value,
    };
    check_accessors(&solved, count, input);
    check_modes(p, &solved);
    Some(solved)
}

/// Short buffers are refused without a write; eigenvalues agree with the modes.
fn check_accessors(s: &Solved, count: usize, input: &mut Input) {
    let capacity = input.below(count + 2);
    let mut lambda = sentinel_doubles(capacity);
    let status = unsafe { mech_modal_result_eigenvalues(s.handle, lambda.as_mut_ptr(), capacity) };
    check_status("mech_modal_result_eigenvalues", status);
    if capacity < count {
        assert_eq!(status, MECH_STATUS_BUFFER_TOO_SMALL);
        assert!(doubles_untouched(&lambda), "a refused eigenvalue buffer was written");
    } else {
        assert_eq!(status, MECH_STATUS_OK);
        for (l, m) in lambda.iter().zip(&s.modes) {
            assert_eq!(l.to_bits(), m.lambda.to_bits(), "eigenvalues and modes disagree");
        }
    }
}

/// Each finite mode: finite numbers, ω² = −λ, and the residual its backward error states.
fn check_modes(p: &Pencil, s: &Solved) {
    let n = p.n;
    for (k, m) in s.modes.iter().enumerate() {
        if m.kind == MECH_MODAL_KIND_INFINITE {
            assert!(
                m.omega_sq == f64::INFINITY && m.lambda == f64::NEG_INFINITY,
                "infinite mode {k} with finite values"
            );
            continue;
        }
        // An error bound of +∞ means "no bound established" (documented for the sparse solver;
        // the dense one gives it when ‖A‖ or ‖B‖ overflows).
        assert!(
            m.lambda.is_finite() && m.omega_sq.is_finite() && m.error_bound >= 0.0 && m.rate.is_finite(),
            "mode {k} not finite: λ {} ω² {} bound {} rate {} kind {}; A = {:?}, B = {:?}",
            m.lambda,
            m.omega_sq,
            m.error_bound,
            m.rate,
            m.kind,
            p.a,
            p.b
        );
        assert_eq!(m.omega_sq, -m.lambda, "ω² ≠ −λ");
        if m.backward_error < 0.0 || !m.error_bound.is_finite() {
            continue;
        }
        let x = &s.vectors[k * n..(k + 1) * n];
        let x_norm = scaled_norm(x);
        // Everything in units of 2ᵉ ≈ |λ|‖A‖ + ‖B‖ (exact powers of two), so that neither the
        // residual nor its scale overflows for pencils and eigenvalues near f64::MAX.
        let (a_norm, b_norm) = (s.accuracy.norm_a, s.accuracy.norm_b);
        let (e_l, e_a, e_b) = (
            binary_exponent(m.lambda),
            binary_exponent(a_norm),
            binary_exponent(b_norm),
        );
        let e = (e_l + e_a).max(e_b);
        let lambda_unit = times_power_of_two(m.lambda, -e_l);
        let mass_term = |a_ij: f64| times_power_of_two(lambda_unit * times_power_of_two(a_ij, -e_a), e_l + e_a - e);
        // The solver decomposes the symmetric parts (entries symmetric within its tolerance are
        // accepted): the residual is theirs. Equal entries are kept (halving a subnormal one
        // rounds).
        let sym = |m: &[f64], i: usize, j: usize| {
            let (x, y) = (m[i + n * j], m[j + n * i]);
            if x == y { x } else { 0.5 * x + 0.5 * y }
        };
        let rows: Vec<f64> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| (mass_term(sym(&p.a, i, j)) + times_power_of_two(sym(&p.b, i, j), -e)) * x[j])
                    .sum()
            })
            .collect();
        let residual = scaled_norm(&rows);
        let scale = (mass_term(a_norm).abs() + times_power_of_two(b_norm, -e)) * x_norm;
        // (η = 0 allows nothing.)
        let from_eta = if m.backward_error == 0.0 {
            0.0
        } else {
            2.0 * m.backward_error * scale
        };
        // Plus the subnormal spacing the residual's products round to (pencils near 1e-310),
        // carried through the shape's entries.
        let subnormal = times_power_of_two(4.0 * n as f64 * f64::from_bits(1) * (1.0 + x_norm) * (1.0 + a_norm), -e);
        let allowed = from_eta + 4.0 * n as f64 * f64::EPSILON * scale + subnormal;
        assert!(
            residual <= allowed,
            "mode {k}: residual {residual:e} above η·scale = {allowed:e} (units of 2^{e}; λ {:e}, η {:e}, kind {}, ‖A‖ {:e}, ‖B‖ {:e}, ‖x‖ {x_norm:e}); A = {:?}, B = {:?}",
            m.lambda,
            m.backward_error,
            m.kind,
            s.accuracy.norm_a,
            s.accuracy.norm_b,
            p.a,
            p.b
        );
    }
}

/// The Euclidean norm without overflow or underflow of the squares (a vector of 1/√a for a
/// subnormal mass a has entries near 1e158).
fn scaled_norm(v: &[f64]) -> f64 {
    let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    largest * v.iter().map(|x| (x / largest).powi(2)).sum::<f64>().sqrt()
}

/// ‖A⁻¹‖_F (≥ ‖A⁻¹‖₂) by Gauss–Jordan elimination with partial pivoting, or None for a
/// matrix singular to working precision or an inverse beyond the double range.
fn inverse_norm(a: &[f64], n: usize) -> Option<f64> {
    let mut m: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..2 * n)
                .map(|j| {
                    if j < n {
                        a[i + n * j]
                    } else {
                        f64::from(u8::from(j - n == i))
                    }
                })
                .collect()
        })
        .collect();
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs()))?;
        if m[pivot][col] == 0.0 || !m[pivot][col].is_finite() {
            return None;
        }
        m.swap(col, pivot);
        let head = m[col].clone();
        for (row, line) in m.iter_mut().enumerate() {
            if row != col {
                let factor = line[col] / head[col];
                line.iter_mut().zip(&head).for_each(|(x, h)| *x -= factor * h);
            }
        }
    }
    let inverse: Vec<f64> = (0..n)
        .flat_map(|i| (n..2 * n).map(move |j| (i, j)))
        .map(|(i, j)| m[i][j] / m[i][i])
        .collect();
    let norm = scaled_norm(&inverse);
    norm.is_finite().then_some(norm)
}

fn finite_omega(s: &Solved) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = s
        .modes
        .iter()
        .filter(|m| m.kind != MECH_MODAL_KIND_INFINITE)
        .map(|m| (m.omega_sq, m.error_bound))
        .collect();
    v.sort_by(|x, y| x.0.total_cmp(&y.0));
    v
}

fn spectra_agree(what: &str, x: &[(f64, f64)], y: &[(f64, f64)]) {
    for ((w1, e1), (w2, e2)) in x.iter().zip(y) {
        let allowed = 2.0 * (e1 + e2) + 1e-13 * (w1.abs() + w2.abs());
        trace!("{what}: {x:?} vs {y:?}");
        assert!(
            (w1 - w2).abs() <= allowed,
            "{what}: ω² {w1} vs {w2} (bounds {e1:e}, {e2:e})"
        );
    }
}

/// The permutation oracle and the Sturm count in a gap.
fn dense(input: &mut Input) {
    let p = pencil(input);
    let Some(first) = solve(&p, input) else { return };
    let mut order: Vec<usize> = (0..p.n).collect();
    for i in (1..p.n).rev() {
        order.swap(i, input.below(i + 1));
    }
    let q = p.permuted(&order);
    trace!(
        "pencil n = {}: A = {:?}, B = {:?}, permutation {order:?}",
        p.n, p.a, p.b
    );
    if let Some(second) = solve(&q, input) {
        let (x, y) = (finite_omega(&first), finite_omega(&second));
        if x.len() == y.len() {
            spectra_agree("permuted coordinates", &x, &y);
        }
    }
    let spectrum = finite_omega(&first);
    if spectrum.len() != p.n || spectrum.len() < 2 {
        return; // the count equals the number of modes only for positive definite A
    }
    let k = input.below(spectrum.len() - 1);
    let ((lo, e_lo), (hi, e_hi)) = (spectrum[k], spectrum[k + 1]);
    let gap = hi - lo;
    if gap <= 4.0 * (e_lo + e_hi) + 1e-8 * (lo.abs() + hi.abs()) {
        return;
    }
    let shift = 0.5 * (lo + hi);
    trace!("spectrum (ω², bound) {spectrum:?}, shift {shift:e}");
    // The count is exact for B − sA up to its rounding: it resolves only modes farther from the
    // shift than about n·u·(‖B‖ + |s|‖A‖)·‖A⁻¹‖ (the documented contract).
    let Some(inverse) = inverse_norm(&p.a, p.n) else { return };
    let resolution = 8.0 * p.n as f64 * f64::EPSILON * (scaled_norm(&p.b) + shift.abs() * scaled_norm(&p.a)) * inverse;
    if shift - lo <= resolution || hi - shift <= resolution {
        return;
    }
    let mut below = Sentinel::<usize>::new();
    let status = unsafe { mech_modal_count_below(p.n, p.a.as_ptr(), p.b.as_ptr(), shift, below.ptr()) };
    check_status("mech_modal_count_below", status);
    if status == MECH_STATUS_OK {
        assert_eq!(below.value, k + 1, "Sturm count below {shift} in the gap ({lo}, {hi})");
    }
}

/// Compressed sparse columns of a dense matrix (nonzeros only, both triangles).
fn csc(n: usize, m: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let (mut ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            if m[i + n * j] != 0.0 {
                rows.push(i);
                vals.push(m[i + n * j]);
            }
        }
        ptr.push(rows.len());
    }
    (ptr, rows, vals)
}

/// The sparse solver against the dense one; sometimes with corrupted column structure.
fn sparse(input: &mut Input) {
    let p = pencil(input);
    let (mut a_ptr, mut a_rows, a_vals) = csc(p.n, &p.a);
    let (b_ptr, b_rows, b_vals) = csc(p.n, &p.b);
    let corrupted = input.u8() >= 224 && !a_rows.is_empty();
    if corrupted {
        let k = input.below(a_rows.len());
        a_rows[k] = input.below(p.n + 3);
        let j = input.below(p.n);
        a_ptr[j] = a_ptr[j].max(input.below(a_rows.len() + 1)).min(a_rows.len());
    }
    let mut options = Sentinel::<mech_modal_sparse_options_t>::new();
    assert_eq!(
        unsafe { mech_modal_sparse_options_default(options.ptr()) },
        MECH_STATUS_OK
    );
    let mut options = options.value;
    options.count = if input.u8() < 240 {
        1 + input.below(p.n)
    } else {
        input.below(2 * p.n + 2)
    };
    if input.u8() >= 224 {
        options.tolerance = input.any_f64();
        options.block_size = input.below(5);
        options.max_runs = input.below(8);
    }
    let count = options.count;
    let mut modes = vec![Sentinel::<mech_modal_mode_t>::new().value; count];
    let mut report = Sentinel::<mech_modal_sparse_report_t>::new();
    let mut details = Sentinel::<mech_modal_sparse_details_t>::new();
    let status = unsafe {
        mech_modal_sparse_solve(
            p.n,
            a_ptr.as_ptr(),
            a_rows.as_ptr(),
            a_vals.as_ptr(),
            b_ptr.as_ptr(),
            b_rows.as_ptr(),
            b_vals.as_ptr(),
            &options,
            modes.as_mut_ptr(),
            std::ptr::null_mut(),
            report.ptr(),
            details.ptr(),
        )
    };
    check_status("mech_modal_sparse_solve", status);
    if status != MECH_STATUS_OK {
        assert!(
            report.untouched() && details.untouched(),
            "a failed sparse solve wrote its report"
        );
        return;
    }
    let sparse: Vec<(f64, f64)> = modes.iter().map(|m| (m.omega_sq, m.error_bound)).collect();
    // An infinite error bound is the solver's "no bound established" (a pair whose θ-interval
    // reaches 0); the frequencies themselves must be finite.
    assert!(
        sparse.iter().all(|(w, e)| w.is_finite() && !e.is_nan() && *e >= 0.0),
        "bad sparse mode: {sparse:?}"
    );
    // Ascending up to the bounds: modes equal within their bounds form a group, in any order.
    assert!(
        sparse.windows(2).all(|w| w[0].0 <= w[1].0 + w[0].1 + w[1].1),
        "sparse modes not ascending: {sparse:?}"
    );
    let Some(dense) = solve(&p, input) else { return };
    let spectrum = finite_omega(&dense);
    trace!("sparse vs dense: A = {:?}, B = {:?}", p.a, p.b);
    // A corrupted structure that is still valid stores another A: nothing to compare with.
    if spectrum.len() == p.n && !corrupted {
        spectra_agree("sparse vs dense", &sparse, &spectrum[..count.min(spectrum.len())]);
    }
}

/// The free response from a solve with all modes: contract and the δ(0) = δ₀ identity.
fn response(input: &mut Input) {
    let p = pencil(input);
    let Some(s) = solve(&p, input) else { return };
    let n = p.n;
    let delta0: Vec<f64> = (0..n)
        .map(|_| {
            if input.bool() {
                input.moderate(1.0)
            } else {
                input.any_f64()
            }
        })
        .collect();
    let delta_dot0: Vec<f64> = (0..n).map(|_| input.moderate(1.0)).collect();
    let times_count = input.below(4);
    let mut times: Vec<f64> = (0..times_count)
        .map(|_| {
            if input.bool() {
                input.moderate(10.0)
            } else {
                input.any_f64()
            }
        })
        .collect();
    times.insert(0, 0.0);
    let capacity = if input.u8() < 230 {
        n * times.len()
    } else {
        input.below(n * times.len() + 1)
    };
    let mut delta = sentinel_doubles(capacity);
    let mut velocity = sentinel_doubles(capacity);
    let mut fit = Sentinel::<mech_modal_response_fit_t>::new();
    let status = unsafe {
        mech_modal_free_response(
            s.handle,
            delta0.as_ptr(),
            delta_dot0.as_ptr(),
            times.as_ptr(),
            times.len(),
            delta.as_mut_ptr(),
            capacity,
            velocity.as_mut_ptr(),
            capacity,
            fit.ptr(),
        )
    };
    check_status("mech_modal_free_response", status);
    if status != MECH_STATUS_OK {
        assert!(
            doubles_untouched(&delta) && doubles_untouched(&velocity) && fit.untouched(),
            "a failed response wrote"
        );
        return;
    }
    assert!(
        delta.iter().chain(&velocity).all(|v| v.is_finite()),
        "non-finite response"
    );
    if s.accuracy.massless == 0 && fit.value.relative_displacement_residual < 1e-6 {
        let scale: f64 = delta0.iter().map(|v| v.abs()).sum::<f64>() + 1e-300;
        for i in 0..n {
            let allowed = 1e-6 * scale + fit.value.max_error_bound;
            assert!(
                (delta[i] - delta0[i]).abs() <= allowed,
                "δ(0)[{i}] = {} but δ₀ = {}",
                delta[i],
                delta0[i]
            );
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let mut steps = 0;
    while !input.is_empty() && steps < 8 {
        steps += 1;
        match input.u8() % 4 {
            0 | 1 => dense(&mut input),
            2 => sparse(&mut input),
            _ => response(&mut input),
        }
    }
    if input.bool() {
        mech_modal_release_scratch();
    }
});
