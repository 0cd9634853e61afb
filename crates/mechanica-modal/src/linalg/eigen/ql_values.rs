//! Eigenvalues (no vectors) of a real symmetric tridiagonal matrix by the root-free QL/QR
//! iteration of Pal, Walker and Kahan ("On the QL algorithm for symmetric tridiagonal matrices",
//! 1969; Parlett, "The Symmetric Eigenvalue Problem", §8.15), organised as LAPACK `dsterf`:
//! split into unreduced blocks, scale each block into a safe range, iterate on the squared
//! off-diagonals with a Wilkinson-type shift, and run QL or QR on a block depending on which
//! end has the larger diagonal entry.

/// Unit roundoff 2⁻⁵³.
const EPS: f64 = f64::EPSILON / 2.0;
/// Its square, for the splitting test on squared off-diagonals.
const EPS2: f64 = EPS * EPS;
/// Upper end of the safe range, √(1/tiny)/3 ≈ 2.2e153: squares and sums of squares cannot overflow.
const SSFMAX: f64 = f64::from_bits((1023 + 511) << 52) / 3.0;
/// Lower end of the safe range, √tiny/eps² ≈ 1.5e-122: squares keep full precision.
const SSFMIN: f64 = f64::from_bits((1023 - 405) << 52);

/// Eigenvalues of the symmetric tridiagonal matrix with diagonal `diag` and off-diagonal `offdiag`
/// (len n−1), ascending. Err(index) if the iteration did not converge (an unreduced block starting
/// at `index` still had a nonzero off-diagonal after 30·n sweeps).
pub(crate) fn tridiagonal_eigenvalues(diag: &[f64], offdiag: &[f64]) -> Result<Vec<f64>, usize> {
    let n = diag.len();
    debug_assert_eq!(offdiag.len(), n.saturating_sub(1));
    let mut d = diag.to_vec();
    let mut e = offdiag.to_vec();
    e.resize(n.saturating_sub(1), 0.0);
    let max_sweeps = 30 * n;
    let mut sweeps = 0;
    let mut start = 0;
    while start < n {
        // The block ends at the first negligible off-diagonal: |e_i| ≤ √|d_i|·√|d_{i+1}|·eps.
        let mut end = start;
        while end + 1 < n {
            let t = e[end].abs();
            if t == 0.0 || t <= d[end].abs().sqrt() * d[end + 1].abs().sqrt() * EPS {
                e[end] = 0.0;
                break;
            }
            end += 1;
        }
        if end > start && !solve_block(&mut d[start..=end], &mut e[start..end], &mut sweeps, max_sweeps) {
            return Err(start);
        }
        start = end + 1;
    }
    d.sort_unstable_by(f64::total_cmp);
    Ok(d)
}

/// The number of eigenvalues of T (diagonal `d`, off-diagonal `e`) below x, from the signs of
/// the LDLᵀ pivots of T − xI (Sylvester's law of inertia; a zero pivot is taken as +tiny).
pub(crate) fn sturm_count(d: &[f64], e: &[f64], x: f64) -> usize {
    let Some(&first) = d.first() else {
        return 0;
    };
    let mut pivot = first - x;
    let mut count = usize::from(pivot < 0.0);
    for i in 1..d.len() {
        let safe = if pivot == 0.0 { f64::MIN_POSITIVE } else { pivot };
        pivot = d[i] - x - e[i - 1] * (e[i - 1] / safe);
        count += usize::from(pivot < 0.0);
    }
    count
}

/// The lowest eigenvalue of T (diagonal `d`, off-diagonal `e`), by bisection on Sturm counts
/// inside T's Gershgorin interval, to a few units of roundoff of ‖T‖ (n·64 flops per step);
/// None for an empty or non-finite T.
pub(crate) fn lowest_eigenvalue(d: &[f64], e: &[f64]) -> Option<f64> {
    let n = d.len();
    let radius = |i: usize| {
        let left = if i > 0 { e[i - 1].abs() } else { 0.0 };
        let right = if i + 1 < n { e[i].abs() } else { 0.0 };
        left + right
    };
    let mut lower = (0..n).map(|i| d[i] - radius(i)).fold(f64::INFINITY, f64::min);
    let mut upper = (0..n).map(|i| d[i] + radius(i)).fold(f64::NEG_INFINITY, f64::max);
    if n == 0 || !lower.is_finite() || !upper.is_finite() {
        return None;
    }
    let width = 4.0 * EPS * lower.abs().max(upper.abs());
    // Invariant: fewer than one eigenvalue below `lower`, at least one below `upper` (+ width).
    upper += width;
    for _ in 0..128 {
        let middle = 0.5 * (lower + upper);
        if upper - lower <= width || middle <= lower || middle >= upper {
            break;
        }
        if sturm_count(d, e, middle) >= 1 {
            upper = middle;
        } else {
            lower = middle;
        }
    }
    Some(0.5 * (lower + upper))
}

/// Replaces the diagonal `d` of one unreduced block (off-diagonal `e`) by its eigenvalues, in
/// no particular order; false when the shared sweep budget ran out first.
fn solve_block(d: &mut [f64], e: &mut [f64], sweeps: &mut usize, max_sweeps: usize) -> bool {
    let norm = d.iter().chain(e.iter()).fold(0.0_f64, |m, x| m.max(x.abs()));
    // A power of two near the target range, so that scaling and unscaling are exact.
    let scale = match norm {
        x if x > SSFMAX => power_of_two_below(SSFMAX / x),
        x if x < SSFMIN && x > 0.0 => power_of_two_below(SSFMIN / x),
        _ => 1.0,
    };
    if scale != 1.0 {
        d.iter_mut().chain(e.iter_mut()).for_each(|x| *x *= scale);
    }
    e.iter_mut().for_each(|x| *x *= *x);
    // QR on the block is QL on the reversed block (the same spectrum). The block is turned so
    // that its larger end, measured by |d| + |e| there, is at the top, where QL deflates.
    // `dsterf` compares |d| alone and deflates at the smaller end, which on a zero diagonal with
    // off-diagonals graded over 1e±150 from the top down loses eigenvalues to 1e-8·‖T‖; this
    // rule keeps every orientation of graded, zero- and alternating-diagonal matrices accurate
    // (the test below checks them against Sturm counts).
    let k = d.len();
    let top = d[0].abs() + e[0].sqrt();
    let bottom = d[k - 1].abs() + e[k - 2].sqrt();
    if bottom > top {
        d.reverse();
        e.reverse();
    }
    let converged = root_free_ql(d, e, sweeps, max_sweeps);
    if scale != 1.0 {
        let unscale = 1.0 / scale;
        d.iter_mut().for_each(|x| *x *= unscale);
    }
    converged
}

/// The largest power of two ≤ `x` (a positive normal number).
fn power_of_two_below(x: f64) -> f64 {
    f64::from_bits(x.to_bits() & 0xfff0_0000_0000_0000)
}

/// Root-free QL iteration (Pal–Walker–Kahan; Parlett §8.15) on a block with diagonal `d` and
/// squared off-diagonal `e2`; eigenvalues are deflated at the top. False when `sweeps` reached
/// `max_sweeps` before the block was diagonal.
fn root_free_ql(d: &mut [f64], e2: &mut [f64], sweeps: &mut usize, max_sweeps: usize) -> bool {
    let k = d.len();
    let mut l = 0;
    while l < k {
        // The active block is l..=m, m at the first negligible e²_m ≤ eps²·|d_m·d_{m+1}|.
        let mut m = l;
        while m + 1 < k {
            if e2[m] <= EPS2 * (d[m] * d[m + 1]).abs() {
                e2[m] = 0.0;
                break;
            }
            m += 1;
        }
        if m == l {
            l += 1;
            continue;
        }
        if m == l + 1 {
            (d[l], d[l + 1]) = symmetric_2x2_eigenvalues(d[l], e2[l].sqrt(), d[l + 1]);
            e2[l] = 0.0;
            l += 2;
            continue;
        }
        if *sweeps >= max_sweeps {
            return false;
        }
        *sweeps += 1;
        // Wilkinson-type shift: the eigenvalue of the top 2×2 block closer to d_l.
        let e_top = e2[l].sqrt();
        let g = (d[l + 1] - d[l]) / (2.0 * e_top);
        let sigma = d[l] - e_top / (g + g.hypot(1.0).copysign(g));
        // One root-free sweep from the bottom to the top of the active block.
        let (d, e2) = (&mut d[l..=m], &mut e2[l..m]);
        let last = m - l;
        let mut gamma = d[last] - sigma;
        let mut p = gamma * gamma;
        let (mut c, mut s) = (1.0, 0.0);
        for i in (0..last).rev() {
            let bb = e2[i];
            let r = p + bb;
            if i + 1 < last {
                e2[i + 1] = s * r;
            }
            let c_old = c;
            c = p / r;
            let c_inv = r / p;
            s = bb / r;
            let gamma_old = gamma;
            let alpha = d[i];
            gamma = c * (alpha - sigma) - s * gamma_old;
            d[i + 1] = gamma_old + (alpha - gamma);
            // p = γ²/c, multiplying by 1/c (computed alongside c) shortens the dependency chain.
            p = if c_inv < f64::INFINITY {
                gamma * gamma * c_inv
            } else if c != 0.0 {
                gamma * gamma / c
            } else {
                c_old * bb
            };
        }
        e2[0] = s * p;
        d[0] = sigma + gamma;
    }
    true
}

/// Eigenvalues of the symmetric 2×2 matrix [a b; b c], the larger in magnitude first; the
/// smaller is det/λ₁ so that it keeps its relative accuracy.
fn symmetric_2x2_eigenvalues(a: f64, b: f64, c: f64) -> (f64, f64) {
    let sum = a + c;
    let rt = (a - c).abs().hypot(2.0 * b.abs());
    let (big, small) = if a.abs() > c.abs() { (a, c) } else { (c, a) };
    if sum == 0.0 {
        return (0.5 * rt, -0.5 * rt);
    }
    let rt1 = 0.5 * (sum + rt.copysign(sum));
    (rt1, (big / rt1) * small - (b / rt1) * b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::{Mat, Side};
    use std::f64::consts::PI;

    /// ‖T‖_∞ (the largest absolute row sum), an upper bound of the spectral norm.
    fn norm_inf(d: &[f64], e: &[f64]) -> f64 {
        let e_abs = |i: Option<usize>| i.and_then(|i| e.get(i)).map_or(0.0, |x| x.abs());
        (0..d.len()).fold(0.0, |m, i| m.max(d[i].abs() + e_abs(Some(i)) + e_abs(i.checked_sub(1))))
    }

    /// Asserts that the computed eigenvalues match `reference` (any order) within c·n·eps·‖T‖_∞.
    fn check(d: &[f64], e: &[f64], mut reference: Vec<f64>, c: f64) {
        let got = tridiagonal_eigenvalues(d, e).expect("converges");
        reference.sort_unstable_by(f64::total_cmp);
        let tol = c * d.len() as f64 * f64::EPSILON * norm_inf(d, e);
        assert_eq!(got.len(), reference.len());
        for (x, y) in got.iter().zip(&reference) {
            assert!(x.is_finite() && (x - y).abs() <= tol, "{x:e} vs {y:e}, tol {tol:e}");
        }
    }

    /// Eigenvalues of the same matrix from faer's dense solver (an independent method).
    fn dense_reference(d: &[f64], e: &[f64]) -> Vec<f64> {
        let t = Mat::from_fn(d.len(), d.len(), |i, j| match i.abs_diff(j) {
            0 => d[i],
            1 => e[i.min(j)],
            _ => 0.0,
        });
        t.self_adjoint_eigenvalues(Side::Lower).expect("faer converges")
    }

    /// tridiag(b, a, b) of order n and its spectrum a + 2b·cos(kπ/(n+1)), k = 1..n.
    fn toeplitz(n: usize, a: f64, b: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let cos = |k: usize| (k as f64 * PI / (n + 1) as f64).cos();
        (
            vec![a; n],
            vec![b; n.saturating_sub(1)],
            (1..=n).map(|k| a + 2.0 * b * cos(k)).collect(),
        )
    }

    /// A linear congruential generator, uniform in [−1, 1).
    fn lcg(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    #[test]
    fn closed_forms() {
        // tridiag(−1, 2, −1) (2 − 2cos(kπ/(n+1))), also scaled by 1e300 and 1e-300, and
        // tridiag(1e-13, 1, 1e-13), whose couplings must not be split off (that would cost ~1e-13).
        for n in [1, 2, 3, 10, 500, 2000] {
            for (a, b) in [(2.0, -1.0), (2e300, -1e300), (2e-300, -1e-300), (1.0, 1e-13)] {
                let (d, e, values) = toeplitz(n, a, b);
                check(&d, &e, values, 4.0);
            }
        }
        assert_eq!(tridiagonal_eigenvalues(&[], &[]), Ok(vec![]));
    }

    #[test]
    fn wilkinson_w21_plus() {
        let d: Vec<f64> = (0..21).map(|i: i32| f64::from((10 - i).abs())).collect();
        check(&d, &[1.0; 20], dense_reference(&d, &[1.0; 20]), 8.0);
    }

    #[test]
    fn random_against_dense() {
        let mut rng = lcg(0x5eed);
        for n in (1..=60).chain([1000]) {
            let d: Vec<f64> = (0..n).map(|_| rng()).collect();
            let mut e: Vec<f64> = (1..n).map(|_| rng()).collect();
            check(&d, &e, dense_reference(&d, &e), 8.0);
            // Some zero off-diagonals: the matrix splits into blocks.
            e.iter_mut().step_by(7).for_each(|x| *x = 0.0);
            check(&d, &e, dense_reference(&d, &e), 8.0);
            // Graded entries from 1e150 down to 1e-150, random signs, and the reverse grading.
            // faer's dense solver does not converge on the increasing grading (n ≥ 6), so both
            // are checked against it on the decreasing one (the same spectrum).
            let grade = |i: usize| 10f64.powf(150.0 - 300.0 * i as f64 / (n - 1).max(1) as f64);
            let d: Vec<f64> = (0..n).map(|i| rng() * grade(i)).collect();
            let e: Vec<f64> = (1..n).map(|i| rng() * grade(i)).collect();
            let reference = dense_reference(&d, &e);
            check(&d, &e, reference.clone(), 8.0);
            let reversed = |v: &[f64]| v.iter().rev().copied().collect::<Vec<f64>>();
            check(&reversed(&d), &reversed(&e), reference, 8.0);
        }
    }

    #[test]
    fn extreme_mixed_entries_stay_finite() {
        // Entries from subnormal to 1e306: no NaN, and the trace and the Frobenius norm are kept.
        let mut rng = lcg(7);
        for n in [2, 3, 17, 100] {
            let mut pick = || rng() * [1e306, 1.0, 1e-300, 5e-324, 0.0][(rng().abs() * 5.0) as usize];
            let (d, e): (Vec<f64>, Vec<f64>) = ((0..n).map(|_| pick()).collect(), (1..n).map(|_| pick()).collect());
            let got = tridiagonal_eigenvalues(&d, &e).expect("converges");
            let (norm, tol) = (norm_inf(&d, &e), 8.0 * n as f64 * f64::EPSILON);
            assert!(got.iter().all(|x| x.is_finite()));
            assert!((got.iter().sum::<f64>() - d.iter().sum::<f64>()).abs() <= tol * norm);
            let sq = |x: &f64| (x / norm).powi(2);
            let frobenius = d.iter().map(sq).sum::<f64>() + 2.0 * e.iter().map(sq).sum::<f64>();
            assert!((got.iter().map(sq).sum::<f64>() - frobenius).abs() <= tol);
        }
    }

    #[test]
    fn repeated_eigenvalues_and_zero() {
        // Four identical tridiag(−1, 2, −1) blocks of order 5 with zero couplings.
        let (d5, _, v5) = toeplitz(5, 2.0, -1.0);
        let e: Vec<f64> = (0..19).map(|i| if i % 5 == 4 { 0.0 } else { -1.0 }).collect();
        check(&d5.repeat(4), &e, v5.repeat(4), 4.0);
        for n in [1, 2, 3, 50] {
            let zeros = vec![0.0; n];
            assert_eq!(tridiagonal_eigenvalues(&zeros, &zeros[1..]), Ok(zeros.clone()));
        }
    }

    #[test]
    fn the_lowest_eigenvalue_by_bisection_matches_the_ql_values() {
        // The fixed chain (closed form 2 − 2cos(kπ/(n+1))), a graded matrix and one with a
        // negative spectrum: the bisected lowest value agrees with QL's to a few u·‖T‖.
        let n = 200;
        let chain = (vec![2.0; n], vec![-1.0; n - 1]);
        let graded: (Vec<f64>, Vec<f64>) = (
            (0..n).map(|i| 10f64.powi(i as i32 % 17 - 8)).collect(),
            (0..n - 1).map(|i| 0.3 * 10f64.powi(i as i32 % 13 - 6)).collect(),
        );
        let negative: (Vec<f64>, Vec<f64>) = ((0..n).map(|i| -5.0 - i as f64).collect(), vec![2.5; n - 1]);
        for (d, e) in [chain, graded, negative] {
            let values = tridiagonal_eigenvalues(&d, &e).expect("converges");
            let norm = d.iter().chain(&e).fold(0.0_f64, |m, x| m.max(x.abs()));
            let lowest = lowest_eigenvalue(&d, &e).expect("finite");
            assert!(
                (lowest - values[0]).abs() <= 16.0 * EPS * norm,
                "{lowest} vs {}",
                values[0]
            );
        }
        let exact = 2.0 - 2.0 * (std::f64::consts::PI / (n as f64 + 1.0)).cos();
        let lowest = lowest_eigenvalue(&vec![2.0; n], &vec![-1.0; n - 1]).expect("finite");
        assert!((lowest - exact).abs() <= 64.0 * EPS * 4.0, "{lowest} vs {exact}");
        assert_eq!(lowest_eigenvalue(&[], &[]), None);
        assert_eq!(lowest_eigenvalue(&[f64::NAN], &[]), None);
    }

    #[test]
    fn graded_over_300_decades_in_every_orientation() {
        // Off-diagonals graded 1e-150 … 1e150 with a zero, graded, alternating or 3× graded
        // diagonal, both ways up: the i-th value must have exactly i Sturm-counted eigenvalues
        // below it and i + 1 below it plus 1e-12·‖T‖ (`dsterf`'s |d|-only orientation rule
        // misses that by up to 1e-8·‖T‖ on the zero diagonal graded downwards).
        let n = 1000;
        let grade = |i: usize, m: usize| 10f64.powf(-150.0 + 300.0 * i as f64 / (m - 1) as f64);
        for variant in 0..8 {
            let mut e: Vec<f64> = (0..n - 1).map(|i| grade(i, n - 1)).collect();
            let mut d: Vec<f64> = match variant / 2 {
                0 => vec![0.0; n],
                1 => (0..n).map(|i| grade(i, n)).collect(),
                2 => (0..n)
                    .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 } * grade(i, n))
                    .collect(),
                _ => (0..n).map(|i| 3.0 * grade(i, n)).collect(),
            };
            if variant % 2 == 1 {
                d.reverse();
                e.reverse();
            }
            let slack = 1e-12 * norm_inf(&d, &e);
            let got = tridiagonal_eigenvalues(&d, &e).expect("converges");
            for (i, &v) in got.iter().enumerate() {
                let (below, above) = (sturm_count(&d, &e, v - slack), sturm_count(&d, &e, v + slack));
                assert!(
                    below <= i && i < above,
                    "variant {variant}: value {i} = {v:e}, counts {below}, {above}"
                );
            }
        }
    }
}
