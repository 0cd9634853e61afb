//! Sylvester inertia (Sturm) counts of the pencil: how many eigenvalues ω² = −λ of
//! det(λA + B) = 0 ((8.89), see docs/theory.md) lie below a shift s.
//!
//! With A positive definite, B − sA is congruent to diag(ω²_k − s) (take X A-orthonormal:
//! Xᵀ(B − sA)X = diag(ω²_k − s)), so by Sylvester's law of inertia the number of negative
//! eigenvalues of B − sA equals the number of modes with ω² < s. The negative eigenvalues are
//! counted on the block-diagonal factor of a Bunch–Kaufman LBLᵀ factorization (faer).

use crate::linalg::powers_of_two::{exponent, times_power_of_two};
use crate::{ModalError, PencilProblem};
use faer::{Mat, Side};

/// The inertia of B − sA: how many modes have ω² below, at (numerically), or above the shift s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaCount {
    /// The shift s, in the units of ω² (rad²/s²).
    pub shift: f64,
    /// Number of negative eigenvalues of B − sA = number of modes with ω² < s.
    pub below: usize,
    /// Number of zero pivots (s is an eigenvalue to working precision, or the pencil is singular).
    pub zero: usize,
    /// Number of positive eigenvalues of B − sA = number of modes with ω² > s.
    pub above: usize,
}

/// Counts the modes with ω² below `shift` (ω² = −λ, λ of det(λA + B) = 0), certified by the
/// inertia of an LBLᵀ factorization of B − shift·A, scaled by a power of two (any finite pencil
/// and shift). Exact for the factorized matrix; the count can be off only for modes within about
/// n·u·(‖B‖ + |s|‖A‖)‖A⁻¹‖ of the shift.
pub fn count_below(problem: &PencilProblem, shift: f64) -> Result<InertiaCount, ModalError> {
    if !shift.is_finite() {
        return Err(ModalError::BadShift(shift));
    }
    let (below, zero, above) = inertia_of(&scaled_shifted(problem, shift));
    Ok(InertiaCount {
        shift,
        below,
        zero,
        above,
    })
}

/// (B − sA)·2⁻ᵉ with 2ᵉ near the largest of max|b_ij| and |s|·max|a_ij|: a positive multiple,
/// so of the same inertia, whose entries and factorization neither over- nor underflow for
/// pencils and shifts anywhere in the double range (B − sA itself overflows for |s|·a_ij beyond
/// f64::MAX, and the pivots' products for entries beyond 1e154). The scalings are exact but for
/// entries pushed below the normal range, which are then below u times the largest.
fn scaled_shifted(problem: &PencilProblem, shift: f64) -> Mat<f64> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    let largest = |m: faer::MatRef<'_, f64>| {
        (0..n)
            .flat_map(|j| (0..n).map(move |i| m[(i, j)].abs()))
            .fold(0.0, f64::max)
    };
    let exponent_of = |x: f64| if x == 0.0 { None } else { Some(exponent(x)) };
    let (e_b, e_a, e_s) = (exponent_of(largest(b)), exponent_of(largest(a)), exponent_of(shift));
    let e_sa = e_a.zip(e_s).map(|(x, y)| x + y);
    let e = e_b.max(e_sa).unwrap_or(0);
    let (e_a, e_s) = (e_a.unwrap_or(0), e_s.unwrap_or(0));
    let unit_shift = times_power_of_two(shift, -e_s);
    // The shift's factor 2^(e_a + e_s − e)·s/2^e_s ≤ 2 in magnitude; 2^−e and 2^−e_a are single
    // normal doubles except at the ends of the range, where each entry is scaled in steps.
    let shift_factor = times_power_of_two(unit_shift, e_a + e_s - e);
    let normal = |x: i32| (-1021..=1022).contains(&x);
    if normal(e) && normal(e_a) {
        let (b_factor, a_factor) = (times_power_of_two(1.0, -e), times_power_of_two(1.0, -e_a));
        return Mat::from_fn(n, n, |i, j| {
            b[(i, j)] * b_factor - (a[(i, j)] * a_factor) * shift_factor
        });
    }
    Mat::from_fn(n, n, |i, j| {
        times_power_of_two(b[(i, j)], -e) - times_power_of_two(a[(i, j)], -e_a) * shift_factor
    })
}

/// Whether every mode has ω² > `shift`: B − shift·A is positive definite to working precision
/// (its Cholesky factorization succeeds with no negligible pivot). The count 0 it certifies
/// costs a third of the LBLᵀ of [`count_below`] (n³/3 flops at Cholesky speed).
/// The factorization works in kept storage ([`crate::runtime::scratch`]), given back afterwards.
pub(crate) fn all_above(problem: &PencilProblem, shift: f64, par: faer::Par) -> bool {
    let mut k = shifted_lower(problem, shift);
    let positive = crate::linalg::reduce::factor_in_place(k.as_mut(), par).is_ok();
    crate::runtime::scratch::give_back(k);
    positive
}

/// Whether B itself is proven positive definite: by the scaled and shifted Cholesky test of
/// [`proven_positive_definite`], or, where that cannot decide and B's pattern is a forest
/// (spring chains and trees), by the extended-precision proof of [`super::forest`]. Then, by
/// Sylvester's law, no mode has ω² ≤ 0: the pencil has neither rigid-body nor unstable modes.
pub(crate) fn stiffness_is_definite(problem: &PencilProblem, par: faer::Par) -> bool {
    proven_positive_definite(problem.b(), par) || super::forest::forest_is_positive_definite(problem.b())
}

/// Whether the symmetric matrix M (lower triangle read) is proven positive definite, whatever
/// its grading (docs/theory.md, §6, item 5, "Definiteness proofs"): with D = diag(2^{s_j}),
/// 2^{2s_j} within a factor two of m_jj, H = D⁻¹MD⁻¹ is formed exactly, and the floating-point
/// Cholesky factorization L̂L̂ᵀ = G + E of G = H − c·diag(H) must run to completion with
/// positive pivots. Then |E| ≤ γ|L̂||L̂ᵀ| (Higham, Theorem 10.3, whatever the order of the
/// inner products; γ = γ_{2n+2} = (2n + 2)u/(1 − (2n + 2)u)), so with S = diag(H)^{-1/2},
/// S H S ⪰ (c − 3u − γρ)·I for ρ ≥ ‖S|L̂||L̂ᵀ|S‖₂, measured on the computed factor (`rho`): M
/// is proven definite when c − 3u − γρ > 0. The shift c = 4u + 1.25γρ is first taken for a
/// factor of well-separated rows (ρ = 2) and, if the measured ρ is larger, once more from it;
/// ρ ≤ n(1 + γ) always holds, so every M with λ_min(SHS) above about 2.5nγ ≈ 5n²u is proven,
/// and a banded or tree-like M (ρ small) down to about 40nu. False for a non-positive or
/// non-finite diagonal entry, or where the proof fails: M singular up to rounding is never
/// proven. O(n³/3) flops (twice at worst) in kept storage.
pub(crate) fn proven_positive_definite(m: faer::MatRef<'_, f64>, par: faer::Par) -> bool {
    proven_definite_with_margin(m, 0.0, par)
}

/// Whether M − τ·diag(M) is proven positive definite for the `margin` τ ≥ 0 (lower triangle
/// read): the proof of [`proven_positive_definite`] with the requirement raised to
/// c − 3u − γρ > τ, which gives S H S ≻ τ·I. Then M + E is positive definite for every
/// symmetric E with ‖diag(M)^{-1/2} E diag(M)^{-1/2}‖₂ ≤ τ: a matrix known only to within such
/// an E (an assembly's rounding) is proven definite with it. False for τ outside [0, 1/2),
/// or where the proof fails. O(n³/3) flops, twice at worst.
pub fn proven_definite_with_margin(m: faer::MatRef<'_, f64>, margin: f64, par: faer::Par) -> bool {
    proven_definite_with_spread_guess(m, margin, 2.0, par)
}

/// [`proven_definite_with_margin`] whose first shift assumes ρ = `spread_guess` (a caller that
/// has factored M already measures it there; 2 for a factor of well-separated rows). The guess
/// decides the cost (one factorization or two), never the truth of a proof: a guess too small
/// fails the check and the second shift is taken from the measured ρ. A pivot that fails at
/// the first shift ends the test, since a larger shift would fail too (up to rounding: the
/// answer is then false, which claims nothing).
pub(crate) fn proven_definite_with_spread_guess(
    m: faer::MatRef<'_, f64>,
    margin: f64,
    spread_guess: f64,
    par: faer::Par,
) -> bool {
    let n = m.nrows();
    if m.ncols() != n || !(0.0..0.5).contains(&margin) || spread_guess.is_nan() || spread_guess < 0.0 {
        return false;
    }
    let Some(half_exponents) = diagonal_half_exponents(m) else {
        return false;
    };
    let u = f64::EPSILON / 2.0;
    let gamma_order = 2.0 * n as f64 + 2.0;
    if gamma_order * u >= 0.25 {
        return false;
    }
    let gamma = gamma_order * u / (1.0 - gamma_order * u);
    let shift_for = |rho: f64| margin + 4.0 * u + 1.25 * gamma * rho;
    let mut shift = shift_for(spread_guess);
    for attempt in 0..2 {
        if shift.is_nan() || shift >= 0.5 {
            return false;
        }
        let Some(rho) = shifted_factor_spread(m, &half_exponents, shift, par) else {
            // A failed pivot: λ_min(SHS) is below this shift, and so below any larger one.
            return false;
        };
        if shift - 3.0 * u - gamma * rho > margin {
            return true;
        }
        if attempt == 0 {
            shift = shift_for(rho);
        }
    }
    false
}

/// The exponents s_j with 2^{2s_j} within a factor two of m_jj, by which the definiteness
/// proofs scale M to H = D⁻¹MD⁻¹ exactly (D = diag(2^{s_j})); None when a diagonal entry is
/// not positive and finite.
pub(crate) fn diagonal_half_exponents(m: faer::MatRef<'_, f64>) -> Option<Vec<i32>> {
    (0..m.nrows())
        .map(|j| {
            let d = m[(j, j)];
            (d > 0.0 && d.is_finite()).then(|| exponent(d).div_euclid(2))
        })
        .collect()
}

/// Factors G = H − shift·diag(H), H = D⁻¹MD⁻¹ (D = diag(2^{half_exponents})), and returns
/// the upper bound ρ of ‖S|L̂||L̂ᵀ|S‖₂ (S = diag(H)^{-1/2}) of [`factor_spread`], or None at
/// a pivot that is not positive and finite.
fn shifted_factor_spread(m: faer::MatRef<'_, f64>, half_exponents: &[i32], shift: f64, par: faer::Par) -> Option<f64> {
    let n = m.nrows();
    let mut g = crate::runtime::scratch::empty(n, n);
    let mut inverse_sqrt_diagonal = Vec::with_capacity(n);
    g.resize_with(n, n, |i, j| {
        let h = times_power_of_two(m[(i, j)], -(half_exponents[i] + half_exponents[j]));
        match i.cmp(&j) {
            std::cmp::Ordering::Greater => h,
            std::cmp::Ordering::Equal => h * (1.0 - shift),
            std::cmp::Ordering::Less => 0.0,
        }
    });
    for j in 0..n {
        let h = times_power_of_two(m[(j, j)], -2 * half_exponents[j]);
        inverse_sqrt_diagonal.push(1.0 / h.sqrt());
    }
    let factored = crate::linalg::reduce::factor_unchecked(g.as_mut(), par).is_ok()
        && (0..n).all(|j| g[(j, j)] > 0.0 && g[(j, j)].is_finite());
    let spread = factored.then(|| factor_spread(g.as_ref(), &inverse_sqrt_diagonal));
    crate::runtime::scratch::give_back(g);
    spread
}

/// An upper bound ρ of ‖S|L||Lᵀ|S‖₂ for the lower triangular L (strict upper triangle not
/// read) and S = diag(`row_weights`): the smaller of ‖S|L|‖_F² and the largest row sum of
/// S|L||Lᵀ|S (a symmetric non-negative matrix, whose 2-norm its ∞-norm bounds), multiplied by
/// 1 + 4(n + 8)u for the rounding of the sums and of the weights. O(n²).
pub(crate) fn factor_spread(l: faer::MatRef<'_, f64>, row_weights: &[f64]) -> f64 {
    let n = l.nrows();
    let s = row_weights;
    // Column sums v_k = Σ_i s_i|l_ik|, then row sums t_i = s_i Σ_k |l_ik| v_k.
    let mut column_sums = vec![0.0; n];
    let mut frobenius = 0.0;
    for k in 0..n {
        for i in k..n {
            let x = s[i] * l[(i, k)].abs();
            column_sums[k] += x;
            frobenius += x * x;
        }
    }
    let mut row_sums = vec![0.0; n];
    for k in 0..n {
        for i in k..n {
            row_sums[i] += l[(i, k)].abs() * column_sums[k];
        }
    }
    let largest_row = (0..n).map(|i| s[i] * row_sums[i]).fold(0.0, f64::max);
    let u = f64::EPSILON / 2.0;
    frobenius.min(largest_row) * (1.0 + 4.0 * (n as f64 + 8.0) * u)
}

/// The lower triangle of B − shift·A (the strict upper triangle zero), in kept storage when
/// some fits ([`crate::runtime::scratch`]).
pub(crate) fn shifted_lower(problem: &PencilProblem, shift: f64) -> Mat<f64> {
    let (a, b) = (problem.a(), problem.b());
    let n = problem.dim();
    let mut k = crate::runtime::scratch::empty(n, n);
    k.resize_with(n, n, |i, j| if i >= j { b[(i, j)] - shift * a[(i, j)] } else { 0.0 });
    k
}

/// (negative, zero, positive) eigenvalue counts of the symmetric matrix `k` (lower triangle read).
pub(crate) fn inertia_of(k: &Mat<f64>) -> (usize, usize, usize) {
    let n = k.nrows();
    if n == 0 {
        return (0, 0, 0);
    }
    let lblt = k.lblt(Side::Lower);
    let d = lblt.B_diag();
    let s = lblt.B_subdiag();
    let (mut neg, mut zero, mut pos) = (0, 0, 0);
    let mut i = 0;
    while i < n {
        if i + 1 < n && s[i] != 0.0 {
            // 2×2 block [d_i s_i; s_i d_{i+1}]: eigenvalue signs from determinant and trace,
            // on the block divided by a power of two near its largest entry (no over- or
            // underflow of the products).
            let top = d[i].abs().max(d[i + 1].abs()).max(s[i].abs());
            let e = if top > 0.0 && top.is_finite() { exponent(top) } else { 0 };
            let [d0, d1, s0] = [d[i], d[i + 1], s[i]].map(|x| times_power_of_two(x, -e));
            let det = d0 * d1 - s0 * s0;
            let trace = d0 + d1;
            if det < 0.0 {
                neg += 1;
                pos += 1;
            } else if det > 0.0 {
                if trace > 0.0 {
                    pos += 2;
                } else {
                    neg += 2;
                }
            } else {
                zero += 1;
                if trace > 0.0 {
                    pos += 1;
                } else if trace < 0.0 {
                    neg += 1;
                } else {
                    zero += 1;
                }
            }
            i += 2;
        } else {
            if d[i] < 0.0 {
                neg += 1;
            } else if d[i] > 0.0 {
                pos += 1;
            } else {
                zero += 1;
            }
            i += 1;
        }
    }
    (neg, zero, pos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;
    use crate::testing::graded::SplitMix;
    use faer::Par;

    /// D M D for a random diagonal D of powers of two over 2^±`spread` (exact products).
    fn graded_by_powers_of_two(m: &Mat<f64>, rng: &mut SplitMix, spread: usize) -> Mat<f64> {
        let n = m.nrows();
        let e: Vec<i32> = (0..n)
            .map(|_| rng.below(2 * spread + 1) as i32 - spread as i32)
            .collect();
        Mat::from_fn(n, n, |i, j| times_power_of_two(m[(i, j)], e[i] + e[j]))
    }

    /// The Laplacian of a random connected graph with small integer weights (a spanning tree
    /// and a few extra edges, cycles included): exactly singular, its null vector the ones.
    fn integer_laplacian(rng: &mut SplitMix, n: usize) -> Mat<f64> {
        let mut l = Mat::<f64>::zeros(n, n);
        let mut couple = |i: usize, j: usize, w: f64| {
            l[(i, j)] -= w;
            l[(j, i)] -= w;
            l[(i, i)] += w;
            l[(j, j)] += w;
        };
        for i in 1..n {
            let parent = rng.below(i);
            couple(i, parent, 1.0 + rng.below(9) as f64);
        }
        for _ in 0..n / 2 {
            let (i, j) = (rng.below(n), rng.below(n));
            if i != j {
                couple(i, j, 1.0 + rng.below(9) as f64);
            }
        }
        l
    }

    #[test]
    fn graded_definite_matrices_are_proven_whatever_the_grading() {
        let mut rng = SplitMix::new(31);
        for case in 0..60 {
            let n = 1 + rng.below(60);
            let q = testing::random_orthogonal(n, case);
            let lambda: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-6.0, 0.0))).collect();
            let c = Mat::from_fn(n, n, |i, j| {
                (0..n).map(|k| q[(i, k)] * lambda[k] * q[(j, k)]).sum::<f64>()
            });
            let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
            let by_powers = graded_by_powers_of_two(&c, &mut rng, 200);
            assert!(
                proven_positive_definite(by_powers.as_ref(), Par::Seq),
                "case {case}, n = {n}"
            );
            // A grading that rounds every entry once: still far inside the definite cone.
            let d: Vec<f64> = (0..n).map(|_| 10f64.powf(rng.uniform(-100.0, 100.0))).collect();
            let rounded = Mat::from_fn(n, n, |i, j| d[i] * c[(i, j)] * d[j]);
            assert!(
                proven_positive_definite(rounded.as_ref(), Par::Seq),
                "case {case}, n = {n}, rounded"
            );
        }
    }

    #[test]
    fn singular_and_indefinite_matrices_are_never_proven() {
        let mut rng = SplitMix::new(32);
        for case in 0..200 {
            let n = 2 + rng.below(60);
            let laplacian = integer_laplacian(&mut rng, n);
            let free = graded_by_powers_of_two(&laplacian, &mut rng, 200);
            assert!(
                !proven_positive_definite(free.as_ref(), Par::Seq),
                "case {case}: singular, n = {n}"
            );
            // Less than its own rounding removed from one diagonal entry: one negative eigenvalue.
            let mut indefinite = laplacian.clone();
            let k = rng.below(n);
            indefinite[(k, k)] -= times_power_of_two(1.0, -40);
            let indefinite = graded_by_powers_of_two(&indefinite, &mut rng, 200);
            assert!(
                !proven_positive_definite(indefinite.as_ref(), Par::Seq),
                "case {case}: indefinite"
            );
            // A rank-deficient Gram matrix X Xᵀ of small integers (exact), X with n − 1 columns.
            let x = Mat::from_fn(n, n - 1, |_, _| rng.below(7) as f64 - 3.0);
            let gram = Mat::from_fn(n, n, |i, j| (0..n - 1).map(|k| x[(i, k)] * x[(j, k)]).sum::<f64>());
            if (0..n).all(|i| gram[(i, i)] > 0.0) {
                let gram = graded_by_powers_of_two(&gram, &mut rng, 200);
                assert!(
                    !proven_positive_definite(gram.as_ref(), Par::Seq),
                    "case {case}: rank deficient"
                );
            }
        }
    }

    /// H = (1 − ρ)I + ρ11ᵀ (unit diagonal, λ_min = 1 − ρ exactly, ρ = 1 − 2⁻ᵏ), graded by
    /// powers of two: a margin below λ_min/2 is proven, one at or above λ_min never is.
    #[test]
    fn margins_are_proven_below_the_smallest_scaled_eigenvalue_and_never_above() {
        let mut rng = SplitMix::new(33);
        for case in 0..80 {
            let n = 2 + rng.below(50);
            let lambda_min = times_power_of_two(1.0, -(1 + rng.below(12) as i32));
            let rho = 1.0 - lambda_min;
            let h = Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { rho });
            let graded = graded_by_powers_of_two(&h, &mut rng, 200);
            let below = lambda_min * rng.uniform(0.0, 0.5);
            assert!(
                proven_definite_with_margin(graded.as_ref(), below, Par::Seq),
                "case {case}: n = {n}, λ_min = {lambda_min}, margin {below}"
            );
            let above = lambda_min * rng.uniform(1.0, 4.0);
            assert!(
                !proven_definite_with_margin(graded.as_ref(), above, Par::Seq),
                "case {case}: n = {n}, λ_min = {lambda_min}, margin {above}"
            );
        }
        let identity = Mat::<f64>::identity(3, 3);
        for bad in [-1e-300, 0.5, f64::NAN, f64::INFINITY] {
            assert!(!proven_definite_with_margin(identity.as_ref(), bad, Par::Seq), "{bad}");
        }
    }

    /// Blocks [[1, ρ], [ρ, 1]] on random pairs of coordinates (λ_min = 1 − ρ = 2⁻ᵏ exactly, k up
    /// to 40), graded by powers of two, n up to 240: the factor's rows stay separate, so the
    /// measured ρ proves margins below λ_min/2 far under the 4n²u of a bound by n alone (1e-11
    /// at n = 240), and never a margin at or above λ_min.
    #[test]
    fn sparse_factors_prove_nearly_singular_matrices() {
        let mut rng = SplitMix::new(34);
        for case in 0..60 {
            let n = 2 * (1 + rng.below(120));
            let mut order: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                order.swap(i, rng.below(i + 1));
            }
            let lambda_min = times_power_of_two(1.0, -(20 + rng.below(21) as i32));
            let mut h = Mat::<f64>::identity(n, n);
            for pair in order.chunks(2) {
                h[(pair[0], pair[1])] = 1.0 - lambda_min;
                h[(pair[1], pair[0])] = 1.0 - lambda_min;
            }
            let graded = graded_by_powers_of_two(&h, &mut rng, 200);
            let below = lambda_min * rng.uniform(0.0, 0.5);
            assert!(
                proven_definite_with_margin(graded.as_ref(), below, Par::Seq),
                "case {case}: n = {n}, λ_min = {lambda_min}, margin {below}"
            );
            let above = lambda_min * rng.uniform(1.0, 4.0);
            assert!(
                !proven_definite_with_margin(graded.as_ref(), above, Par::Seq),
                "case {case}: n = {n}, λ_min = {lambda_min}, margin {above}"
            );
            // One pair made exactly singular: never proven.
            let (i, j) = (order[0], order[1]);
            let mut singular = h.clone();
            singular[(i, j)] = 1.0;
            singular[(j, i)] = 1.0;
            let singular = graded_by_powers_of_two(&singular, &mut rng, 200);
            assert!(
                !proven_positive_definite(singular.as_ref(), Par::Seq),
                "case {case}: n = {n}, singular"
            );
        }
    }

    #[test]
    fn fixed_chain_counts_match_the_closed_form() {
        // Unit chain fixed at both ends: ω²_k = 4 sin²(kπ / (2(n+1))), k = 1..n.
        let n = 40;
        let (a, b) = testing::fixed_chain(n);
        let p = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
        let exact = testing::fixed_chain_omega_sq(n);
        for s in [-1.0, 0.0, 0.3, 1.7, 2.0, 3.99, 5.0] {
            let c = count_below(&p, s).expect("finite shift");
            let expected = exact.iter().filter(|&&w| w < s).count();
            assert_eq!(c.below, expected, "shift {s}");
            assert_eq!(c.below + c.zero + c.above, n);
        }
        assert!(matches!(count_below(&p, f64::NAN), Err(ModalError::BadShift(_))));
    }

    /// Blocks [[c, 2c], [2c, c]] (eigenvalues 3c and −c; Bunch–Kaufman takes them as 2×2
    /// pivots) with c from 1e-300 to 1e300 and A = I: one mode below each shift in (−c, 3c).
    /// The block's determinant c² − 4c² was ∞ − ∞ above 1e154 and 0 − 0 below 1e-162, and the
    /// block was counted as a zero eigenvalue.
    #[test]
    fn two_by_two_pivots_keep_their_signs_across_the_double_range() {
        for p in (-300..=300).step_by(25) {
            let c = 10f64.powi(p);
            let b = Mat::from_fn(2, 2, |i, j| if i == j { c } else { 2.0 * c });
            let a = Mat::<f64>::identity(2, 2);
            let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("valid pencil");
            for (s, expected) in [(-2.0, 0), (-0.5, 1), (0.0, 1), (2.5, 1), (4.0, 2)] {
                let count = count_below(&problem, s * c).expect("finite shift");
                assert_eq!((count.below, count.zero), (expected, 0), "c = 1e{p}, shift {s}·c");
            }
        }
    }

    /// The same chain with B scaled by 10^p and A by 10^q anywhere in the double range (ω² and
    /// the shifts by 10^(p−q)): the counts are those of the closed form.
    #[test]
    fn counts_hold_across_the_double_range() {
        let n = 12;
        let (a, b) = testing::fixed_chain(n);
        let exact = testing::fixed_chain_omega_sq(n);
        for p in [-300, -160, -20, 0, 40, 155, 300] {
            for q in [-300, -150, 0, 150, 300] {
                if p - q > 300 || q - p > 300 {
                    continue;
                }
                let (sb, sa) = (10f64.powi(p), 10f64.powi(q));
                let scaled_b = Mat::from_fn(n, n, |i, j| b[(i, j)] * sb);
                let scaled_a = Mat::from_fn(n, n, |i, j| a[(i, j)] * sa);
                let problem = PencilProblem::new(scaled_a.as_ref(), scaled_b.as_ref()).expect("valid pencil");
                for s in [-1.0, 0.05, 0.3, 1.7, 2.0, 3.99, 5.0] {
                    let expected = exact.iter().filter(|&&w| w < s).count();
                    let count = count_below(&problem, s * (sb / sa)).expect("finite shift");
                    assert_eq!(count.below, expected, "B·1e{p}, A·1e{q}, shift {s}");
                    assert_eq!(count.below + count.zero + count.above, n);
                }
            }
        }
    }
}
